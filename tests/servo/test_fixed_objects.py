"""The robot's whole body among the scene's fixed objects, in closed loop: a box that stands
between the robot and its target (not the target) is passed clear of, not driven into (seed 8
trials 273 and 746 drove into the box at 1.8 m on their way to the target at 1.2-1.4 m: the
lane kept clear of the target alone, and the lane watch takes what the reference showed for
"not new"); a robot whose card is at the picture's edge is not driven out of the view (seed 8
trials 519 and 935: the probe move drove with the ring already cut by the edge); a robot
pushed toward the object while its card is hidden stops before it reaches it."""

from __future__ import annotations

import math

from host.sim.faults import Event, MotorFaults, WorldFaults
from host.sim.run import Setup, simulation
from host.sim.trials import _unsafe


def _run(setup: Setup, seconds: float) -> tuple[str, str, float]:
    """("unsafe", why) as the trials judge it, ("held", "") or ("stopped", reason); and the
    closest the robot's body came to the box at 1.8 m (m, side to side; negative: inside)."""
    with simulation(setup) as sim:
        servo, last_valid, gap = sim.servo, sim.source.t, math.inf
        box = sim.world.boxes[1]
        while sim.source.t < seconds:
            sim.step()
            row = servo.rows[-1]
            if math.isfinite(row.depth_m) and not row.reason:
                last_valid = row.t
            r = sim.world.robot
            if abs(r.z_m - box.z_m) < 0.06:
                gap = min(gap, box.x0_m - (r.x_m + r.body_width_m / 2))
            why = _unsafe(sim, last_valid, servo.stale_s)
            if why:
                return "unsafe", why, gap
            if servo.stop_reason:
                return "stopped", servo.stop_reason, gap
            if servo.held_for(1.0):
                return "held", "", gap
        return "unsettled", "", gap


def test_a_box_between_the_robot_and_the_target_is_passed_clear_of() -> None:
    """Facing the camera 2.5 m away, 15 cm right of centre: its line passes 1 cm inside the
    box at 1.8 m (0.22-0.55 m). The lane moves 15 cm clear of the box's side while the box is
    ahead, and the robot holds at the target beside its own box."""
    kind, why, gap = _run(Setup(start_z_m=2.5, start_x_m=0.15, start_theta=math.pi, seed=3),
                          40.0)
    assert kind == "held", why
    assert gap > 0.03


def test_a_card_at_the_pictures_edge_is_not_driven_out_of_view() -> None:
    """At 0.47 m, 15 cm right of centre and facing the camera 20 degrees off: the ring (46 px)
    is cut by the picture's right edge. No drive, probe or turn takes it farther out; the run
    ends with the reason (or holds, if the robot gets back into the view)."""
    kind, why, _ = _run(Setup(start_z_m=0.47, start_x_m=0.15,
                              start_theta=math.pi + math.radians(20), seed=3), 25.0)
    assert kind in ("held", "stopped"), why


def test_a_robot_pushed_beside_the_object_while_its_card_is_hidden_stops_the_run() -> None:
    """Started 5 cm behind the object's face, its body 6 cm from the object's side, pushed
    sideways toward the object (8 mm/s: a slope) while a post hides its card for 14 s (dev
    seed 101 trial 75: the acquisition waited and spun for 10 s unseen while the push took it
    into the box). The drift the estimator had before the card went brings the body onto the
    object within the push horizon: the run ends with the reason before it gets there."""
    faults = WorldFaults(motor=MotorFaults(push_mps=-0.008),
                         events=(Event(1.0, "occlude", fraction=1.0, duration_s=14.0),))
    kind, why, _ = _run(Setup(start_z_m=1.25, start_x_m=-0.04, faults=faults, seed=3), 20.0)
    assert kind == "stopped", why
