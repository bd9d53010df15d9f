"""The card unseen beside the object, a sideways rate that would bring the body onto it within
the unseen horizon ends the run ("drifting ... unseen") at once only when the robot showed that
rate standing; a rate learnt while it was driven (a drive's curve, a spin's swinging card: seed
17's trials 86, 188, 190, 636, 909, the true push the other way or half of it) makes it stand
until the card shows the rate standing, and the same check decides on that rate; the run ends
as before once the body, moved on at the driven rate, comes within the push horizon of the
object (loop.Servo._drift_stand, Estimator.rate_stood; issue 23)."""

from __future__ import annotations

from collections.abc import Iterator
from types import SimpleNamespace

import numpy as np
import pytest

from host.camera.geometry import Geometry
from host.servo.controller import DRIFTED, Command
from host.servo.estimator import Estimator, Sighting, _State
from host.servo.loop import Servo
from host.servo.phase import Phase
from host.sim.faults import Event, MotorFaults, WorldFaults
from host.sim.run import Setup, simulation
from tests.servo.judged import Judged

G = Geometry.minoru_default(320, 240)
FB = G.focal_px * G.baseline_m


def _sighting(t: float, z: float, x: float) -> Sighting:
    d = FB / z
    return Sighting(t, d, G.cx + x * d / G.baseline_m, 0.5 * d)


def test_a_lateral_rate_learnt_driven_is_stood_only_after_sightings_standing() -> None:
    """Driven sideways (a curve) the lateral rate is not one shown standing; the sightings of
    the stop's run-down do not count, stood_sightings taken standing after it do. A state
    only ever seen standing, or forgotten, has shown its rate standing."""
    est = Estimator(G)
    n = est.cfg.stood_sightings
    est.commanded(-1.0, 0, 0)  # told to stand a second before the first sighting
    t = 0.0
    for _ in range(10):
        est.accept(_sighting(t, 1.2, 0.0))
        est.commanded(t, 0, 0)
        t += 1 / 30
    assert est.rate_stood
    for k in range(10):  # driven on a curve: 1.2 cm/s sideways
        est.commanded(t, 300, 320)
        est.accept(_sighting(t, 1.2, -0.012 * (k + 1) / 30))
        t += 1 / 30
    assert not est.rate_stood and est.state is not None and est.state.vx < -0.005
    est.commanded(t, 0, 0)  # told to stand
    stop = t
    while t - stop < est.cfg.run_down_s:  # the run-down's sightings: not standing
        est.accept(_sighting(t, 1.2, -0.04))
        est.commanded(t, 0, 0)
        t += 1 / 30
    for _ in range(n - 1):
        est.accept(_sighting(t, 1.2, -0.04))
        est.commanded(t, 0, 0)
        t += 1 / 30
    assert not est.rate_stood
    est.accept(_sighting(t, 1.2, -0.04))
    assert est.rate_stood
    est.commanded(t, 200, 200)
    est.accept(_sighting(t + 1 / 30, 1.2, -0.04))  # driven once more
    assert not est.rate_stood
    est.forget()
    assert est.rate_stood


@pytest.fixture(scope="module")
def scene() -> Iterator[Servo]:
    """A servo after its reference phase (seed 3's scene)."""
    with simulation(Setup(start_z_m=2.7, start_x_m=-0.1, seed=3)) as sim:
        yield sim.servo


T0, Z, X, VX = 10.0, 1.2, -0.018, -0.012  # 16 cm centre to side, 1.2 cm/s toward it
KEEP_OUT = (-0.389, -0.178)  # seed 12 trial 213's object


def _beside(servo: Servo, driven: bool) -> Servo:
    """The robot estimated 1.2 m from the camera beside the object (6 cm from the 2 cm margin
    with the square body), its last sighting at T0 with VX toward the object: learnt while
    driven, or shown standing."""
    c = servo.controller
    assert c is not None
    c.target_m, c.keep_out, c.fault, c.phase = 1.213, KEEP_OUT, "", Phase.WAIT
    c.turns.clear()  # the square body: reach_m is half its width
    servo.estimator.state = _State(T0, Z, X, 0.0, VX)
    servo.estimator._lateral_driven = driven
    servo.stop_reason = ""
    servo._drift_since = None
    servo.acquisition.phase = Phase.DONE
    servo._measured_t = T0  # the target's depth fresh (no stand for a re-measure)
    servo._still_since = None
    return servo


