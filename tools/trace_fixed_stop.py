"""Trace a trial's fixed-object stop (Servo._fixed_fault): the estimate against the world's truth
at the frame the stop fired, the check redone along the estimated pose and heading and along
the true pose and heading (against the reference's cells, and against the true faces: the
back wall and the boxes other than the target, no margin), and the true room between the body
and the wall. A diagnostic (session 11, fixed2, after session 6's dstops tool): it wraps the
servo's methods and changes nothing.

    PYTHONPATH=. .venv/bin/python tools/trace_fixed_stop.py INDEX --seed S [--log] [--trials N]

--log prints the frames from 3 s before the stop (estimate, heading, command, truth).
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
from host.servo.clearance import Body, in_the_way, motion_heading, run_fault
from host.servo.perception import stopping_distance_m
from host.servo.phase import Phase
from host.sim import trials as T

idx = int(sys.argv[1])
seed = int(sys.argv[sys.argv.index("--seed") + 1])
args = build_parser().parse_args(["servo", "--sim", "--trials", "1", "--seed", str(seed)])
params = params_from_args(args)
st: dict[str, Any] = {"w": None, "fires": [], "log": []}
orig = L.Servo._fixed_fault


def true_cells(w: Any, target_z: float) -> np.ndarray:
    """The true faces every 1 cm: the back wall and the boxes but the target (its face)."""
    rows = [(w.wall_z_m, xx) for xx in np.arange(-1.5, 1.5, 0.01)]
    for b in w.boxes:
        if abs(b.z_m - target_z) < 0.05:
            continue
        rows += [(b.z_m, xx) for xx in np.arange(b.x0_m, b.x1_m + 1e-9, 0.01)]
    return np.array(rows)


def fixed(self: Any, t: float, cmd: Any) -> str:
    why = orig(self, t, cmd)
    w = st["w"]
    s, h, c = self.estimator.state, self.heading, self.controller
    r = w.robot if w is not None else None
    if s is not None and r is not None and c is not None:
        st["log"].append((t, cmd.phase.name, cmd.left, cmd.right, s.z, s.x, s.vz, s.vx,
                          h.value, h.spread, h.way, c.facing_away, r.z_m, r.x_m, r.theta, why))
    if why and r is not None:
        cfg = c.cfg
        cells = c.obstacles(s.z, s.x)
        lines = [f"FIRE t {t:.2f} phase {cmd.phase.name} cmd {cmd.left},{cmd.right}: {why}"]
        lines.append(f"  est z {s.z:.3f} x {s.x:+.3f} vz {s.vz:+.3f} vx {s.vx:+.3f} | truth z "
                     f"{r.z_m:.3f} x {r.x_m:+.3f} theta {math.degrees(r.theta):+.1f} deg; "
                     f"est-true dz {s.z - r.z_m:+.3f}")
        hv = None if h.value is None else round(math.degrees(h.value), 1)
        lines.append(f"  heading {hv} spread {math.degrees(h.spread):.1f} way {h.way} "
                     f"facing_away {c.facing_away} acq {self.acquisition.phase.name} "
                     f"either {self.acquisition.either_way} target {c.target_m:.3f}")
        back = cells[np.abs(cells[:, 1] - s.x) < 0.2]
        far = back[back[:, 0] > s.z]
        near_wall = float(np.min(far[:, 0])) if len(far) else math.nan
        back_m = r.z_m + r.half_extent()[1]
        lines.append(f"  nearest cell beyond the robot within 0.2 m across: {near_wall:.3f} m "
                     f"(true wall {w.wall_z_m:.2f}); true body back {back_m:.3f}, true room to "
                     f"wall {w.wall_z_m - back_m:+.3f} m")
        speed = max(math.hypot(s.vz, s.vx),
                    self.estimator.cfg.max_speed_mps * abs(cmd.left + cmd.right) / 2000)
        travel = stopping_distance_m(speed, margin_m=cfg.block_margin_m)
        if cmd.phase == Phase.PROBE:
            travel = self.cfg.acquire.probe_m + speed * self.cfg.react_s + cfg.block_margin_m
        body = Body(cfg.half_width_m, cfg.half_length_m, cfg.block_margin_m + cfg.cell_m / 2)
        body0 = Body(cfg.half_width_m, cfg.half_length_m, 0.0)
        tc = true_cells(w, c.target_m)
        if cmd.left * cmd.right < 0:
            rad = cfg.turn_radius_m + cfg.block_margin_m + cfg.cell_m / 2
            for name, z_, x_, cl, rr in (
                    ("est pose, cells, margin", s.z, s.x, cells, rad),
                    ("true pose, cells, margin", r.z_m, r.x_m, cells, rad),
                    ("true pose, true faces, no margin", r.z_m, r.x_m, tc, cfg.turn_radius_m)):
                hit = in_the_way(cl, z_, x_, None, 0.0, rr)
                d = float(np.min(np.hypot(cl[:, 0] - z_, cl[:, 1] - x_)))
                lines.append(f"  turn recheck {name}: radius {rr:.3f} nearest {d:.3f} -> {hit}")
        elif not cmd.is_stop:
            hv2, sp = motion_heading(h, c.facing_away)
            for name, z_, x_, h_, sp_, cl, bd, k in (
                    ("est pose, est heading, spread, cells", s.z, s.x, hv2, sp, cells, body, 1),
                    ("est pose, flipped heading, cells", s.z, s.x, hv2 + math.pi, sp, cells,
                     body, 1),
                    ("true pose, true heading, cells, margin", r.z_m, r.x_m, r.theta, 0.0,
                     cells, body, 1),
                    ("true pose, flipped true heading, cells, margin", r.z_m, r.x_m,
                     r.theta + math.pi, 0.0, cells, body, 1),
                    ("true pose, true heading, true faces, no margin", r.z_m, r.x_m, r.theta,
                     0.0, tc, body0, 1),
                    ("true pose, true heading, true faces, 2x travel", r.z_m, r.x_m, r.theta,
                     0.0, tc, body0, 2)):
                hit = run_fault(cl, z_, x_, cmd.left, cmd.right, h_, sp_, travel * k, bd,
                                self.cfg.wheelbase_m)
                lines.append(f"  recheck {name}: travel {travel * k:.3f} -> {hit}")
        st["fires"].append((t, why, lines))
    return why


L.Servo._fixed_fault = fixed  # type: ignore[method-assign]
keep_world(st)
n = int(sys.argv[sys.argv.index("--trials") + 1]) if "--trials" in sys.argv else 1000
tr = T.run_trial((seed, idx, parse_size(args.size), params, False))
stop = [f for f in st["fires"] if tr.reason and f[1] and tr.reason.endswith(f[1])]
first = stop[0] if stop else (st["fires"][-1] if st["fires"] else None)
print(f"fixed-check fires {len(st['fires'])} (matching the stop {len(stop)})")
if first is not None:
    print("\n".join(first[2]))
print("OUTCOME", tr.outcome, tr.reason, f"start {tr.start_m:.3f} target {tr.target_m:.3f}",
      f"error {tr.error_m}")
if "--log" in sys.argv:
    t0 = first[0] if first is not None else math.inf
    for rec in st["log"]:
        if rec[0] > t0 - 3.0 and rec[0] <= t0 + 0.05:
            t, ph, lft, rgt, z, x, vz, vx, hv, hs, way, fa, tz, tx, th, why = rec
            hs_ = "-" if hv is None else f"{math.degrees(hv):+6.1f}"
            print(f"{t:6.2f} {ph:7s} {lft:5d} {rgt:5d} est {z:.3f} {x:+.3f} v {vz:+.3f} "
                  f"{vx:+.3f} h {hs_} sp {math.degrees(hs):5.1f} way {way:+d} fa {fa} | true "
                  f"{tz:.3f} {tx:+.3f} th {math.degrees(th):+6.1f} {why[:50]}")
