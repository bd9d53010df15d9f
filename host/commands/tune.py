"""host tune: tune the matcher's parameters on scenes with ground truth, or on a camera's own
frames with the self-supervised objective; locally, in processes or on Ray."""

from __future__ import annotations

import argparse
import datetime
import json
import sys
from pathlib import Path
from typing import Any

from host.commands.options import add_matcher_options, params_from_args
from host.errors import HostError
from host.params_file import save_params
from host.stereo.scenes import Scene, load_scenes
from host.tuning.backends import make_backend
from host.tuning.disparity_range import RangePolicy
from host.tuning.ground_truth import GroundTruthScore
from host.tuning.learners import METHODS, TuneResult, tune
from host.tuning.objective import Objective, SceneTable
from host.tuning.spaces import SPACES, Space, make_space, odd_range

DEFAULT_ITERATIONS = {"paper": 20, "qlearning": 300, "random": 60, "grid": 0}


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("tune", help="tune the matcher's parameters against ground truth")
    p.add_argument("scenes", nargs="*", type=Path, metavar="SCENE_DIR",
                   help="scenes with ground truth (default: the embedded Motorcycle pair)")
    p.add_argument("--space", choices=SPACES, default="window")
    p.add_argument("--method", choices=METHODS, default="paper")
    p.add_argument("--iterations", type=int,
                   help="learner steps (default: paper 20, qlearning 300, random 60; grid: all)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--workers", type=int, default=1, help="parallel evaluation processes")
    p.add_argument("--windows", default="5:41", help="odd window sizes lo:hi (window space)")
    p.add_argument("--step", type=int, default=1, help="action step in values of a parameter")
    p.add_argument("--alpha", type=float, help="qlearning: learning rate (default 0.5)")
    p.add_argument("--gamma", type=float, help="discount (default: paper 0.8, qlearning 0.9)")
    p.add_argument("--epsilon", type=float,
                   help="exploration (paper 0.2; qlearning 0.3 at the start, decaying)")
    p.add_argument("--episodes", type=int, help="qlearning: episodes (default 20)")
    p.add_argument("--range", dest="range_policy", metavar="POLICY",
                   help="each scene's disparity range: ground-truth (default), coarse (a quick "
                        "quarter-size pass), depth:NEAR:FAR (m, needs a calibration) or fixed:N")
    p.add_argument("--range-margin", type=float, default=4.0, metavar="PX",
                   help="widen the derived range by this much on both sides (default 4 px)")
    cv = p.add_mutually_exclusive_group()
    cv.add_argument("--tune-on", type=int, metavar="N",
                    help="tune on the first N scenes, report the others as held out")
    cv.add_argument("--cv", action="store_true",
                    help="leave-one-scene-out: for each scene, tune on the others and score it")
    p.add_argument("--scale", type=float, help="ground-truth scale for 2001/2003 layouts")
    p.add_argument("--out", type=Path, metavar="PARAMS.toml", help="write the tuned parameters")
    p.add_argument("--plot", type=Path, metavar="FIG.png", help="Figure 9 and the Q table")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_matcher_options(p)
    p.set_defaults(run=run)


def _progress(total: int, enabled: bool):
    if not enabled:
        return None
    from tqdm import tqdm

    return tqdm(total=total, unit="step", file=sys.stderr, leave=False)


def _hyper(args: argparse.Namespace) -> dict[str, Any]:
    hyper = {k: v for k, v in (("gamma", args.gamma), ("epsilon", args.epsilon),
                               ("alpha", args.alpha), ("episodes", args.episodes))
             if v is not None}
    if args.method in ("paper", "qlearning"):
        hyper["step"] = args.step
    if args.method == "paper" and ({"alpha", "episodes"} & set(hyper)):
        raise HostError("--alpha and --episodes belong to --method qlearning")
    if args.method in ("grid", "random") and set(hyper) - {"step"}:
        raise HostError(f"--method {args.method} takes no learning parameters")
    if args.step < 1 or (args.episodes is not None and args.episodes < 1):
        raise HostError("--step and --episodes must be at least 1")
    for name in ("alpha", "gamma", "epsilon"):
        value = getattr(args, name)
        if value is not None and not 0.0 <= value <= 1.0:
            raise HostError(f"--{name} must be in [0, 1], got {value}")
    return hyper


def _check_args(args: argparse.Namespace) -> int:
    iterations = DEFAULT_ITERATIONS[args.method] if args.iterations is None else args.iterations
    if args.method != "grid" and iterations < 1:
        raise HostError(f"--iterations must be at least 1, got {iterations}")
    if args.workers < 1:
        raise HostError(f"--workers must be at least 1, got {args.workers}")
    if args.num_disp is not None or args.min_disp is not None:
        raise HostError("tune derives each scene's disparity range: use --range "
                        "(e.g. fixed:N) instead of --num-disp / --min-disp")
    return iterations