def _frame(servo: Servo, t: float, cmd: Command) -> tuple[Command, str]:
    """The command the servo sends at t for cmd, the card unseen since T0, and why."""
    frame = SimpleNamespace(left=np.zeros((240, 320)), t_left=t)
    return servo._watch_lane(frame, t, cmd, "")  # type: ignore[arg-type]


def test_a_drift_on_a_rate_learnt_driven_stands_until_the_push_horizon(scene: Servo) -> None:
    """The card unseen 0.2 s, the rate learnt driven would bring the body within the margin in
    4.8 s (< 6 s: the run ended here before): it stands (the command a stop, no run's end),
    every frame checked again on the body moved on at that rate, and the run ends named once
    that rate would bring it onto the margin within the push horizon (3 s): still that far
    from it, so a true push at that rate ends the run before it could touch."""
    servo = _beside(scene, driven=True)
    c = servo.controller
    assert c is not None
    cmd = Command(0, 0, Phase.LOST, None)
    t, stood = T0 + 0.2, 0
    while t < T0 + 6.0:
        sent, why = _frame(servo, t, cmd)
        if servo.stop_reason:
            break
        assert sent.is_stop and why.startswith(f"standing: {DRIFTED}"), why
        stood += 1
        t += 1 / 30
    assert servo.stop_reason == DRIFTED and stood > 30
    gap = (X + VX * (t - T0)) - c.reach_m() - c.cfg.block_margin_m - KEEP_OUT[1]
    to_margin = gap / -VX
    assert c.cfg.push_horizon_s - 1 / 30 <= to_margin <= c.cfg.push_horizon_s, to_margin


def test_a_drift_on_a_rate_shown_standing_still_ends_the_run_at_once(scene: Servo) -> None:
    """The same drift, its rate shown standing: the run ends on the first frame, as before."""
    servo = _beside(scene, driven=False)
    sent, _ = _frame(servo, T0 + 0.2, Command(0, 0, Phase.LOST, None))
    assert sent.phase == Phase.STOP and servo.stop_reason == DRIFTED


@pytest.mark.parametrize("phase", [Phase.TURN, Phase.FIND])
def test_a_drift_in_a_spin_that_cannot_wait_ends_the_run(scene: Servo, phase: Phase) -> None:
    """A turn round (its timing is the card's) or the acquisition's spin: not held."""
    servo = _beside(scene, driven=True)
    sent, _ = _frame(servo, T0 + 0.2, Command(400, -400, phase, None))
    assert sent.phase == Phase.STOP and servo.stop_reason == DRIFTED


@pytest.mark.parametrize("cmd", [Command(300, -300, Phase.SEARCH, None),
                                 Command(190, 180, Phase.CREEP, 0.01)])
def test_the_controllers_spin_or_drive_is_not_sent_in_the_stand(scene: Servo,
                                                               cmd: Command) -> None:
    """The search spin after a turn, or (the stand on) a creep: not sent; the robot stands and
    the controller is told (its creep floor must not rise)."""
    servo = _beside(scene, driven=True)
    sent, why = _frame(servo, T0 + 0.2, Command(0, 0, Phase.LOST, None))
    assert why.startswith("standing") and servo._drift_since is not None
    sent, why = _frame(servo, T0 + 0.25, cmd)
    assert sent.is_stop and sent.phase == Phase.WAIT and not servo.stop_reason, why
    assert servo.controller is not None and servo.controller.phase == Phase.WAIT


@pytest.mark.parametrize(("vx", "stops"),
                         [(VX, True), (-0.010, True), (-0.006, False), (0.004, False)])
