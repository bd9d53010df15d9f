"""Benchmark of tuning on the shared Middlebury scenes: the grid of every space on every scene is
evaluated once (and cached), and everything else is read from those tables: leave-one-scene-out
generalisation and the per-scene optimum beside the built-in defaults.

Each scene gets its disparity range from its ground truth (+4 px), never a tuned number.
Run: .venv/bin/python bench/tuning.py [--cache DIR] [--scenes a,b,...]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from host.stereo import MatcherParams
from host.stereo.scenes import Scene, load_scene
from host.tuning.backends.local import LocalBackend
from host.tuning.disparity_range import RangePolicy
from host.tuning.ground_truth import GroundTruthScore
from host.tuning.objective import SceneTable
from host.tuning.spaces import Space, make_space

BASE = MatcherParams(border="clip")
DEFAULTS = MatcherParams()  # what host eval uses with no options (border invalid)
POLICY = RangePolicy("ground-truth", 4.0)


def conditions() -> str:
    load = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    return f"{os.cpu_count()} cores, numba threads {os.environ.get('NUMBA_NUM_THREADS', 'all')}; " \
           f"uptime: {load}"


def grid_table(space: Space, scenes: list[Scene], ranges, cache: Path | None
               ) -> np.ndarray:
    """bad % of every state (rows, in grid order) on every scene (columns)."""
    key = hashlib.sha1(repr((space, [s.name for s in scenes], ranges)).encode()).hexdigest()[:12]
    path = cache / f"grid-{space.name}-{key}.json" if cache else None
    if path and path.exists():
        return np.array(json.loads(path.read_text()))
    table = SceneTable(LocalBackend(GroundTruthScore(scenes, ranges)), space.params)
    rows = np.array(table.get(space.states()))
    if path:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(rows.tolist()))
    return rows


def leave_one_out(space: Space, names: list[str], table: np.ndarray,
                  defaults: dict[str, float]) -> None:
    print(f"\nleave-one-scene-out on the {space.name} space ({space.size} states): tuned by grid "
          "on the mean of the other scenes, scored on the one left out (nonocc bad %)")
    print(f"  {'scene':<9}{'left out':>9}{'own best':>9}{'defaults':>9}  parameters tuned on "
          "the others")
    picked = []
    for i, name in enumerate(names):
        others = [j for j in range(len(names)) if j != i]
        pick = int(np.argmin(table[:, others].mean(axis=1)))
        picked.append(table[pick, i])
        print(f"  {name:<9}{table[pick, i]:9.2f}{table[:, i].min():9.2f}{defaults[name]:9.2f}  "
              f"{space.values(space.states()[pick])}")
    own = table.min(axis=0)
    print(f"  mean: left out {np.mean(picked):.2f}, own best {own.mean():.2f}, defaults "
          f"{np.mean(list(defaults.values())):.2f}; mean gap to the own best "
          f"{np.mean(np.array(picked) - own):.2f} pt")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cache", type=Path, help="keep grid tables here between runs")
    ap.add_argument("--scenes", help="comma-separated scene names (default: all shared)")
    args = ap.parse_args()
    data = os.environ.get("STEREO_SERVO_DATA")
    if not data:
        print("STEREO_SERVO_DATA is not set: the tuning benchmark needs the Middlebury scenes")
        return 0
    root = Path(data) / "middlebury"
    names = args.scenes.split(",") if args.scenes else [
        d.name for d in sorted(root.iterdir()) if (d / "meta.json").exists()]
    scenes = [load_scene(root / n) for n in names]
    ranges = [POLICY.resolve(s.left, s.right, gt=s.gt) for s in scenes]
    print(f"tuning benchmark: {len(scenes)} scenes ({', '.join(names)}), ~450x375 px; "
          f"{conditions()}")
    defaults = dict(zip(names, GroundTruthScore(scenes, ranges)(DEFAULTS)))
    tables = {}
    for name in ("window", "sad"):
        space = make_space(name, BASE)
        t0 = time.perf_counter()
        tables[name] = grid_table(space, scenes, ranges, args.cache)
        print(f"grid of {name} ({space.size} states x {len(scenes)} scenes): "
              f"{time.perf_counter() - t0:.1f} s (0 when cached)")
    leave_one_out(make_space("sad", BASE), names, tables["sad"], defaults)
    return 0


if __name__ == "__main__":
    sys.exit(main())
