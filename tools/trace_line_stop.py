"""Trace a trial's stops beside the object against the world's truth when they fire.

The controller's "the robot's line passes through the object" and "pushed sideways onto the
object while holding" (and their back-off's "no safe way back: ..."), and "turning here
would sweep the robot's body into the object": at each, the estimate (depth, lateral, the
turned reach, the object's extent and depth, the heading) beside the truth (the pose, the
heading, the target box, the push), and the check's own rule on the truth. For a back-off's
"no safe way back", the ways that were there in truth: straight along the true heading
toward the camera and away from it, until out of the object's depth (block_m + clear_m),
and a spin in place, each with the least clearance (m) between the body (the true
rectangle) and the object (its face's extent, its sides running back from the face: the
servo's model; the simulated box is the face alone).

    .venv/bin/python tools/trace_line_stop.py INDEX --seed S [--json]
"""

import json
import math
import sys
from typing import Any

import numpy as np
from trace_world import keep_world

from host.cli import build_parser
from host.commands.options import params_from_args
from host.commands.servo import parse_size
from host.servo import controller as C
from host.servo import loop as L
from host.servo import recovery as R
from host.sim import trials as T

BACK_DEPTH_M = 0.5  # how far the object's sides run back from its face (unseen: the servo's model)

st: dict[str, Any] = {"w": None, "servo": None, "events": []}


def target_box(w: Any) -> Any:
    return w.nearest_box() if w.target_index is None else w.boxes[w.target_index]


def body_outline(x: float, z: float, theta: float, half_w: float = 0.08,
                 half_l: float = 0.08, n: int = 24) -> np.ndarray:
    """Points (x, z) on the body's rectangle outline, heading theta (world: +x for theta>0)."""
    s = np.linspace(-1.0, 1.0, n)
    a = np.concatenate([s, s, np.ones(n), -np.ones(n)]) * half_l  # along
    c = np.concatenate([np.ones(n), -np.ones(n), s, s]) * half_w  # across
    ax, az = math.sin(theta), math.cos(theta)
    return np.stack([x + a * ax + c * az, z + a * az - c * ax], axis=1)


def clearance(x: float, z: float, theta: float, b: Any) -> float:
    """The least distance (m) from the body to the object's region (x0..x1 across, its face
    at z_m and BACK_DEPTH_M behind it); negative: they overlap (how deep, roughly)."""
    p = body_outline(x, z, theta)
    x0, x1, z0, z1 = b.x0_m, b.x1_m, b.z_m, b.z_m + BACK_DEPTH_M
    dx = np.maximum(np.maximum(x0 - p[:, 0], p[:, 0] - x1), 0.0)
    dz = np.maximum(np.maximum(z0 - p[:, 1], p[:, 1] - z1), 0.0)
    out = np.hypot(dx, dz)
    inside = (p[:, 0] > x0) & (p[:, 0] < x1) & (p[:, 1] > z0) & (p[:, 1] < z1)
    if inside.any():
        depth = np.minimum.reduce([p[:, 0] - x0, x1 - p[:, 0], p[:, 1] - z0, z1 - p[:, 1]])
        return -float(depth[inside].max())
    # a corner of the region inside the body (the face's ends)
    ax, az = math.sin(theta), math.cos(theta)
    for cx, cz in ((x0, z0), (x1, z0)):
        along = (cx - x) * ax + (cz - z) * az
        across = (cx - x) * az - (cz - z) * ax
        if abs(along) < 0.08 and abs(across) < 0.08:
            return -min(0.08 - abs(along), 0.08 - abs(across))
    return float(out.min())


def way_clear(x: float, z: float, theta: float, b: Any, sign: int, out_m: float) -> float:
    """The least clearance backing straight along the true heading (sign +1 forward, -1
    backward) until the centre is out_m or more from the face's depth (at most 0.6 m)."""
    least = math.inf
    for s in np.arange(0.0, 0.6, 0.005):
        px = x + sign * s * math.sin(theta)
        pz = z + sign * s * math.cos(theta)
        least = min(least, clearance(px, pz, theta, b))
        if abs(pz - b.z_m) >= out_m and s > 0:
            return least
    return least


def spin_clear(x: float, z: float, b: Any) -> float:
    """The least clearance of a spin in place (every heading)."""
    return min(clearance(x, z, a, b) for a in np.linspace(0, math.pi, 37))


def truth(w: Any, out_m: float = 0.25) -> dict[str, Any]:
    r, b = w.robot, target_box(w)
    hx, hz = r.half_extent()
    gap = max(b.x0_m - (r.x_m + hx), (r.x_m - hx) - b.x1_m)
    toward_camera = -1 if math.cos(r.theta) > 0 else 1  # the wheels' sign that lowers z
    return {
        "x": round(r.x_m, 4), "z": round(r.z_m, 4), "theta_deg": round(math.degrees(r.theta), 1),
        "half_across": round(hx, 4), "box": [round(b.z_m, 3), round(b.x0_m, 3), round(b.x1_m, 3)],
        "e": round(r.z_m - b.z_m, 4), "gap": round(gap, 4),
        "push_cmps": round(w.motor_faults.push_mps * 100, 2),
        "clear_now": round(clearance(r.x_m, r.z_m, r.theta, b), 4),
        "back_to_camera": round(way_clear(r.x_m, r.z_m, r.theta, b, toward_camera, out_m), 4),
        "back_away": round(way_clear(r.x_m, r.z_m, r.theta, b, -toward_camera, out_m), 4),
        "spin": round(spin_clear(r.x_m, r.z_m, b), 4),
    }


