"""Benchmark of a trial campaign (host servo --sim --trials N, faulty world, 320x240): wall time
in one process, in 2 worker processes and as Ray tasks on a local 2-CPU cluster, side by side on
this machine, each the same command a user types; the three must give the same trials.

    python bench/trials.py                # 1000 trials of seed 1 (the goal: <= 10 min)
    python bench/trials.py --trials 60 --seed 2

Seeds 1..6 only: seed 7 is held out for the reported figures. The Ray run goes inside a
loopback-only network namespace when `unshare -n` is allowed (../shared/local-servers.md), else
on the local cluster bound to 127.0.0.1. Prints the load (uptime) before and after each run.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HELD_OUT = 7


def _loopback_prefix() -> list[str]:
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return []
    probe = subprocess.run(["unshare", "-n", "sh", "-c", "ip link set lo up"],
                           capture_output=True, text=True)
    return [] if probe.returncode else ["unshare", "-n", "sh", "-c",
                                        "ip link set lo up && exec \"$@\"", "sh"]


def _load() -> str:
    return os.getloadavg().__repr__()


def run(name: str, argv: list[str], json_path: Path) -> tuple[float, float, dict]:
    """Wall s, CPU s of the children (the campaign's own processes; Ray's workers are not
    counted), and the campaign's JSON."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(f"{name}: load {_load()} before", flush=True)
    t0 = time.monotonic()
    r = subprocess.run(argv, capture_output=True, text=True,
                       env=os.environ | {"RAY_USAGE_STATS_ENABLED": "0"})
    wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode:
        sys.exit(f"{name} failed ({r.returncode}): {r.stderr.strip()[-500:]}")
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    print(f"{name}: load {_load()} after", flush=True)
    return wall, cpu, json.loads(json_path.read_text())


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=1, choices=range(1, 7), metavar="1..6")
    ap.add_argument("--skip", action="append", default=[], choices=("1", "2", "ray"),
                    help="leave a configuration out")
    a = ap.parse_args()
    assert a.seed != HELD_OUT
    base = [sys.executable, "-m", "host", "servo", "--sim", "--trials", str(a.trials),
            "--seed", str(a.seed)]
    configs = [("1", "1 process", ["--workers", "1"], []),
               ("2", "2 workers", ["--workers", "2"], []),
               ("ray", "Ray, 2 CPUs", ["--ray", "--workers", "2"], _loopback_prefix())]
    results = {}
    with tempfile.TemporaryDirectory() as d:
        for key, name, extra, prefix in configs:
            if key in a.skip:
                continue
            path = Path(d) / f"{key}.json"
            results[name] = run(name, prefix + base + extra + ["--json", str(path)], path)
    print(f"\n{a.trials} faulty trials of seed {a.seed} at 320x240, {os.cpu_count()} cores:")
    first = None
    for name, (wall, cpu, doc) in results.items():
        s = doc["summary"]
        sim = sum(t["sim_s"] for t in doc["trials"])
        cpu_text = f"CPU {cpu / a.trials:5.2f} s a trial" if "Ray" not in name else \
            "CPU (Ray workers) not counted"
        print(f"  {name:<12} wall {wall:7.1f} s ({wall / a.trials:5.2f} s a trial, "
              f"{1000 * wall / a.trials / 60:5.1f} min for 1000), {cpu_text}; "
              f"{sim / a.trials:4.1f} s simulated a trial; held {s['held']}, unsafe "
              f"{s['unsafe']}")
        if first is None:
            first = doc["trials"]
        elif doc["trials"] != first:
            print(f"  {name}: trials differ from the first configuration's", file=sys.stderr)
            return 1
    walls = [w for w, _, _ in results.values()]
    if len(walls) > 1:
        print("  speed-up against the first: " + ", ".join(
            f"{name} {walls[0] / w:.2f}x" for name, (w, _, _) in list(results.items())[1:]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
