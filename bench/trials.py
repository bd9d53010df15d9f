"""Benchmark of a trial campaign (host servo --sim --trials N, faulty world, 320x240): wall time
and CPU a trial in one process, in 2 worker processes and as Ray tasks on a local 2-CPU cluster
(its node on 127.0.0.1), side by side over the same trials on this machine, each the same
command a user types; the three must give the same trials (exit 1 if not).

    python bench/trials.py --trials 40 --seed 3   # about 3 x 40 trials; minutes, not hours
    python bench/trials.py                        # 1000 trials of seed 1 (the goal: <= 10 min
                                                  # on 2 workers), three times over: hours

What it takes: each configuration runs every trial once, so the whole bench costs about three
campaigns of CPU (a faulty trial is ~1-3 s of CPU once its camera is calibrated; each process
calibrates each of its cameras once, ~1.3 s); skip configurations with --skip. It prints the
load average (os.getloadavg, as uptime) before and after each run, the CPU a trial (the
campaign's processes; Ray's workers are not counted), the wall time 1000 trials would take at
that run's pace, and, from the one process's CPU, what 1000 trials need on two free cores: the
16 cameras' calibrations (timed here first, one thread) once in each of the two workers, and
the trials' CPU shared between them. Under load the wall times and their ratios say more about
the other processes than about the backends; the CPU figures much less so. Dev seeds only
(1..8 and 100..199; 9 and 10..99 are the lead's reported campaigns). The Ray run goes inside a
loopback-only network namespace when `unshare -n` is allowed (../shared/local-servers.md), else
on the local cluster bound to 127.0.0.1.
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

from host.sim.trials import CAMERAS  # each process calibrates the cameras it meets

DEV_SEEDS = (*range(1, 9), *range(100, 200))


def _loopback_prefix() -> list[str]:
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return []
    probe = subprocess.run(["unshare", "-n", "sh", "-c", "ip link set lo up"],
                           capture_output=True, text=True)
    return [] if probe.returncode else ["unshare", "-n", "sh", "-c",
                                        "ip link set lo up && exec \"$@\"", "sh"]


def _load() -> str:
    return "/".join(f"{v:.1f}" for v in os.getloadavg())


before_after: dict[str, str] = {}


def _commit() -> str:
    r = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                       cwd=Path(__file__).parent)
    return r.stdout.strip() or "unknown"


def run(name: str, argv: list[str], json_path: Path) -> tuple[float, float, dict]:
    """Wall s, CPU s of the children (the campaign's own processes; Ray's workers are not
    counted), and the campaign's JSON."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    load0 = _load()
    print(f"{name}: load {load0} before", flush=True)
    t0 = time.monotonic()
    r = subprocess.run(argv, capture_output=True, text=True,
                       env=os.environ | {"RAY_USAGE_STATS_ENABLED": "0"})
    wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode:
        sys.exit(f"{name} failed ({r.returncode}): {r.stderr.strip()[-500:]}")
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    load1 = _load()
    before_after[name] = f"{load0}->{load1}"
    print(f"{name}: load {load1} after", flush=True)
    return wall, cpu, json.loads(json_path.read_text())


def _calibrations_cpu(seed: int, cameras: int) -> float:
    """CPU seconds of the calibrations of the campaign's first `cameras` cameras, as one
    process makes them (in a child process, one thread)."""
    code = ("import time; from host.sim.trial_backends import one_thread; one_thread(); "
            "from host.sim.run import _calibration; from host.sim.trials import trial_setup; "
            "from host.stereo.params import MatcherParams; "
            "p = MatcherParams.for_matcher(MatcherParams.matcher).validate(); "
            "t = time.process_time(); "
            f"[_calibration((320, 240), s.faults.camera.distortion, s.calib_seed) "
            f"for s in (trial_setup({seed}, i, (320, 240), p, False) for i in range({cameras}))]; "
            "print(time.process_time() - t)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return float(r.stdout.split()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--trials", type=int, default=1000, help="trials a configuration runs "
                    "(default 1000)")
    ap.add_argument("--seed", type=int, default=1, choices=DEV_SEEDS,
                    metavar="{1..8,100..199}", help="the campaign's seed (default 1)")
    ap.add_argument("--skip", action="append", default=[], choices=("1", "2", "ray"),
                    help="leave a configuration out")
    a = ap.parse_args()
    cameras = min(a.trials, CAMERAS)  # those the trials meet
    calib_s = _calibrations_cpu(a.seed, cameras)
    print(f"the {cameras} cameras' calibrations: {calib_s:.1f} s of CPU (one thread, "
          f"load {_load()})", flush=True)
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
    print(f"\n{a.trials} faulty trials of seed {a.seed} at 320x240, {os.cpu_count()} cores, "
          f"commit {_commit()}:")
    first = None
    for name, (wall, cpu, doc) in results.items():
        s = doc["summary"]
        sim = sum(t["sim_s"] for t in doc["trials"])
        cpu_text = f"CPU {cpu / a.trials:5.2f} s a trial" if "Ray" not in name else \
            "CPU (Ray workers) not counted"
        print(f"  {name:<12} load {before_after[name]}: wall {wall:7.1f} s "
              f"({wall / a.trials:5.2f} s a trial, "
              f"{1000 * wall / a.trials / 60:5.1f} min for 1000), {cpu_text}; "
              f"{sim / a.trials:4.1f} s simulated a trial; held {s['held']}, unsafe "
              f"{s['unsafe']}")
        if first is None:
            first = doc["trials"]
        elif doc["trials"] != first:
            print(f"  {name}: trials differ from the first configuration's", file=sys.stderr)
            return 1
    one = results.get("1 process")
    if one is not None:
        per_trial = (one[1] - calib_s) / a.trials
        free = (1000 * per_trial + 2 * calib_s * CAMERAS / cameras) / 2
        print(f"  CPU a trial once its camera is calibrated (one process): {per_trial:.2f} s; "
              f"1000 trials on two free cores: about {free / 60:.1f} min (each worker "
              f"calibrating the {CAMERAS} cameras, the trials' CPU split evenly)")
    walls = [w for w, _, _ in results.values()]
    if len(walls) > 1:
        print("  speed-up against the first: " + ", ".join(
            f"{name} {walls[0] / w:.2f}x" for name, (w, _, _) in list(results.items())[1:]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
