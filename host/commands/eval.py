"""host eval [SCENE ...]: score a matcher on scenes with ground truth (Middlebury v2 metric)."""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from typing import Any

import cv2
import numba
import numpy as np

from host.commands.options import (
    POSITIVE,
    add_matcher_options,
    num_disparities_given,
    params_from_args,
)
from host.errors import HostError
from host.files import (
    IMAGE,
    all_or_nothing,
    check_folder,
    check_output,
    inside,
    safe_name,
    write_image_atomic,
)
from host.stereo.matcher import compute_disparity, matched_on, warm_up
from host.stereo.metrics import middlebury, round_submission
from host.stereo.params import MatcherParams
from host.stereo.picture import picture
from host.stereo.scenes import Scene, load_scenes


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenes", nargs="*", type=Path, metavar="SCENE_DIR",
                   help="scene folders, or folders of them (default: the embedded Motorcycle "
                        "pair)")
    p.add_argument("--scale", type=POSITIVE, help="ground-truth scale for 2001/2003 layouts")
    p.add_argument("--rho", type=POSITIVE, default=1.0, help="bad-pixel threshold (px)")
    p.add_argument("--round8", action="store_true",
                   help="score each map as an 8-bit Middlebury v2 submission stores it: "
                        "round(d * scale) / scale with the scene's ground-truth scale")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--picture", type=Path, metavar="DIR",
                   help="write each scene's disparity picture into DIR")
    add_matcher_options(p)
    p.set_defaults(run=run)


def score_scene(scene: Scene, params: MatcherParams, rho: float, round8: bool = False
                ) -> dict[str, Any]:
    """One row of the table, Middlebury v2's regions: bad (all: all.png where the scene has
    it, else every pixel with known ground truth), bad_nonocc, bad_disc (None where the
    scene has no such mask), rms and density (%) over all, ms (one compute_disparity call
    after warm-up). round8: the map is rounded as an 8-bit submission first."""
    warm_up(params)
    t0 = time.perf_counter()
    disp = compute_disparity(scene.left, scene.right, params)
    ms = (time.perf_counter() - t0) * 1000
    assert scene.gt is not None
    if round8:
        assert scene.scale is not None
        disp = round_submission(disp, scene.scale)
    scores = middlebury(disp, scene.gt, scene.masks, rho)
    whole = scores["all"]

    def bad(region: str) -> float | None:
        return scores[region].bad if region in scores else None

    return {"scene": scene.name, "bad": whole.bad, "bad_nonocc": bad("nonocc"),
            "bad_disc": bad("disc"), "rms": whole.rms, "density": whole.density, "ms": ms,
            "disp": disp}


def _scene_range(args: argparse.Namespace, params: MatcherParams, scene: Scene
                 ) -> MatcherParams:
    """The scene's disparity range: the params file's policy, else from ground truth."""
    from host.params_file import load_disparity_range
    from host.tuning.disparity_range import RangePolicy, apply_range

    table = load_disparity_range(args.params) if args.params else None
    if table is not None:
        return apply_range(params, RangePolicy.from_table(table).resolve(
            scene.left, scene.right, gt=scene.gt, nonocc=scene.masks.get("nonocc")))
    return params.replace(num_disparities=scene.num_disparities(
        16 if params.matcher.startswith("opencv") else 1))


def _fmt(v: float | None, spec: str = ".2f") -> str:
    return "-" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def run(args: argparse.Namespace) -> int:
    params = params_from_args(args)
    scenes = load_scenes(args.scenes, args.scale)
    for scene in scenes:
        if scene.gt is None:
            raise HostError(f"{scene.name}: no ground truth to evaluate against")
        if args.round8 and scene.scale is None:
            raise HostError(f"{scene.name}: no 8-bit ground-truth scale to round to (--round8)")
        if not np.isfinite(scene.gt).any():
            raise HostError(f"{scene.name}: its ground truth has no known pixel (all 0 or "
                            "unknown): nothing to score against")
    if args.picture:  # made, as capture makes --out; once the scenes are known to be good
        check_folder(args.picture, "--picture", create=True)
    with all_or_nothing():  # the pictures appear together, after every scene was scored
        rows = [_score(scene, params, args) for scene in scenes]
    out = [{k: (None if isinstance(v, float) and math.isnan(v) else v)
            for k, v in r.items() if k != "disp"} for r in rows]
    if args.json:
        print(json.dumps({"matcher": params.to_dict(), "scenes": out}))
        return 0
    print(f"matcher {params.matcher}, block size {params.block_size}, rho {args.rho} px")
    print(f"{'scene':<16}{'bad%':>8}{'nonocc%':>9}{'disc%':>8}{'rms':>8}{'density%':>10}"
          f"{'ms':>9}")
    for r in out:
        print(f"{r['scene']:<16}{_fmt(r['bad']):>8}{_fmt(r['bad_nonocc']):>9}"
              f"{_fmt(r['bad_disc']):>8}{_fmt(r['rms']):>8}{_fmt(r['density']):>10}"
              f"{_fmt(r['ms'], '.1f'):>9}")
    rounded = ", maps rounded as 8-bit submissions" if args.round8 else ""
    print("bad%: Middlebury v2's 'all' region (all.png where the scene has it, else every pixel "
          f"with known ground truth){rounded}")
    inputs = sorted({matched_on(s.left, params) for s in scenes})
    print(f"ms: one compute_disparity call on the {'/'.join(inputs)} pair after warm-up, "
          f"{numba.get_num_threads()} numba / {cv2.getNumThreads()} OpenCV threads")
    return 0


def _score(scene: Scene, params: MatcherParams, args: argparse.Namespace) -> dict[str, Any]:
    """Score one scene; with --picture, stage its picture (named from the scene, made safe)."""
    p = params if num_disparities_given(args) else _scene_range(args, params, scene)
    row = score_scene(scene, p, args.rho, args.round8)
    if args.picture:
        path = check_output(inside(args.picture, safe_name(scene.name, ".png")), IMAGE,
                            "--picture")
        write_image_atomic(path, picture(row["disp"], p.min_disparity + p.num_disparities))
    return row
