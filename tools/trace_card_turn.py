"""Measure the card's signed turn (host/servo/card_turn.py) against the world's truth in whole
trials: every frame the servo admits a marker pair, the disparity across the disc read from
that frame's two views beside the robot's true heading and depth; the sign's error rate by
|turn from square| (the heading wrapped to -90..90 degrees: 10/20/30/40 are 5-15, 15-25,
25-35, 35-45) and depth. A diagnostic (session 11, sign, issue 23): it wraps the servo's
marker search and changes nothing in the servo.

    PYTHONPATH=. .venv/bin/python tools/trace_card_turn.py --seed S --index I [I ...]
        [--perspective]

--perspective draws each view's disc with the width a turned card has in it (the near edge at
the larger disparity: the left view's disc wider by d 2 R sin(theta) / z when theta > 0),
which the simulator does not model (host/sim/renderer.py draws one ellipse at one disparity in
both views): what the sign would be worth with the simulator's noise if it did.
"""

import argparse
import math
from collections import defaultdict
from typing import Any

from trace_world import keep_world

from host.cli import build_parser
from host.commands.options import params_from_args
from host.commands.servo import parse_size  # type: ignore[attr-defined]
from host.servo import loop as L
from host.servo.card_turn import across_px, expected_px, from_square
from host.sim import renderer as R
from host.sim import trials as T

ap = argparse.ArgumentParser()
ap.add_argument("--seed", type=int, required=True)
ap.add_argument("--index", type=int, nargs="+", required=True)
ap.add_argument("--perspective", action="store_true")
ap.add_argument("--sure", type=float, default=0.3, help="px: a sign read as sure beyond it")
opts = ap.parse_args()
SURE_PX = opts.sure
args = build_parser().parse_args(["servo", "--sim", "--trials", "1", "--seed", str(opts.seed)])
params = params_from_args(args)
st: dict[str, Any] = {"w": None}
rows: list[tuple[float, float, float, float, float]] = []  # turn, z, aspect, across, expected

orig_search = L.Servo._search


def search(self: Any, frame: Any) -> Any:
    seen = orig_search(self, frame)
    w = st["w"]
    if seen.pair is not None and w is not None:
        r = w.robot
        g = w.geometry
        d = g.focal_px * g.baseline_m / r.z_m
        rows.append((from_square(r.theta), r.z_m, seen.pair.left.aspect,
                     across_px(frame.left, frame.right, seen.pair),
                     expected_px(from_square(r.theta), r.z_m, d, r.marker_radius_m)))
    return seen


L.Servo._search = search  # type: ignore[method-assign]

if opts.perspective:
    orig_marker = R.Renderer._marker

    def marker(self: Any, image: Any, disp: Any, u: float, v: float, rx: float, ry: float,
               d: float, ring: float) -> None:
        r, g = self.world.robot, self.world.geometry
        if abs(d - g.focal_px * g.baseline_m / r.z_m) < 1e-9 and rx >= 0.5:
            ul = self._project(r.x_m, r.marker_height_m, r.z_m)[0]
            shift = round((ul - u) / d)  # 0: the left view, 1: the right
            # width_left - width_right
            delta = expected_px(from_square(r.theta), r.z_m, d, r.marker_radius_m)
            rx = rx + (delta / 4 if shift == 0 else -delta / 4)
        orig_marker(self, image, disp, u, v, rx, ry, d, ring)

    R.Renderer._marker = marker  # type: ignore[method-assign]

keep_world(st)

for i in opts.index:
    tr = T.run_trial((opts.seed, i, parse_size(args.size), params, False))
    print(f"# seed {opts.seed} #{i}: {tr.outcome} {tr.reason[:60]}")


def band(deg: float) -> str:
    for c in (10, 20, 30, 40):
        if abs(deg - c) < 5:
            return f"{c}"
    return "<5" if deg < 5 else ">45" if deg >= 45 else "-"


def zband(z: float) -> str:
    return "<1.0" if z < 1.0 else "1.0-1.5" if z < 1.5 else "1.5-2.0" if z < 2.0 else ">=2.0"


cells: dict[tuple[str, str], list[tuple[float, float, float]]] = defaultdict(list)
for th, z, _a, ac, ex in rows:
    if math.isfinite(ac):
        cells[(band(abs(math.degrees(th))), zband(z))].append((th, ac, ex))
print(f"# frames {len(rows)} (read {sum(len(v) for v in cells.values())}), perspective "
      f"{opts.perspective}")
print("|turn| deg  depth m   n   sign wrong   across px mean (sd)   expected px mean   "
      f"|across| >= {SURE_PX} px: n, wrong   turn < 0: n, wrong")
for key in sorted(cells):
    v = cells[key]
    wrong = sum(1 for th, ac, _ in v if ac * th < 0 or ac == 0)
    signed = [ac * (1 if th >= 0 else -1) for th, ac, _ in v]
    mean = sum(signed) / len(v)
    sd = math.sqrt(sum((s - mean) ** 2 for s in signed) / max(1, len(v) - 1))
    exp = sum(abs(e) for _, _, e in v) / len(v)
    sure = [(th, ac) for th, ac, _ in v if abs(ac) >= SURE_PX]
    bad = sum(1 for th, ac in sure if ac * th < 0)
    neg = [ac for th, ac, _ in v if th < 0]
    print(f"{key[0]:>5}        {key[1]:>7} {len(v):4d}   {wrong / len(v):6.1%}     "
          f"{mean:+7.3f} ({sd:.3f})          {exp:.3f}              {len(sure):4d}, {bad}"
          f"           {len(neg):4d}, {sum(1 for ac in neg if ac >= 0)}")
