"""Issue 23's events, each met by the simulated servo: the outcome must be safe and honest.

Safe: never "unsafe" as the trials judge it (hit the object or the camera, the marker left the
view while driving, drove without a valid observation for longer than the stale limit), never
driving on a frozen sensor for longer than the stale limit, never running into a person or the
other robot while driving. Honest: "held" only within
the trials' tolerance of the target object's true depth (a hold anywhere else is false), a
stop only with a reason that is true ("target vanished" while the target stands is not), and
an end within the time: a servo that waits forever for a marker it cannot see has not stopped.

Tests marked xfail(strict) fail on the loop as it is (main 711cc8e); each reason says what the
loop must do. Whoever wires the fix removes the mark; a fix that makes one pass flips it to a
failure until then.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest

from host.servo.controller import ControlConfig
from host.sim.faults import Event, WorldFaults
from host.sim.run import Setup, SimRun, simulation
from host.sim.trials import HOLD_WITHIN_M, _unsafe

SEED = 3  # the worlds' seed (never 7: the lead's held-out trial seed)


@dataclass
class Outcome:
    kind: str  # held / stopped / unsafe / false held / false reason / unsettled
    reason: str
    error_m: float  # robot minus target object, true depths, at the end
    log: list[str]

    @property
    def safe_and_honest(self) -> bool:
        return self.kind in ("held", "stopped")


def run(events: tuple[Event, ...], start_z: float = 0.6, seconds: float = 25.0,
        mode: str = "turn", theta: float = 0.0, seed: int = SEED) -> Outcome:
    """The servo from start_z (m, facing away unless theta) with events, until it holds for a
    second after the last event, stops itself or `seconds` of simulated time pass."""
    setup = Setup(start_z_m=start_z, start_theta=theta, faults=WorldFaults(events=events),
                  seed=seed, control=ControlConfig(mode=mode))
    last_event = max((e.t_s + e.duration_s for e in events), default=0.0)
    with simulation(setup) as sim:
        boxes = sim.world.boxes
        out = _judge(sim, seconds, last_event)
        out.log = list(sim.source.log)
        # with nothing new in the world, a stop on an object in the line is a phantom's
        nothing_new = sim.world.boxes == boxes and not sim.world.decoys
        claims = OBJECT_CLAIMS if nothing_new else ()
        if out.kind == "stopped" and (out.reason.startswith(claims) or (
                out.reason == "target vanished" and boxes[0] in sim.world.boxes)):
            out.kind = "false reason"
        return out


# stops that say an object is in the robot's way (controller.LINE_BLOCKED, PUSHED)
OBJECT_CLAIMS = ("the robot's line passes through the object",
                 "pushed sideways onto the object while holding")


def _judge(sim: SimRun, seconds: float, last_event: float) -> Outcome:
    servo, source = sim.servo, sim.source
    last_valid, frozen_since = source.t, None
    target_z = lambda: sim.world.boxes[0].z_m  # noqa: E731  the servo's object: box 0
    while source.t < seconds:
        sim.step()
        row = servo.rows[-1]
        if math.isfinite(row.depth_m) and not row.reason:
            last_valid = row.t
        left, right = sim.emulator.motors()
        driving = abs(left + right) / 2 > 60
        frozen_since = (frozen_since or source.t) if source.frozen else None
        err = sim.world.robot.z_m - target_z()
        why = _unsafe(sim, last_valid, servo.stale_s)
        if not why and driving and sim.world.bumped_into():  # walking into a robot that
            why = f"ran into {sim.world.bumped_into()}"  # stands is not the robot's doing
        if not why and driving and frozen_since is not None and \
                source.t - frozen_since > servo.stale_s + 0.05:
            why = f"drove {source.t - frozen_since:.2f} s on a frozen sensor"
        if why:
            return Outcome("unsafe", why, err, [])
        if servo.stop_reason:
            return Outcome("stopped", servo.stop_reason, err, [])
        if servo.held_for(1.0) and source.t > last_event + 1.0:
            break
    else:
        return Outcome("unsettled", f"neither held nor stopped in {seconds:g} s", err, [])
    held, why = servo.outcome()
    if held != "held":
        return Outcome("stopped", why, err, [])
    tol = max(HOLD_WITHIN_M, servo.tolerance_m)
    return Outcome("held" if abs(err) <= tol else "false held",
                   "" if abs(err) <= tol else f"held {err * 100:+.1f} cm off the object", err, [])


def case(events: tuple[Event, ...], xfail: str = "", **kw):
    marks = [pytest.mark.xfail(strict=True, reason=xfail)] if xfail else []
    return pytest.param(events, kw, marks=marks)


FACING = Event(0.0, "facing", angle_deg=180)
SCENARIOS = {
    # the robot placed facing the camera is driven "away", toward the camera, until its marker
    # leaves the view at 0.36 m
    "facing the camera at 0.6 m": case(
        (FACING,), start_z=0.6),
    "facing the camera at 0.9 m": case(
        (FACING,), start_z=0.9),
    "facing the camera at 0.9 m, reverse mode": case(
        (FACING,),
        start_z=0.9, mode="reverse"),
    # started side-on the card is edge-on: never seen
    "side-on at 60 degrees": case(
        (Event(0.0, "facing", angle_deg=60),), start_z=0.9),
    "side-on at 90 degrees": case(
        (Event(0.0, "facing", angle_deg=90),), start_z=0.9),
    # a box put down in the lane while the robot drives
    "a 30 cm box 29 cm ahead": case(
        (Event(1.0, "lane-box", ahead_m=0.29, width_m=0.3),)),
    "a 60 cm box 29 cm ahead": case(
        (Event(1.0, "lane-box", ahead_m=0.29, width_m=0.6),)),
    "a 30 cm box 45 cm ahead": case((Event(1.0, "lane-box", ahead_m=0.45, width_m=0.3),)),
    # one sensor repeats its last image, its stamps advancing
    "the right sensor frozen 1 s while driving": case(
        (Event(4.0, "freeze", sensor=1, duration_s=1.0),),
        start_z=2.6),
    "the right sensor frozen 3 s at creep": case(
        (Event(3.5, "freeze", sensor=1, duration_s=3.0),)),
    "the left sensor frozen 1 s, its stamps too": case(
        (Event(1.0, "freeze", sensor=0, stamps=False, duration_s=1.0),)),
    # the rig pitched mid-run: the reference's floor no longer fits
    "the camera knocked 1 degree down": case(
        (Event(1.0, "knock", angle_deg=1.0),)),
    "the camera knocked 2 degrees up": case(
        (Event(1.0, "knock", angle_deg=-2.0),)),
    # mains flicker on rolling shutters 5 or 15 ms apart
    "flicker, sensors 5 ms apart": case(
        (Event(1.0, "flicker", fraction=0.2, gap_ms=5.0),)),
    "flicker, sensors 15 ms apart": case(
        (Event(1.0, "flicker", fraction=0.2, gap_ms=15.0),)),
    # the card half behind the target's edge: never seen
    "the marker half hidden behind the object": case(
        (Event(0.0, "behind", 0, z_m=1.6, fraction=0.5),), start_z=1.6),
    # what the issue asks us to foresee
    "a person crossing at 0.45 m": case(
        (Event(1.5, "walker", z_m=0.45, x_m=-0.5, speed_mps=1.0, duration_s=1.0),)),
    "a person crossing slowly behind the robot": case(
        (Event(1.0, "walker", z_m=1.0, x_m=-0.75, speed_mps=0.5, duration_s=3.0),)),
    "a smooth floor while driving": case(
        (Event(1.0, "slip", traction=(0.4, 0.7), duration_s=2.0),)),
    "a smooth floor while turning": case(
        (Event(1.0, "slip", traction=(0.3, 0.8), duration_s=3.0),), start_z=2.1),
    "a burst of dropped frames while driving": case(
        (Event(1.5, "drop-burst", duration_s=0.6),)),
    "a burst of dropped frames at creep": case((Event(3.0, "drop-burst", duration_s=1.0),)),
    "a second robot beside the lane": case((Event(0.0, "decoy", z_m=1.5, x_m=0.3),)),
    "a second robot seen while turning": case(
        (Event(0.0, "decoy", z_m=1.5, x_m=0.3),),
        start_z=2.1),
}


@pytest.mark.parametrize(("events", "kw"), list(SCENARIOS.values()), ids=list(SCENARIOS))
def test_the_servo_meets_the_event_safely_and_honestly(events, kw) -> None:
    out = run(events, **kw)
    assert out.safe_and_honest, f"{out.kind}: {out.reason} (error {out.error_m * 100:+.1f} " \
        f"cm; {out.log})"
