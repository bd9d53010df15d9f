"""Randomized trials of the servo in the simulated world (host servo --sim --trials N).

Each trial: the target box at a random depth, the robot at a random start 0.4-3.0 m from the
camera (in front of or behind the target), every fault of host.sim.faults at a random size
(none with nominal=True), run in lockstep simulated time until the servo holds (after the last
scene event), stops itself, or 45 s pass. Outcomes:

    held    holding, within 2 cm of the object's true depth (or within the tolerance the servo
            announced it had to widen to)
    missed  holding, but farther than that from the object's true depth
    stopped a safe stop, with its reason (target vanished, marker lost, link error ...)
    unsafe  the robot hit the object or the camera, its marker left the view while the motors
            drove, or the firmware drove on with no valid observation for longer than the
            stale limit
"""

from __future__ import annotations

import dataclasses
import json
import math
import multiprocessing
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from host.camera.source import CameraError
from host.errors import HostError
from host.files import write_text_atomic
from host.link.client import LinkError
from host.servo.controller import ControlConfig
from host.sim.faults import WorldFaults, random_faults
from host.sim.run import Setup, SimRun, simulation
from host.sim.world import Box
from host.stereo.params import MatcherParams

MAX_S = 45.0
SETTLE_S = 1.0
LOST_GIVE_UP_S = 5.0
HOLD_WITHIN_M = 0.02


@dataclass
class Trial:
    index: int
    start_m: float
    target_m: float  # the object's true depth at the start
    faults: str  # a short description
    outcome: str  # held / missed / stopped / unsafe
    reason: str
    error_m: float  # robot's true depth minus the object's, at the end
    tolerance_m: float  # as the servo announced it
    overshoot_m: float
    time_to_hold_s: float
    sim_s: float


def trial_setup(seed: int, index: int, size: tuple[int, int], params: MatcherParams,
                nominal: bool = False) -> Setup:
    rng = np.random.default_rng([seed, index])
    target_z = float(rng.uniform(1.0, 1.5))
    boxes = (Box(target_z, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30),
             Box(2.4, 0.60, 0.95, 0.55))
    start = float(rng.uniform(0.4, 3.0))
    x = float(rng.uniform(-0.04, 0.04)) * start
    theta = math.radians(float(rng.uniform(-4, 4)))
    faults = WorldFaults() if nominal else random_faults(rng, target_z)
    if not nominal:  # lenses from a stream of their own: the other faults stay as they were
        lens = np.random.default_rng([seed, index, 1]).uniform(-0.1, 0.04, 2)
        faults = dataclasses.replace(faults, camera=dataclasses.replace(
            faults.camera, distortion=(float(lens[0]), float(lens[1]))))
    return Setup(size, start, x, theta, boxes, faults, seed=int(rng.integers(1 << 30)),
                 params=params.replace(colour=False), control=ControlConfig())


def _describe(f: WorldFaults) -> str:
    m, c = f.motor, f.camera
    parts = [f"gain {m.gain[0]:.2f}/{m.gain[1]:.2f}", f"latency {m.latency_ms:.0f} ms",
             f"skew {c.skew_ms:.0f} ms", f"drop {c.drop:.2f}"]
    parts += [e.kind for e in f.events]
    if f.link.silent_after_ms is not None:
        parts.append("silent")
    return ", ".join(parts)


def _unsafe(sim: SimRun, last_valid: float, stale_s: float) -> str:
    w, r = sim.world, sim.world.robot
    left, right = sim.emulator.motors()
    driving = abs(left + right) / 2 > 60
    for b in w.boxes:
        if b.x0_m - 0.08 < r.x_m < b.x1_m + 0.08 and abs(r.z_m - b.z_m) < 0.06:
            return "hit the object"
    if r.z_m < 0.3:
        return "hit the camera"
    u, v, _ = w.marker_truth()
    ring = w.geometry.focal_px * r.marker_radius_m * r.ring_ratio / r.z_m
    width, height = w.size
    if driving and not (ring <= u <= width - ring and ring <= v <= height - ring):
        return "the marker left the view while driving"
    if driving and sim.source.t - last_valid > stale_s + 0.05:
        return f"drove {sim.source.t - last_valid:.2f} s without a valid observation"
    return ""