def test_the_rate_shown_standing_decides_as_the_check_did(scene: Servo, vx: float,
                                                          stops: bool) -> None:
    """In the stand, the card back and the rate shown standing: the check on that rate
    (its unseen horizon, 6 s) ends the run (1.2 or 1.0 cm/s toward the object, 5.5 cm from the
    margin), or (0.6 cm/s toward it, or away) the stand ends and the controller's command goes
    out."""
    servo = _beside(scene, driven=True)
    _frame(servo, T0 + 0.2, Command(0, 0, Phase.LOST, None))
    assert servo._drift_since is not None and not servo.stop_reason
    t = T0 + 0.9  # seen again, standing, the rate shown standing
    servo.estimator.state = _State(t, Z, X + VX * 0.4, 0.0, vx)
    servo.estimator._lateral_driven = False
    hold = Command(0, 0, Phase.HOLD, 0.001)
    sent, why = _frame(servo, t, hold)
    if stops:
        assert servo.stop_reason == DRIFTED and sent.phase == Phase.STOP
    else:
        assert sent == hold and not why and not servo.stop_reason
        assert servo._drift_since is None


def test_a_rate_not_yet_shown_standing_releases_nothing(scene: Servo) -> None:
    """In the stand, the card back for a few sightings that turn the rate away from the
    object (not yet stood_sightings): the robot stands on (a rate half learnt releases
    nothing, a command that cannot wait does not either); at unseen_horizon_s -
    push_horizon_s of standing with no rate shown standing the run ends as before."""
    servo = _beside(scene, driven=True)
    c = servo.controller
    assert c is not None
    _frame(servo, T0 + 0.2, Command(0, 0, Phase.LOST, None))
    since = servo._drift_since
    assert since is not None
    servo.estimator.state = _State(T0 + 0.6, Z, X + VX * 0.4, 0.0, 0.002)  # still driven
    hold = Command(0, 0, Phase.HOLD, 0.001)
    bound = since + c.cfg.unseen_horizon_s - c.cfg.push_horizon_s
    sent, why = _frame(servo, bound - 0.05, hold)
    assert why.startswith(f"standing: {DRIFTED}") and not servo.stop_reason, why
    sent, why = _frame(servo, bound, hold)
    assert servo.stop_reason == DRIFTED and sent.phase == Phase.STOP


def test_a_turn_round_in_the_stand_ends_the_run_on_a_rate_not_yet_shown(scene: Servo) -> None:
    """The card back (the rate half learnt, away from the object) and the controller starts a
    turn round, which cannot wait: the run ends as the check first said."""
    servo = _beside(scene, driven=True)
    _frame(servo, T0 + 0.2, Command(0, 0, Phase.LOST, None))
    servo.estimator.state = _State(T0 + 0.6, Z, X + VX * 0.4, 0.0, 0.002)
    sent, _ = _frame(servo, T0 + 0.6, Command(400, -400, Phase.TURN, None))
    assert servo.stop_reason == DRIFTED and sent.phase == Phase.STOP


def test_a_robot_pushed_onto_the_object_at_the_rate_it_drove_with_stops_in_time() -> None:
    """Closed loop: started 5 cm behind the object's face, its body 8 cm from the object's
    side, pushed toward it at 8 mm/s (a slope); a post hides its card for good from 1.45 s,
    as its creep ends: the rate it had is the creep's and the push's, not shown standing. It
    stands, and the run still ends named before the body touches the object (the trials'
    judge, every frame), the true body then at least the push's push_horizon_s from the
    object's side (the run ended here at 1.6 s before the stand)."""
    faults = WorldFaults(motor=MotorFaults(push_mps=-0.008),
                         events=(Event(1.45, "occlude", fraction=1.0, duration_s=30.0),))
    with simulation(Setup(start_z_m=1.25, start_x_m=-0.02, faults=faults, seed=3)) as sim:
        servo, judged = sim.servo, Judged(sim)
        box = sim.world.boxes[0]
        stood = 0
        while sim.source.t < 30.0 and not servo.stop_reason:
            assert not judged.step()
            stood += servo.rows[-1].reason.startswith(f"standing: {DRIFTED}")
        r = sim.world.robot
        gap = r.x_m - r.half_extent()[0] - box.x1_m
        assert servo.controller is not None
        horizon = servo.controller.cfg.push_horizon_s
    assert servo.stop_reason == DRIFTED and stood > 30, (servo.stop_reason, stood)
    assert gap > 0.008 * horizon, gap
