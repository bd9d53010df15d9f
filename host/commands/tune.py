"""host tune: tune the matcher's parameters on scenes with ground truth, or on a camera's own
frames with the self-supervised objective; locally, in worker processes or on Ray."""

from __future__ import annotations

import argparse
import datetime
import json
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from host import renamed
from host.camera.open import add_camera_options, known_geometry, open_source, parse_size
from host.commands.options import (
    COUNT,
    FRACTION,
    NON_NEGATIVE,
    POSITIVE,
    SEED,
    add_matcher_options,
    add_old_spelling,
    int_range,
    option,
    params_from_args,
)
from host.commands.swap_check import check_pairs
from host.errors import HostError
from host.files import all_or_nothing, check_output
from host.params_file import save_params
from host.stereo import MatcherParams
from host.stereo.scenes import Scene, load_scenes
from host.tuning.backends import make_backend
from host.tuning.disparity_range import RangePolicy
from host.tuning.ground_truth import GroundTruthScore
from host.tuning.learners import METHODS, TuneResult, tune
from host.tuning.objective import Objective, SceneTable
from host.tuning.self_supervised import SelfSupervisedScore
from host.tuning.spaces import SPACES, Space, make_space, odd_range

DEFAULT_METHOD = "tpe"  # the best measured (docs/tuning.md, "Methods at the CLI's budgets")
DEFAULT_ITERATIONS = {"paper": 20, "guided": 20, "qlearning": 300, "random": 60, "grid": 0,
                      "tpe": 60}


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenes", nargs="*", type=Path, metavar="SCENE_DIR",
                   help="scenes with ground truth (default: the embedded Motorcycle pair)")
    p.add_argument("--objective", choices=("gt", "self"), default="gt",
                   help="gt: bad %% against ground truth; self: self-supervised (census "
                        "reconstruction of the right view, holes, hidden, invalid, "
                        "roughness), no ground truth")
    p.add_argument("--frames", type=COUNT, default=4, metavar="N",
                   help="--camera: tune on N pairs spread over what the camera gives")
    p.add_argument("--space", type=_space, choices=SPACES, default="block-size",
                   help="parameters to tune: the block size alone, or a matcher's several")
    p.add_argument("--method", choices=METHODS, default=DEFAULT_METHOD,
                   help="Optuna's TPE (the default: within 0.5 pt of the grid optimum in 10 of "
                        "10 seeds on each space measured, docs/tuning.md), the paper's eq. 6 "
                        "learner as published, its guided variant, full Q-learning, grid or "
                        "random search")
    p.add_argument("--iterations", type=int_range(0),
                   help="learner steps (default: paper and guided 20, qlearning 300, random and "
                        "tpe 60; grid: all)")
    p.add_argument("--seed", type=SEED, default=0, help="seed of the learner")
    p.add_argument("--workers", type=COUNT, default=1, help="parallel evaluation processes")
    p.add_argument("--ray", nargs="?", const="local", metavar="ADDRESS",
                   help="evaluate on Ray: a local cluster, or the one at ADDRESS (host:port, "
                        "ray://host:port or auto); optional extra stereo-servo[ray]")
    sizes = p.add_argument("--block-sizes", default="5:41", metavar="LO:HI",
                           help="odd block sizes lo:hi (block-size space)")
    for old, new in renamed.TUNE_OPTIONS.items():
        add_old_spelling(p, option(old), {sizes.dest: sizes}[new])
    p.add_argument("--step", type=COUNT, default=1, help="action step in values of a parameter")
    p.add_argument("--alpha", type=FRACTION, help="qlearning: learning rate (default 0.5)")
    p.add_argument("--gamma", type=FRACTION,
                   help="discount (default: paper and guided 0.8, qlearning 0.9)")
    p.add_argument("--epsilon", type=FRACTION,
                   help="exploration (paper 0, guided 0.2; qlearning 0.3 at the start, "
                        "decaying)")
    p.add_argument("--episodes", type=COUNT, help="qlearning: episodes (default 20)")
    p.add_argument("--range", dest="range_policy", metavar="POLICY",
                   help="each scene's disparity range: ground-truth (default with --objective "
                        "gt: robust percentiles of the nonocc ground truth), coarse (default "
                        "with --objective self and a camera: a quick half-size pass), "
                        "depth:NEAR:FAR (m, needs a calibration) or fixed:N")
    p.add_argument("--range-margin", type=NON_NEGATIVE, default=4.0, metavar="PX",
                   help="widen the derived range by this much on both sides (default 4 px)")
    cv = p.add_mutually_exclusive_group()
    cv.add_argument("--tune-on", type=COUNT, metavar="N",
                    help="tune on the first N scenes, report the others as held out")
    cv.add_argument("--cv", action="store_true",
                    help="leave-one-scene-out: for each scene, tune on the others and score it")
    p.add_argument("--scale", type=POSITIVE, help="ground-truth scale for 2001/2003 layouts")
    p.add_argument("--out", type=Path, metavar="PARAMS.toml", help="write the tuned parameters")
    p.add_argument("--plot", type=Path, metavar="FIG.png", help="Figure 9 and the Q table")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_matcher_options(p)
    border = next(a for a in p._actions if a.dest == "border")
    border.help = (f"window at the image edge: invalid or clip (default without --params: "
                   f"{TUNE_BORDER}, the condition the objectives were measured under)")
    add_camera_options(p, sim=True)
    p.set_defaults(run=run, camera=None)


