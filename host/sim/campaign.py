"""A campaign of trials (host servo --sim --trials N): runs them on a backend, prints each as it
finishes, streams them to the JSON and the per-trial CSV, keeps what finished when interrupted,
and goes on from there with resume."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import sys
import time
from collections.abc import Iterator
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, TextIO

from host.errors import HostError
from host.files import write_text_atomic
from host.sim import trial_backends as backends
from host.sim.run import CalibKey, _calibration, keep_calibration
from host.sim.run import calibration_key as run_calibration_key
from host.sim.trial_stats import lines, plot, summary
from host.sim.trials import Trial, run_trial, trial_setup
from host.stereo.params import MatcherParams

FIELDS = [f.name for f in dataclasses.fields(Trial)]


@dataclass(frozen=True)
class Plan:
    """What a campaign is: its trials are (seed, i) for i in indices of range(n)."""

    n: int
    seed: int
    size: tuple[int, int]
    params: MatcherParams
    nominal: bool = False
    indices: tuple[int, ...] | None = None  # None: all n

    @property
    def world(self) -> str:
        return "nominal" if self.nominal else "faulty"

    def header(self) -> dict[str, Any]:
        return {"world": self.world, "seed": self.seed, "size": list(self.size), "n": self.n,
                "indices": list(self.indices) if self.indices is not None else None,
                "params": repr(self.params)}

    def wanted(self) -> list[int]:
        return sorted(set(self.indices)) if self.indices is not None else list(range(self.n))


class Outputs:
    """The JSON (rewritten atomically, at most every flush_s and at the end) and the CSV (a row
    appended as each trial finishes) of a campaign."""

    def __init__(self, plan: Plan, json_path: Path | None, csv_path: Path | None,
                 done: list[Trial], flush_s: float = 2.0) -> None:
        self.plan, self.json_path, self.csv_path = plan, json_path, csv_path
        self.trials = list(done)
        self.flush_s = flush_s
        self._flushed = time.monotonic()
        if csv_path is not None:  # what is known so far, then a row per trial as it comes
            buf = io.StringIO()
            w = csv.writer(buf)
            w.writerow(FIELDS)
            for t in sorted(self.trials, key=lambda t: t.index):
                w.writerow(_row(t))
            write_text_atomic(csv_path, buf.getvalue())

    def add(self, t: Trial) -> None:
        self.trials.append(t)
        if self.csv_path is not None:
            with open(self.csv_path, "a", newline="") as f:
                csv.writer(f).writerow(_row(t))
        if time.monotonic() - self._flushed >= self.flush_s:
            self.write_json()

    def complete(self) -> bool:
        return {t.index for t in self.trials} >= set(self.plan.wanted())

    def write_json(self) -> None:
        self._flushed = time.monotonic()
        if self.json_path is None:
            return
        trials = sorted(self.trials, key=lambda t: t.index)
        doc = {**self.plan.header(), "complete": self.complete(), "summary": summary(trials),
               "trials": [asdict(t) for t in trials]}
        write_text_atomic(self.json_path, json.dumps(doc, indent=1) + "\n")


def _row(t: Trial) -> list[Any]:
    return [";".join(v) if isinstance(v, list) else v for v in asdict(t).values()]


def resumed(plan: Plan, json_path: Path | None) -> list[Trial]:
    """The trials a previous run of the same plan finished, from its JSON."""
    if json_path is None:
        raise HostError("--resume needs --json FILE: the trials finished are read from it")
    if not json_path.exists():
        return []
    try:
        doc = json.loads(json_path.read_text())
    except (OSError, ValueError) as e:
        raise HostError(f"--resume: cannot read {json_path}: {e}") from None
    theirs = {k: doc.get(k) for k in plan.header()}
    if theirs != plan.header():
        diff = next(k for k in plan.header() if theirs[k] != plan.header()[k])
        raise HostError(f"--resume: {json_path} is another campaign ({diff} "
                        f"{theirs[diff]!r}, here {plan.header()[diff]!r})")
    return [Trial(**t) for t in doc["trials"]]


def _line(t: Trial) -> str:
    return (f"  {t.index:4d}  start {t.start_m:4.2f} m  target {t.target_m:4.2f} m  "
            f"{t.outcome:<11} err {t.error_m * 100:+6.2f} cm  overshoot "
            f"{t.overshoot_m * 100:5.1f} cm  hold at {t.time_to_hold_s:5.1f} s  "
            f"{t.reason}  [{t.faults}]")


Job = tuple[int, int, tuple[int, int], MatcherParams, bool]


def calibration_key(job: Job) -> CalibKey | None:
    """The camera calibration a trial needs (host.sim.run.calibration_key), or None."""
    return run_calibration_key(trial_setup(*job))


def _calibrate(key: CalibKey) -> tuple[CalibKey, Any]:
    return key, _calibration(*key)


def _trial_calibrated(arg: tuple[Job, CalibKey | None, Any]) -> Trial:
    job, key, calib = arg
    if key is not None and calib is not None:
        keep_calibration(key, calib)
    return run_trial(job)


def _calibrated_first(jobs: list[Job], workers: int) -> Iterator[Trial]:
    """The trials on worker processes, their cameras calibrated first, each once, shared among
    the workers (a camera's calibration is ~1.2 s of CPU, the same in any process: without
    this each worker calibrated every camera its trials met, the 16 cameras of a campaign
    twice on two workers)."""
    keys = {job: calibration_key(job) for job in jobs}
    cameras = sorted({k for k in keys.values() if k is not None})
    calibs: dict[CalibKey, Any] = {}
    if len(cameras) > 1:
        calibs = dict(backends.processes(_calibrate, cameras, workers))
    args = [(job, key, None if key is None else calibs.get(key))
            for job, key in keys.items()]
    yield from backends.processes(_trial_calibrated, args, workers)


def run_trials(n: int, seed: int, size: tuple[int, int], params: MatcherParams,
               json_path: Path | None = None, workers: int = 2, nominal: bool = False,
               out: TextIO = sys.stdout, indices: list[int] | None = None,
               csv_path: Path | None = None, ray: str | bool | None = None,
               resume: bool = False, plot_path: Path | None = None) -> int:
    """Runs trials 0..n-1 (or those of `indices`: trial i is the same whatever else runs and
    wherever it runs), prints each and the summary, streams them to json_path and csv_path.
    ray: True for a local Ray cluster, an address for an existing one."""
    if indices and max(indices) >= n:
        raise HostError(f"--trial-index {max(indices)} is not among the {n} trials")
    plan = Plan(n, seed, size, params, nominal, tuple(sorted(set(indices))) if indices else None)
    done = resumed(plan, json_path) if resume else []
    have = {t.index for t in done}
    todo = [i for i in plan.wanted() if i not in have]
    which = f"{len(plan.wanted())} of {n}" if indices else f"{n}"
    again = f" ({len(done)} done before, {len(todo)} to go)" if resume else ""
    print(f"{which} trials of the {plan.world} world at {size[0]}x{size[1]}, seed {seed}{again}",
          file=out)
    outputs = Outputs(plan, json_path, csv_path, done)
    jobs = [(seed, i, size, params, nominal) for i in todo]
    if ray:
        stream = backends.on_ray(run_trial, jobs, None if ray is True else str(ray), workers)
    elif workers > 1 and len(jobs) > 1:
        stream = _calibrated_first(jobs, workers)
    else:
        stream = backends.in_process(run_trial, jobs)
    try:
        for t in stream:
            outputs.add(t)
            print(_line(t), file=out, flush=True)
    finally:  # also on Ctrl-C: what finished is kept, --resume goes on from it
        getattr(stream, "close", lambda: None)()
        outputs.write_json()
    s = summary(outputs.trials)
    for text in lines(s):
        print(text, file=out)
    if plot_path is not None:
        plot(plot_path, s, outputs.trials)
    return 0
