"""No single sighting is trusted: a look-alike of the marker (a dark disc in a light ring) is
not taken for it when it appears where the robot cannot be, and one that is all the servo
ever sees does not move the robot for long: it is left out, and the run stops with its reason
when nothing else is found."""

from __future__ import annotations

import math

from host.camera.source import StereoFrame
from host.servo.acquire import NOT_FOUND_AGAIN
from host.servo.loop import Servo
from host.servo.marker import MarkerPair, marker_candidates
from host.sim.faults import Event, WorldFaults
from host.sim.run import Setup, simulation

from .simulation import with_look_alike


def test_a_look_alike_seen_while_the_card_is_edge_on_is_not_taken_for_the_marker() -> None:
    """The issue's case: while the card turns edge-on a disc 51 px away at 8 px disparity (the
    wall's) shows; on main (711cc8e) it was taken for the marker at 3.2 m, and the robot drove
    on it for 8 s, into the camera. Here the robot turns, finds its own card and holds."""
    with simulation(Setup((320, 240), 1.5)) as sim:
        with_look_alike(sim, lambda s: abs(math.cos(s.world.robot.theta)) < 0.35,
                        du=51, dv=-6, disparity=8.0, radius=3.5)
        nearest = 1.5
        while sim.source.t < 25 and not sim.servo.stop_reason and not sim.servo.held_for(1.0):
            sim.step()
            nearest = min(nearest, sim.world.robot.z_m)
        assert sim.servo.outcome() == ("held", "")
        assert abs(sim.depth_error_m()) <= 0.02 and nearest > 1.1
        depths = [r.depth_m for r in sim.servo.rows if math.isfinite(r.depth_m)]
        assert max(abs(a - b) for a, b in zip(depths, depths[1:])) < 0.05  # no jump


def test_a_look_alike_that_does_not_move_when_the_robot_is_driven_is_left_out() -> None:
    """The robot's own card hidden, a disc on the wall is all there is: the probe move does not
    move it, so it is not the robot's; left out, nothing else is found and the run stops saying
    so (main drove on the wall's disc)."""
    with simulation(Setup((320, 240), 0.9)) as sim:
        sim.world.robot.marker_hidden = True
        with_look_alike(sim, lambda s: True, du=40, dv=-20, disparity=8.0, radius=4.0)
        sim.run(20.0)
        kind, why = sim.servo.outcome()
        assert kind == "stopped" and why.startswith(NOT_FOUND_AGAIN), why  # not "never seen"
        assert "did not move with the robot" in why
        assert any("did not move with the robot" in n for n in sim.servo.notes)
        assert sim.emulator.motors() == (0, 0)
        assert abs(sim.world.robot.z_m - 0.9) < 0.15  # the probe drove it blind that far


def test_another_robot_nearer_the_camera_is_not_taken_for_this_one() -> None:
    """Started at 2.9 m, a second robot with the same marker stands at 1.5 m beside the lane:
    its larger card is taken first, but it does not move under the probe; left out, the robot's
    own card is found and the robot holds at the box (the trials' 'decoy')."""
    faults = WorldFaults(events=(Event(0.0, "decoy", z_m=1.5, x_m=0.33),))
    with simulation(Setup((320, 240), 2.9, faults=faults)) as sim:
        sim.run(25.0)
        assert sim.servo.outcome() == ("held", "")
        assert abs(sim.depth_error_m()) <= 0.02
        assert any("did not move with the robot" in n for n in sim.servo.notes)


def test_a_look_alike_left_out_stays_out_when_the_estimate_would_admit_it() -> None:
    """Seed 11's trial 907: a look-alike shown not to move (left out by the acquisition) was
    admitted again 7 s later, during the spin back after the robot's own card was lost while
    driving: the estimate kept from before the loss had grown its gate over the look-alike's
    place, 0.25 m from it, and only a servo without an estimate left look-alikes out. Here the
    decoy is left out, the robot acquired, then its card hidden and the estimate put 3 cm from
    the decoy (inside the gate): the decoy must still not be taken for the marker."""
    faults = WorldFaults(events=(Event(0.0, "decoy", z_m=1.5, x_m=0.33),))
    with simulation(Setup((320, 240), 2.9, faults=faults)) as sim:
        servo = sim.servo
        while sim.source.t < 15 and not (servo.acquisition.done and servo._statics):
            sim.step()
        assert servo.acquisition.done and servo._statics  # the decoy was left out
        sim.world.robot.marker_hidden = True
        state = servo.estimator.state
        assert state is not None
        frame = sim.source.read()
        decoy = servo._sighting(frame.t_left, _decoy_pair(servo, frame))
        z, x = servo.estimator.position(decoy)
        assert abs(z - 1.5) < 0.1  # it is the decoy's card
        state.z, state.x, state.vz, state.vx, state.t = z + 0.03, x, 0.0, 0.0, frame.t_left
        assert servo.estimator.gate(decoy) == ""  # the gate alone would admit it
        seen = servo._see(frame)
        assert seen.pair is None


def _decoy_pair(servo: Servo, frame: StereoFrame) -> MarkerPair:
    """The decoy's marker pair in the frame (the robot's own card is hidden)."""
    cfg, g = servo.cfg, servo.geometry
    pairs = marker_candidates(frame.left, frame.right, cfg.marker_kind, cfg.marker_radius_m,
                              g.baseline_m, None, whole=True)
    assert pairs
    return pairs[0]