TUNE_BORDER = "clip"  # bench/tuning.py and docs/tuning.md measured every figure with it


def _space(name: str) -> str:
    """--space's type: a space's former name read as its name, with a note on stderr."""
    if name in renamed.SPACES:
        print(f"note: --space {name} is now {renamed.SPACES[name]} (the old name will go)",
              file=sys.stderr)
        return renamed.SPACES[name]
    return name


def _progress(total: int, enabled: bool, what: str) -> Any:
    """A progress bar on stderr (a terminal only), one tick per learner step."""
    if not enabled:
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc=what, unit="step", file=sys.stderr, mininterval=0.2,
                dynamic_ncols=True)


def _hyper(args: argparse.Namespace) -> dict[str, Any]:
    hyper = {k: v for k, v in (("gamma", args.gamma), ("epsilon", args.epsilon),
                               ("alpha", args.alpha), ("episodes", args.episodes))
             if v is not None}
    if args.method in ("paper", "guided", "qlearning"):
        hyper["step"] = args.step
    if args.method in ("paper", "guided") and ({"alpha", "episodes"} & set(hyper)):
        raise HostError("--alpha and --episodes belong to --method qlearning")
    if args.method in ("grid", "random", "tpe") and set(hyper) - {"step"}:
        raise HostError(f"--method {args.method} takes no learning parameters")
    return hyper


def _check_args(args: argparse.Namespace) -> int:
    iterations = DEFAULT_ITERATIONS[args.method] if args.iterations is None else args.iterations
    if args.method != "grid" and iterations < 1:
        raise HostError(f"--iterations must be at least 1, got {iterations}")
    if args.ray is not None:
        if args.workers > 1:
            raise HostError("--workers and --ray are two ways to run evaluations: pick one")
        if not (args.ray in ("local", "auto") or args.ray.startswith("ray://")
                or re.fullmatch(r"[\w.\-]+:\d+", args.ray)):
            raise HostError(f"--ray ADDRESS must be host:port, ray://host:port or auto, got "
                            f"{args.ray!r} (put scene folders before --ray)")
    if args.num_disparities is not None or args.min_disparity is not None:
        raise HostError("tune derives each scene's disparity range: use --range "
                        "(e.g. fixed:N) instead of --num-disparities / --min-disparity")
    return iterations


def camera_scenes(args: argparse.Namespace) -> tuple[list[Scene], float | None]:
    """Pairs from --camera as scenes without ground truth, and focal_px * baseline_m when the
    geometry is known (calibration or simulation). The right view is brought to the left's
    exposure as `host servo` does before it matches, so the tuned parameters fit what the servo
    matches."""
    from host.servo.perception import match_exposure
    from host.tuning.frames import sim_pairs, spread_pairs

    focal_baseline = None
    if args.camera == "sim":
        pairs, focal_baseline = sim_pairs(*parse_size(args.size), args.frames)
    else:
        with open_source(args, speed=0) as source:  # a bag as fast as it reads
            pairs = spread_pairs(source, args.frames, live=args.camera == "minoru")
        g = known_geometry(args, source)  # --calib, or a bag's CameraInfo
        if g is not None:
            focal_baseline = g.focal_px * g.baseline_m
    return [Scene(f"{args.camera.split(':')[0]}-{i}", left, match_exposure(left, right))
            for i, (left, right) in enumerate(pairs)], focal_baseline