def estimate(servo: Any) -> dict[str, Any]:
    c, s, h = servo.controller, servo.estimator.state, servo.heading
    d: dict[str, Any] = {}
    if s is not None:
        d.update(z=round(s.z, 4), x=round(s.x, 4), vx_cmps=round(s.vx * 100, 2))
    if c is not None:
        d.update(target=round(c.target_m, 4), reach=round(c.reach_m(), 4),
                 keep_out=None if c.keep_out is None else [round(v, 3) for v in c.keep_out],
                 facing_away=c.facing_away, drift=c.drift())
        if s is not None and c.keep_out is not None:
            x0, x1 = c.keep_out
            d["gap"] = round(max(x0 - s.x, s.x - x1) - c.reach_m(), 4)
            d["e"] = round(s.z - c.target_m, 4)
    d["heading_deg"] = None if h.value is None else round(math.degrees(h.value), 1)
    d["spread_deg"] = round(math.degrees(h.spread), 1)
    return d


def note(kind: str, t: float, extra: dict[str, Any] | None = None) -> None:
    servo, w = st["servo"], st["w"]
    ev = {"kind": kind, "t": round(t, 2), "est": estimate(servo), "truth": truth(w)}
    ev.update(extra or {})
    st["events"].append(ev)


orig_update = C.Controller.update


def c_update(self: Any, obs: Any) -> Any:
    before = self.fault
    cmd = orig_update(self, obs)
    if not before and self.fault in (C.LINE_BLOCKED, C.PUSHED) and st["servo"] is not None:
        note("fires: " + self.fault, obs.t, {"obs_x": obs.lateral_m, "aspect": obs.aspect})
    return cmd


orig_bo = R.BackOff.update


def bo_update(self: Any, t: float, z: Any, gap: Any, *a: Any, **k: Any) -> Any:
    before, started = self.outcome, self.start_z is not None
    out = orig_bo(self, t, z, gap, *a, **k)
    names = ["target_m", "confirmed", "facing_away", "trim", "pushed_m", "floor",
             "steer", "settled", "turned_m", "away"]
    args = dict(zip(names, a))
    args.update(k)
    if not started and self.start_z is not None:  # its first move: the raw gap and reach then
        self.trace0 = (gap, args.get("turned_m"), t)
    if "--frames" in sys.argv and st["w"] is not None and not before:
        r = st["w"].robot
        print(f"  bo t {t:.2f} z {z} gap {gap if gap is None else round(gap, 4)} turned "
              f"{args.get('turned_m', 0):.4f} deeper {self.deeper} flipped {self.flipped} "
              f"start ({self.start_z and round(self.start_z, 3)}, "
              f"{self.start_gap and round(self.start_gap, 4)}) cmd {out} | true x "
              f"{r.x_m:+.4f} z {r.z_m:.4f} th {math.degrees(r.theta):+.1f} "
              f"gap {truth(st['w'])['gap']:+.4f}")
    if not before and self.outcome and self.outcome != R.DONE:
        note("back-off: " + self.outcome, t, {
            "bo": {"gap_est": gap, "deeper": self.deeper, "flipped": self.flipped,
                   "start_z": self.start_z, "start_gap": self.start_gap,
                   "turned_m": args.get("turned_m"), "away": args.get("away"),
                   "pushed_m": args.get("pushed_m"),
                   "first": getattr(self, "trace0", None)}})
    return out


orig_sf = L.Servo._spin_fault


def sf(self: Any, t: float, cmd: Any) -> str:
    why = orig_sf(self, t, cmd)
    if why == C.TURN_BLOCKED:
        aged = self._measured_t is not None and t - self._measured_t > self.cfg.target_age_s
        note("spin: " + why, t, {"phase": cmd.phase.name, "aged": aged,
                                 "readings": list(self.controller.readings_m)})
    return why


orig_decide = L.Servo._decide


def decide(self: Any, *a: Any, **k: Any) -> Any:
    st["servo"] = self
    return orig_decide(self, *a, **k)


C.Controller.update = c_update
R.BackOff.update = bo_update
L.Servo._spin_fault = sf
L.Servo._decide = decide
keep_world(st)


def main() -> None:
    idx = int(sys.argv[1])
    seed = int(sys.argv[sys.argv.index("--seed") + 1])
    args = build_parser().parse_args(["servo", "--sim", "--trials", "1", "--seed", str(seed)])
    tr = T.run_trial((seed, idx, parse_size(args.size), params_from_args(args), False))
    rec = {"seed": seed, "index": idx, "outcome": tr.outcome, "reason": tr.reason,
           "error_m": tr.error_m, "sim_s": tr.sim_s, "events": st["events"]}
    if "--json" in sys.argv:
        print(json.dumps(rec, default=str))
        return
    for ev in st["events"]:
        print(ev["kind"], "t", ev["t"])
        for key in ("est", "truth", "bo", "phase", "aged", "readings", "obs_x"):
            if key in ev:
                print("  ", key, ev[key])
    print("OUTCOME", tr.outcome, tr.reason, tr.error_m)


if __name__ == "__main__":
    main()