def run_trial(job: tuple[int, int, tuple[int, int], MatcherParams, bool]) -> Trial:
    seed, index, size, params, nominal = job
    setup = trial_setup(seed, index, size, params, nominal)
    target0 = setup.boxes[0].z_m if setup.boxes else math.nan
    last_event = max((e.t_s + e.duration_s for e in setup.faults.events), default=0.0)
    outcome, reason, tol = "stopped", "", math.nan
    with simulation(setup, reference=False) as sim:
        servo = sim.servo
        try:
            servo.reference()
            last_valid, lost_since = 0.0, None
            while sim.source.t < MAX_S:
                sim.step()
                row = servo.rows[-1]
                if math.isfinite(row.depth_m) and not row.reason:
                    last_valid = row.t
                why = _unsafe(sim, last_valid, servo.stale_s)
                if why:
                    outcome, reason = "unsafe", why
                    break
                if servo.stop_reason:
                    reason = servo.stop_reason
                    break
                lost_since = (lost_since or row.t) if row.phase == "lost" else None
                if lost_since is not None and row.t - lost_since > LOST_GIVE_UP_S:
                    reason = f"marker lost for {LOST_GIVE_UP_S:g} s"
                    break
                if servo.held_for(SETTLE_S) and sim.source.t > last_event + 2.5:
                    break
            else:
                reason = f"did not settle in {MAX_S:g} s"
            tol = servo.tolerance_m
        except (LinkError, CameraError) as e:
            reason = f"link: {e}" if isinstance(e, LinkError) else str(e)
        if outcome != "unsafe" and not reason:
            held, why = servo.outcome()
            err = sim.depth_error_m()
            within = abs(err) <= max(HOLD_WITHIN_M, tol if math.isfinite(tol) else 0.0)
            outcome = ("held" if within else "missed") if held == "held" else "stopped"
            reason = why
        err = sim.depth_error_m() if sim.world.boxes else math.nan
        z = sim.depths or [setup.start_z_m]
        final = sim.world.nearest_box().z_m if sim.world.boxes else target0
        over = max(z) - final if setup.start_z_m < final else final - min(z)
        t_hold = math.nan
        if outcome in ("held", "missed"):
            rows = servo.rows
            k = len(rows) - 1
            while k > 0 and rows[k - 1].phase == "hold":
                k -= 1
            t_hold = rows[k].t - rows[0].t
        return Trial(index, setup.start_z_m, target0, _describe(setup.faults), outcome, reason,
                     err, tol, max(0.0, over), t_hold, sim.source.t)


def _pct(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else math.nan


def summary(trials: list[Trial]) -> dict:
    held = [t for t in trials if t.outcome == "held"]
    errs = [abs(t.error_m) * 100 for t in trials if t.outcome in ("held", "missed")]
    times = [t.time_to_hold_s for t in trials if t.outcome in ("held", "missed")]
    reasons: dict[str, int] = {}
    for t in trials:
        if t.outcome in ("stopped", "unsafe"):
            key = f"{t.outcome}: {t.reason}"
            reasons[key] = reasons.get(key, 0) + 1
    return {"trials": len(trials), "held": len(held),
            "missed": sum(t.outcome == "missed" for t in trials),
            "stopped": sum(t.outcome == "stopped" for t in trials),
            "unsafe": sum(t.outcome == "unsafe" for t in trials),
            "hold_rate": len(held) / len(trials) if trials else math.nan,
            "error_cm_p50": _pct(errs, 50), "error_cm_p95": _pct(errs, 95),
            "error_cm_max": max(errs) if errs else math.nan,
            "time_s_p50": _pct(times, 50), "time_s_p95": _pct(times, 95),
            "reasons": reasons}


def run_trials(n: int, seed: int, size: tuple[int, int], params: MatcherParams,
               json_path: Path | None = None, workers: int = 2, nominal: bool = False,
               out=sys.stdout, indices: list[int] | None = None) -> int:
    """Runs trials 0..n-1 (or only those of `indices`: trial i is the same whatever else
    runs), prints each and the summary, optionally writes them as JSON."""
    if indices and max(indices) >= n:
        raise HostError(f"--trial-index {max(indices)} is not among the {n} trials")
    jobs = [(seed, i, size, params, nominal) for i in (sorted(set(indices)) if indices
                                                       else range(n))]
    trials: list[Trial] = []
    world = "nominal" if nominal else "faulty"
    which = f"{len(jobs)} of {n}" if indices else f"{n}"
    print(f"{which} trials of the {world} world at {size[0]}x{size[1]}, seed {seed}", file=out)
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(max(1, min(workers, len(jobs)))) as pool:
        for t in pool.imap(run_trial, jobs):
            trials.append(t)
            print(f"  {t.index:3d}  start {t.start_m:4.2f} m  target {t.target_m:4.2f} m  "
                  f"{t.outcome:<7} err {t.error_m * 100:+6.2f} cm  overshoot "
                  f"{t.overshoot_m * 100:5.1f} cm  hold at {t.time_to_hold_s:5.1f} s  "
                  f"{t.reason}  [{t.faults}]", file=out, flush=True)
    s = summary(trials)
    print(f"held {s['held']}/{s['trials']} ({s['hold_rate']:.0%}), missed {s['missed']}, "
          f"safe stops {s['stopped']}, unsafe {s['unsafe']}; |error| p50 "
          f"{s['error_cm_p50']:.2f} cm, p95 {s['error_cm_p95']:.2f} cm, max "
          f"{s['error_cm_max']:.2f} cm; time to hold p50 {s['time_s_p50']:.1f} s, p95 "
          f"{s['time_s_p95']:.1f} s", file=out)
    for k, v in s["reasons"].items():
        print(f"  {v:3d} x {k}", file=out)
    if json_path is not None:
        write_text_atomic(json_path, json.dumps({"world": world, "seed": seed, "size": size,
                                                 "summary": s,
                                                 "trials": [asdict(t) for t in trials]},
                                                indent=1) + "\n")
    return 0