def _ranges(scenes: list[Scene], policy: RangePolicy, focal_baseline: float | None
            ) -> list[tuple[int, int]]:
    return [policy.resolve(s.left, s.right, gt=s.gt, focal_baseline=focal_baseline,
                           nonocc=s.masks.get("nonocc")) for s in scenes]


def _validate_space(space: Space, scenes: list[Scene], ranges: list[tuple[int, int]]) -> None:
    """Every state must be a valid matcher on every scene (with that scene's range)."""
    from host.tuning.disparity_range import apply_range

    for s in space.states():
        p = space.params(s)
        for sc, r in zip(scenes, ranges):
            apply_range(p, r).validate(width=sc.left.shape[1])


@dataclass(frozen=True)
class TuneJob:
    """What `host tune` was asked to do, checked: the scenes with their disparity ranges, the
    space, the learner and its settings, and where the results go. from_args raises HostError
    (one line, exit 2) on bad input before anything runs or is written."""

    method: str
    space: Space
    seed: int
    objective: str  # "gt": bad % against ground truth; "self": the self-supervised score
    iterations: int
    hyper: dict[str, Any]
    scenes: list[Scene]
    n_tune: int  # tune on scenes[:n_tune], report the others as held out
    cv: bool  # leave-one-scene-out folds first
    policy: RangePolicy
    ranges: list[tuple[int, int]]  # each scene's, from the policy
    workers: int
    ray: str | None
    out: Path | None
    plot: Path | None
    json: bool
    progress: bool  # a progress bar on stderr

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> TuneJob:
        if args.out:
            check_output(args.out, "toml", "--out")
        if args.plot:
            check_output(args.plot, "png", "--plot")
        iterations = _check_args(args)
        hyper = _hyper(args)
        if args.params is None and args.border is None:
            args = argparse.Namespace(**vars(args) | {"border": TUNE_BORDER})
        if args.camera is not None and args.scenes:
            raise HostError("give scene folders or --camera, not both")
        if args.camera is not None and args.objective != "self":
            raise HostError("a camera's frames have no ground truth: use --objective self")
        focal_baseline = None
        if args.camera is not None:
            scenes, focal_baseline = camera_scenes(args)
        else:
            scenes = load_scenes(args.scenes, args.scale)
        for s in scenes:
            if s.gt is None and args.objective == "gt":
                raise HostError(f"{s.name}: no ground truth to tune against "
                                "(--objective self needs none)")
        if args.objective == "self":
            check_pairs([(s.name, s.left, s.right) for s in scenes], args.swap_check)
        n_tune = len(scenes) if args.tune_on is None else args.tune_on
        if not 1 <= n_tune <= len(scenes):
            raise HostError(f"--tune-on must be 1..{len(scenes)}, got {args.tune_on}")
        if args.cv and len(scenes) < 2:
            raise HostError("--cv needs at least two scenes")
        default_policy = "ground-truth" if args.objective == "gt" else "coarse"
        policy = RangePolicy.parse(args.range_policy or default_policy, args.range_margin)
        if args.objective == "self" and policy.kind == "ground-truth":
            raise HostError("the self-supervised objective uses no ground truth: choose --range "
                            "coarse, depth:NEAR:FAR or fixed:N")
        ranges = _ranges(scenes, policy, focal_baseline)
        space = make_space(args.space, params_from_args(args), odd_range(args.block_sizes))
        if args.method in ("paper", "guided") and len(space.dims) != 1:
            raise HostError(f"the {args.method} learner tunes one parameter; space {space.name} "
                            f"has {len(space.dims)} (use --method qlearning)")
        _validate_space(space, scenes, ranges)
        return cls(args.method, space, args.seed, args.objective, iterations, hyper, scenes,
                   n_tune, args.cv, policy, ranges, args.workers, args.ray, args.out, args.plot,
                   args.json, progress=not args.json and sys.stderr.isatty())

    @property
    def tuned_on(self) -> list[Scene]:
        return self.scenes[:self.n_tune]


@dataclass(frozen=True)
class TuneOutcome:
    """What a tuning job found: the learner's result on the tuned-on scenes, the tuned
    parameters' score on each scene, and the leave-one-out folds and ground-truth scores when
    asked for or known."""

    result: TuneResult
    best: MatcherParams
    held_out: dict[str, float]  # scene name: score with the tuned parameters
    folds: dict[str, dict[str, Any]]  # --cv: left-out scene: its params, score, tuned score
    truth: dict[str, float] | None  # self-tuned parameters against unused ground truth


