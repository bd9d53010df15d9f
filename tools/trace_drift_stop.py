"""Trace a trial's DRIFTED stop: estimate vs world truth when it fires; --run-on suppresses it.
The stands on a rate learnt driven (Servo._drift_stand) are counted, with the true gap at each
stand's start and end."""

import math
import sys

from trace_world import keep_world

from host.cli import build_parser
from host.commands.options import params_from_args
from host.commands.servo import parse_size
from host.servo import loop as L
from host.sim import trials as T

idx = int(sys.argv[1])
seed = int(sys.argv[sys.argv.index("--seed") + 1])
runon = "--run-on" in sys.argv
args = build_parser().parse_args(["servo", "--sim", "--trials", "1", "--seed", "13"])
params = params_from_args(args)
st = {"w": None, "first": None, "lastseen": None, "mingap": 9.0, "n": 0, "stands": []}
orig = L.Servo._spin_fault
orig_stand = L.Servo._drift_stand


def truth_gap(w):
    r = w.robot
    b = w.boxes[0] if w.boxes else None
    if b is None:
        return math.nan, math.nan
    hx, hz = r.half_extent()
    return max(r.x_m - b.x1_m, b.x0_m - r.x_m) - hx, hx


def sf(self, t, cmd):
    why = orig(self, t, cmd)
    w = st["w"]
    s = self.estimator.state
    c = self.controller
    if w is not None and s is not None:
        g, hx = truth_gap(w)
        if abs(w.robot.z_m - w.boxes[0].z_m) < 0.15 if w.boxes else False:
            st["mingap"] = min(st["mingap"], g)
        if t - s.t <= 0.05:  # the truth at the last sighting
            st["lastseen"] = (s.t, w.robot.x_m, w.robot.theta)
    if why == L.DRIFTED:
        st["n"] += 1
        if st["first"] is None:
            r = w.robot
            g, hx = truth_gap(w)
            st["first"] = t
            pred = s.x + s.vx * (t - s.t)
            reach = c.reach_m() if hasattr(c, "reach_m") else 0.08
            turns = [round(math.degrees(a), 1) for a in getattr(c, "turns", [])]
            print(
                f"DRIFTED t {t:.2f} phase {cmd.phase.name} cmd {cmd.left},{cmd.right}"
                f" unseen {t - s.t:.2f}s"
            )
            print(
                f"  est x {s.x:+.4f} vx {s.vx * 100:+.2f} cm/s pred x {pred:+.4f} z {s.z:.3f}"
                f" | reach_m {reach:.4f} turns(deg) {turns}"
            )
            print(f"  keep_out {c.keep_out} target {c.target_m:.3f}")
            e = self.estimator
            since = None if e._stopped_since is None else round(t - e._stopped_since, 2)
            fit = c.drift() if hasattr(c, "drift") else None
            print(f"  rate learnt while driven {e._driven_rate}, standing for {since} s;"
                  f" the hold's fit (t, x, rate) {fit}")
            print(
                f"  truth x {r.x_m:+.4f} z {r.z_m:.3f} theta {math.degrees(r.theta):+.1f}"
                f" half-across {hx:.4f} true gap {g:+.4f}; box {w.boxes[0]}"
            )
            print(f"  truth at last sighting: {st['lastseen']}; push_mps {w.motor_faults.push_mps}")
        if runon:
            return ""
    return why


def ds(self, t, cmd, fault):
    out = orig_stand(self, t, cmd, fault)
    w = st["w"]
    g = truth_gap(w)[0] if w is not None else math.nan
    stands = st["stands"]
    if out[1]:
        if not stands or stands[-1][-1] is not None:
            s = self.estimator.state
            stands.append([t, g, s.vx, w.motor_faults.push_mps, None])
    elif stands and stands[-1][-1] is None:
        stands[-1][-1] = (t, g, out[2])
    return out


L.Servo._spin_fault = sf
L.Servo._drift_stand = ds
keep_world(st)
tr = T.run_trial((seed, idx, parse_size(args.size), params, False))
for t0, g0, vx, push, end in st["stands"]:
    print(f"STAND from {t0:.2f} s (true gap {g0:+.4f}, rate {vx * 100:+.2f} cm/s learnt driven,"
          f" true push {push * 100:+.2f} cm/s): " + ("still standing at the end" if end is None else
          f"ended at {end[0]:.2f} s ({end[2] or 'released'}), true gap {end[1]:+.4f}"))
print(
    "OUTCOME",
    tr.outcome,
    tr.reason,
    "drift-fires",
    st["n"],
    "min true gap beside box",
    round(st["mingap"], 4),
)