def _ranges(scenes: list[Scene], policy: RangePolicy) -> list[tuple[int, int]]:
    return [policy.resolve(s.left, s.right, gt=s.gt) for s in scenes]


def _validate_space(space: Space, scenes: list[Scene], ranges: list[tuple[int, int]]) -> None:
    """Every state must be a valid matcher on every scene (with that scene's range)."""
    from host.tuning.disparity_range import apply_range

    for s in space.states():
        p = space.params(s)
        for sc, r in zip(scenes, ranges):
            apply_range(p, r).validate(width=sc.left.shape[1])


def _run_method(args: argparse.Namespace, obj: Objective, space: Space, iterations: int,
                hyper: dict[str, Any], show: bool) -> TuneResult:
    total = space.size if args.method == "grid" else iterations
    bar = _progress(total, show)
    try:
        return tune(args.method, obj, space, iterations, args.seed,
                    on_step=bar.update if bar else None, **hyper)
    finally:
        if bar:
            bar.close()


def run(args: argparse.Namespace) -> int:
    iterations = _check_args(args)
    hyper = _hyper(args)
    scenes = load_scenes(args.scenes, args.scale)
    for s in scenes:
        if s.gt is None:
            raise HostError(f"{s.name}: no ground truth to tune against")
    n_tune = len(scenes) if args.tune_on is None else args.tune_on
    if not 1 <= n_tune <= len(scenes):
        raise HostError(f"--tune-on must be 1..{len(scenes)}, got {args.tune_on}")
    if args.cv and len(scenes) < 2:
        raise HostError("--cv needs at least two scenes")
    policy = RangePolicy.parse(args.range_policy or "ground-truth", args.range_margin)
    ranges = _ranges(scenes, policy)
    space = make_space(args.space, params_from_args(args), odd_range(args.windows))
    if args.method == "paper" and len(space.dims) != 1:
        raise HostError(f"the paper's learner tunes one parameter; space {space.name} has "
                        f"{len(space.dims)} (use --method qlearning)")
    _validate_space(space, scenes, ranges)
    score = GroundTruthScore(scenes, ranges)
    show = not args.json and sys.stderr.isatty()
    table = SceneTable(make_backend(score, args.workers), space.params)
    try:
        folds = {}
        if args.cv:
            for i, held in enumerate(scenes):
                others = [j for j in range(len(scenes)) if j != i]
                r = _run_method(args, Objective.of(table, others), space, iterations, hyper,
                                show)
                folds[held.name] = {"params": space.values(r.best_state),
                                    "bad": table.get([r.best_state])[0][i],
                                    "tuned_bad": r.best_bad}
        result = _run_method(args, Objective.of(table, list(range(n_tune))), space,
                             iterations, hyper, show)
        row = table.get([result.best_state])[0]
    finally:
        table.close()
    best = space.params(result.best_state)
    tuned_on = scenes[:n_tune]
    held = {s.name: row[i] for i, s in enumerate(scenes) if i >= n_tune}
    if args.out:
        save_params(args.out, best, {
            "method": args.method, "space": args.space, "seed": args.seed,
            "objective": "ground-truth", "scenes": [s.name for s in tuned_on],
            "bad": round(result.best_bad, 4), "evaluations": result.evaluations,
            "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")},
            disparity_range=policy.to_table())
    if args.plot:
        from host.tuning.plot import plot

        plot(result, args.plot)
    out = result.to_json() | {"scenes": [s.name for s in tuned_on], "held_out": held,
                              "disparity_range": str(policy),
                              "ranges": {s.name: list(r) for s, r in zip(scenes, ranges)}}
    if args.cv:
        out["leave_one_out"] = folds
    if args.json:
        print(json.dumps(out, default=str))
        return 0
    print(f"{args.method} on {args.space} over {', '.join(out['scenes'])}: best "
          f"{result.best_bad:.2f}% bad with {out['best_params']} after {len(result.history)} "
          f"iterations, {result.evaluations} distinct evaluations")
    for name, bad in held.items():
        print(f"  held out {name}: {bad:.2f}% bad with the tuned parameters")
    for name, f in folds.items():
        print(f"  left out {name}: {f['bad']:.2f}% bad with {f['params']} "
              f"(tuned on the others: {f['tuned_bad']:.2f}%)")
    if args.out:
        print(f"  parameters written to {args.out} (disparity range: {policy})")
    return 0
