"""Trace a trial's first probe refused by a fixed object (Servo._fixed_fault, phase PROBE): the
pose (estimate and truth), the heading the check took, and where the body, grown by the check's
margin, first meets a cell (the target's own face cells with the others) along the depth axis
toward the camera and away from it, by spread; against the shortest leg that could show the
facing: the check's stop at the probe's first duty (its reaction and run-down and
block_margin_m, travelled on from wherever the leg is) and the move that shows the facing
(max(probe_m, 3 sightings' noise)). A diagnostic (session 12, beside12): it wraps the servo's
check and changes nothing.

    PYTHONPATH=. .venv/bin/python tools/trace_probe_refusal.py INDEX --seed S [--trials N]

Why no shorter leg helps (the check is redone every frame from where the robot is): a leg
that shows its facing runs at least max(probe_m, 3 noise) and then its stop, so from its
start it reaches at least that plus the stop's travel; the check already looks probe_m plus
the stop's travel ahead, no farther. A hit nearer than the stop's travel alone refuses any leg.

Found with it (bbfffd6, 2026-12-05 03:16-03:25 UTC, load 11-19): two classes, neither mended
by a shorter leg or the other way (the check looks both ways alike while the facing is unshown).
Refused at the probe's start at the unknown 5 degrees: seed 3 #4 (own face cell 5.6 cm on
toward the camera; clear within 3 degrees; noise 0.99 cm, the shortest showing leg reaches
8.9 cm, the stop alone 6.0) and seed 18 #260 (2.8 cm on; clear within 3). Refused mid-leg after
3.0-3.6 cm of probe on a heading its own chord gave, wider than the unknown one: seed 18 #227
(+10.9 within 14.8 degrees, true +1.1) and #318 (+5.7 within 13.6, true +1.0), both clear
within 5 degrees, 0.00 m on within the chord's spread.
"""

import math
import sys
from typing import Any

import numpy as np
from trace_world import keep_world

from host.cli import build_parser
from host.commands.options import params_from_args
from host.commands.servo import parse_size  # type: ignore[attr-defined]
from host.servo import loop as L
from host.servo.clearance import swept
from host.servo.perception import stopping_distance_m
from host.servo.phase import Phase
from host.sim import trials as T

idx = int(sys.argv[1])
seed = int(sys.argv[sys.argv.index("--seed") + 1])
n = sys.argv[sys.argv.index("--trials") + 1] if "--trials" in sys.argv else "1000"
args = build_parser().parse_args(["servo", "--sim", "--trials", n, "--seed", str(seed)])
params = params_from_args(args)
st: dict[str, Any] = {"w": None, "lines": []}
orig = L.Servo._fixed_fault


def fixed(self: Any, t: float, cmd: Any) -> str:
    why = orig(self, t, cmd)
    if not why or cmd.phase != Phase.PROBE or st["lines"]:
        return why
    s, c, h, acq = self.estimator.state, self.controller, self.heading, self.acquisition
    r = st["w"].robot
    cells, own = c.obstacles(s.z, s.x), c.own()
    both = np.concatenate([cells, own]) if len(own) else cells
    body = self._body()
    noise = self._sighting_noise_m()
    show = max(acq.cfg.probe_m, 3 * noise)
    stop = stopping_distance_m(self.estimator.cfg.max_speed_mps * acq.cfg.probe_duty / 1000,
                               margin_m=c.cfg.block_margin_m)
    hv = "None" if h.value is None else f"{math.degrees(h.value):+.1f}"
    out = [f"FIRE t {t:.2f} cmd {cmd.left},{cmd.right}: {why}",
           f"  est z {s.z:.3f} x {s.x:+.3f} vz {s.vz:+.3f} | truth z {r.z_m:.3f} x {r.x_m:+.3f} "
           f"theta {math.degrees(r.theta):+.1f} deg | target {c.target_m:.3f} keep-out "
           f"{c.keep_out[0]:+.3f}..{c.keep_out[1]:+.3f}",
           f"  heading {hv} spread {math.degrees(h.spread):.1f} (unknown: "
           f"{math.degrees(h.unknown_spread):.0f}) either {acq.either_way} start z "
           f"{acq.depths[-1] if acq.depths else float('nan'):.3f}",
           f"  sighting noise {noise * 100:.2f} cm: a leg shows its facing after {show * 100:.1f} "
           f"cm; the stop at duty {acq.cfg.probe_duty} reaches {stop * 100:.1f} cm: the shortest "
           f"leg that shows reaches {(show + stop) * 100:.1f} cm"]
    for way, head in (("toward the camera", math.pi), ("away from it", 0.0)):
        for sp in (5.0, 4.0, 3.0, 2.0, 0.0):
            hit = swept(both, s.z, s.x, head, 0.25, body, math.radians(sp), 0.0, step_m=0.002)
            other = swept(cells, s.z, s.x, head, 0.25, body, math.radians(sp), 0.0,
                          step_m=0.002)
            out.append(f"  {way:17s} within {sp:.0f} deg: own+others hit "
                       f"{'-' if hit is None else f'{hit * 100:.1f} cm'}, others alone "
                       f"{'-' if other is None else f'{other * 100:.1f} cm'}")
    st["lines"] = out
    return why


L.Servo._fixed_fault = fixed  # type: ignore[method-assign]
keep_world(st)
tr = T.run_trial((seed, idx, parse_size(args.size), params, False))
print("\n".join(st["lines"]) if st["lines"] else "no probe refused by a fixed object")
print("OUTCOME", tr.outcome, tr.reason, f"start {tr.start_m:.3f} target {tr.target_m:.3f}")
