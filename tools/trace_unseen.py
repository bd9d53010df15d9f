"""Why the marker goes unseen, frame by frame, against the world's truth: for each frame of a
trial in a time window, the search's outcome (the pair taken, or the first reason a candidate
was refused, or none found) beside the robot's true depth, heading from square and the
card's aspect in the view. A diagnostic (session 12, lost12, issue 23): it wraps the servo's
marker search and changes nothing in the servo.

    PYTHONPATH=. .venv/bin/python tools/trace_unseen.py --seed S --index I [--t0 T] [--t1 T]
        [--trials N]
"""

import argparse
import math
from typing import Any

from trace_world import keep_world

from host.cli import build_parser
from host.commands.options import params_from_args
from host.commands.servo import parse_size  # type: ignore[attr-defined]
from host.servo import loop as L
from host.servo.card_turn import from_square
from host.sim import trials as T

ap = argparse.ArgumentParser()
ap.add_argument("--seed", type=int, required=True)
ap.add_argument("--index", type=int, required=True)
ap.add_argument("--trials", type=int, default=1000)
ap.add_argument("--t0", type=float, default=0.0)
ap.add_argument("--t1", type=float, default=1e9)
opts = ap.parse_args()
args = build_parser().parse_args(["servo", "--sim", "--trials", str(opts.trials), "--seed",
                                  str(opts.seed)])
params = params_from_args(args)
st: dict[str, Any] = {"w": None}
orig_search = L.Servo._search


def search(self: Any, frame: Any) -> Any:
    seen = orig_search(self, frame)
    w = st["w"]
    t = frame.t_left
    if w is not None and opts.t0 <= t <= opts.t1:
        r = w.robot
        what = (f"seen u {seen.pair.left.u:.0f} v {seen.pair.left.v:.0f} d "
                f"{seen.pair.disparity:.2f} aspect {seen.pair.left.aspect:.2f}"
                if seen.pair is not None else f"UNSEEN {seen.rejected or 'no candidate'}")
        extra = ""
        for name in ("occluder", "walker", "occluders"):
            if hasattr(w, name):
                extra += f" {name}={getattr(w, name)!r}"[:120]
        print(f"{t:7.3f} true z {r.z_m:.4f} x {r.x_m:+.4f} turn "
              f"{math.degrees(from_square(r.theta)):+6.1f} deg  {what}{extra}")
    return seen


L.Servo._search = search  # type: ignore[method-assign]
keep_world(st)
tr = T.run_trial((opts.seed, opts.index, parse_size(args.size), params, False))
print(f"# seed {opts.seed} #{opts.index}: {tr.outcome} {tr.reason}")
