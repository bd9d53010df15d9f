"""host tune: tune the matcher against ground truth (the paper's Q-learner and alternatives)."""

from __future__ import annotations

import argparse
import datetime
import json
import sys
from pathlib import Path

from host.commands.options import (
    COUNT,
    FRACTION,
    POSITIVE,
    SEED,
    add_matcher_options,
    int_range,
    num_disp_given,
    params_from_args,
)
from host.errors import HostError
from host.files import all_or_nothing, check_output
from host.params_file import save_params
from host.stereo.scenes import load_scenes
from host.tuning.learners import METHODS, tune
from host.tuning.objective import Objective, mean_bad
from host.tuning.spaces import SPACES, make_space, odd_range

DEFAULT_ITERATIONS = {"paper": 20, "qlearning": 300, "random": 60, "grid": 0}


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("tune", help="tune the matcher's parameters against ground truth")
    p.add_argument("scenes", nargs="*", type=Path, metavar="SCENE_DIR",
                   help="scenes with ground truth (default: the embedded Motorcycle pair)")
    p.add_argument("--space", choices=SPACES, default="window",
                   help="parameters to tune: the window alone, or a matcher's several")
    p.add_argument("--method", choices=METHODS, default="paper",
                   help="the paper's Q-learner, full Q-learning, grid or random search")
    p.add_argument("--iterations", type=int_range(0),
                   help="learner steps (default: paper 20, qlearning 300, random 60; grid: all)")
    p.add_argument("--seed", type=SEED, default=0, help="seed of the learner")
    p.add_argument("--workers", type=COUNT, default=1, help="parallel evaluation processes")
    p.add_argument("--windows", default="5:41", help="odd window sizes lo:hi (window space)")
    p.add_argument("--step", type=COUNT, default=1, help="action step in values of a parameter")
    p.add_argument("--alpha", type=FRACTION, help="qlearning: learning rate (default 0.5)")
    p.add_argument("--gamma", type=FRACTION, help="discount (default: paper 0.8, qlearning 0.9)")
    p.add_argument("--epsilon", type=FRACTION,
                   help="exploration (paper 0.2; qlearning 0.3 at the start, decaying)")
    p.add_argument("--episodes", type=COUNT, help="qlearning: episodes (default 20)")
    p.add_argument("--tune-on", type=COUNT, metavar="N",
                   help="tune on the first N scenes, report the others as held out")
    p.add_argument("--scale", type=POSITIVE, help="ground-truth scale for 2001/2003 layouts")
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


def run(args: argparse.Namespace) -> int:
    if args.out:
        check_output(args.out, "toml", "--out")
    if args.plot:
        check_output(args.plot, "png", "--plot")
    iterations = DEFAULT_ITERATIONS[args.method] if args.iterations is None else args.iterations
    if args.method != "grid" and iterations < 1:
        raise HostError(f"--iterations must be at least 1, got {iterations}")
    scenes = load_scenes(args.scenes, args.scale)
    for s in scenes:
        if s.gt is None:
            raise HostError(f"{s.name}: no ground truth to tune against")
    n_tune = len(scenes) if args.tune_on is None else args.tune_on
    if not 1 <= n_tune <= len(scenes):
        raise HostError(f"--tune-on must be 1..{len(scenes)}, got {args.tune_on}")
    tuned_on, held_out = scenes[:n_tune], scenes[n_tune:]
    base = params_from_args(args)
    if not num_disp_given(args):
        base = base.replace(num_disparities=max(s.num_disparities(16) for s in scenes))
    space = make_space(args.space, base, odd_range(args.windows))
    if args.method == "paper" and len(space.dims) != 1:
        raise HostError(f"the paper's learner tunes one parameter; space {space.name} has "
                        f"{len(space.dims)} (use --method qlearning)")
    for s in space.states():  # every state must be a valid matcher on these images
        space.params(s).validate(width=min(sc.left.shape[1] for sc in scenes))
    hyper = {k: v for k, v in (("gamma", args.gamma), ("epsilon", args.epsilon),
                               ("alpha", args.alpha), ("episodes", args.episodes))
             if v is not None}
    if args.method in ("paper", "qlearning"):
        hyper["step"] = args.step
    if args.method == "paper" and ({"alpha", "episodes"} & set(hyper)):
        raise HostError("--alpha and --episodes belong to --method qlearning")
    if args.method in ("grid", "random") and set(hyper) - {"step"}:
        raise HostError(f"--method {args.method} takes no learning parameters")
    obj = Objective.on_scenes(tuned_on, space.params, workers=args.workers)
    total = space.size if args.method == "grid" else iterations
    bar = _progress(total, not args.json and sys.stderr.isatty())
    try:
        result = tune(args.method, obj, space, iterations, args.seed,
                      on_step=bar.update if bar else None, **hyper)
    finally:
        obj.close()
        if bar:
            bar.close()
    best = space.params(result.best_state)
    held = {s.name: mean_bad([s], best) for s in held_out}
    with all_or_nothing():  # both outputs, or neither
        if args.out:
            save_params(args.out, best, {
                "method": args.method, "space": args.space, "seed": args.seed,
                "scenes": [s.name for s in tuned_on], "bad": round(result.best_bad, 4),
                "evaluations": result.evaluations,
                "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")})
        if args.plot:
            from host.tuning.plot import plot

            plot(result, args.plot)
    out = result.to_json() | {"scenes": [s.name for s in tuned_on], "held_out": held}
    if args.json:
        print(json.dumps(out, default=str))
        return 0
    print(f"{args.method} on {args.space} over {', '.join(out['scenes'])}: best "
          f"{result.best_bad:.2f}% bad with {out['best_params']} after {len(result.history)} "
          f"iterations, {result.evaluations} distinct evaluations")
    for name, bad in held.items():
        print(f"  held out {name}: {bad:.2f}% bad with the tuned parameters")
    if args.out:
        print(f"  parameters written to {args.out}")
    return 0