def run_job(job: TuneJob) -> TuneOutcome:
    """Tune: no file is written and nothing printed (a progress bar on stderr if asked)."""
    score = (GroundTruthScore(job.scenes, job.ranges) if job.objective == "gt"
             else SelfSupervisedScore([(s.left, s.right) for s in job.scenes], job.ranges))
    table = SceneTable(make_backend(score, job.workers, job.ray), job.space.params)
    try:
        folds = {}
        if job.cv:
            for i, held in enumerate(job.scenes):
                others = [j for j in range(len(job.scenes)) if j != i]
                r = _run_method(job, Objective.of(table, others), f"without {held.name}")
                folds[held.name] = {"params": job.space.values(r.best_state),
                                    "bad": table.get([r.best_state])[0][i],
                                    "tuned_bad": r.best_bad}
        result = _run_method(job, Objective.of(table, list(range(job.n_tune))),
                             f"{job.method} on {job.space.name}")
        row = table.get([result.best_state])[0]
    finally:
        table.close()
    best = job.space.params(result.best_state)
    held_out = {s.name: row[i] for i, s in enumerate(job.scenes) if i >= job.n_tune}
    truth = None
    if job.objective == "self" and all(s.gt is not None for s in job.scenes):
        # the self-tuned parameters scored against the ground truth it did not use
        truth = dict(zip([s.name for s in job.scenes],
                         GroundTruthScore(job.scenes, job.ranges)(best)))
    return TuneOutcome(result, best, held_out, folds, truth)


def _run_method(job: TuneJob, obj: Objective, what: str) -> TuneResult:
    total = job.space.size if job.method == "grid" else job.iterations
    bar = _progress(total, job.progress, what)
    try:
        return tune(job.method, obj, job.space, job.iterations, job.seed,
                    on_step=bar.update if bar else None, **job.hyper)
    finally:
        if bar:
            bar.close()


def to_json(job: TuneJob, done: TuneOutcome) -> dict[str, Any]:
    """The --json object: the learner's result and what it was tuned and scored on."""
    out = done.result.to_json() | {
        "objective": job.objective, "scenes": [s.name for s in job.tuned_on],
        "held_out": done.held_out, "disparity_range": str(job.policy),
        "ranges": {s.name: list(r) for s, r in zip(job.scenes, job.ranges)}}
    if job.cv:
        out["leave_one_out"] = done.folds
    if done.truth is not None:
        out["ground_truth_bad"] = done.truth
    return out


def report(job: TuneJob, done: TuneOutcome) -> None:
    """Write the parameters and the plot (both, or neither), then print the JSON object or
    the lines."""
    result = done.result
    with all_or_nothing():  # both outputs, or neither
        if job.out:
            save_params(job.out, done.best, {
                "method": job.method, "space": job.space.name, "seed": job.seed,
                "objective": {"gt": "ground-truth", "self": "self-supervised"}[job.objective],
                "scenes": [s.name for s in job.tuned_on],
                "bad" if job.objective == "gt" else "score": round(result.best_bad, 4),
                "evaluations": result.evaluations,
                "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")},
                disparity_range=job.policy.to_table())
        if job.plot:
            from host.tuning.plot import plot

            plot(result, job.plot, score="bad pixels (%)" if job.objective == "gt"
                 else "self-supervised score (%)", scenes=tuple(s.name for s in job.tuned_on))
    out = to_json(job, done)
    if job.json:
        print(json.dumps(out, default=str))
        return
    what = "bad" if job.objective == "gt" else "self-supervised score"
    print(f"{job.method} on {job.space.name} over {', '.join(out['scenes'])}: best "
          f"{result.best_bad:.2f}% {what} with {out['best_params']} after "
          f"{len(result.history)} iterations, {result.evaluations} distinct evaluations")
    for name, bad in (done.truth or {}).items():
        print(f"  {name}: {bad:.2f}% bad against its ground truth (not used for tuning)")
    for name, bad in done.held_out.items():
        print(f"  held out {name}: {bad:.2f}% {what} with the tuned parameters")
    for name, f in done.folds.items():
        print(f"  left out {name}: {f['bad']:.2f}% {what} with {f['params']} "
              f"(tuned on the others: {f['tuned_bad']:.2f}%)")
    if job.out:
        print(f"  parameters written to {job.out} (disparity range: {job.policy})")


def run(args: argparse.Namespace) -> int:
    report(job := TuneJob.from_args(args), run_job(job))
    return 0
