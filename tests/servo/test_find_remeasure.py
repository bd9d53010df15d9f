"""The acquisition's find spin refused only on the object's aged depth waits, standing, for
the depth to be measured again, as the search spin does (loop._measure_before_spin; issue 23,
seed 17 #524 #553 #578 #612: "turning here would sweep the robot's body into the object" in
phase find, the robot in truth 0.24-1.24 m from the object's face, the spin clear by 17-63 cm)."""

from __future__ import annotations

from host.servo.controller import TURN_BLOCKED, Command
from host.servo.estimator import _State
from host.servo.phase import Phase
from host.sim.run import Setup, simulation


def test_a_find_spin_on_an_aged_depth_stands_for_a_re_measure_then_spins_or_stops() -> None:
    """Seed 17 #612's geometry: the robot 0.26 m in front of the object's believed depth, its
    centre inside the extent across (the extent runs to the image's edge), the depth 2.2 s
    old. The find spin is not sent: the robot stands and the tracker must measure the depth
    again (the controller's phase is the acquisition's business: left as it was); measured,
    the spin is checked on the fresh depth (clear: 26 cm in front of it); not measured within
    remeasure_stand_s, the aged check ends the run as before; beside the fresh depth the
    spin still stops."""
    with simulation(Setup(start_z_m=2.7, start_x_m=-0.1, seed=3)) as sim:
        servo = sim.servo
        c, tr = servo.controller, servo.tracker
        assert c is not None and tr is not None
        c.target_m, c.keep_out = 1.034, (-0.325, float("inf"))
        servo.estimator.state = _State(10.90, 0.778, -0.039, 0.0, -0.03)
        servo._measured_t = 8.8
        spin = Command(260, -260, Phase.FIND, None)
        c.phase = Phase.LOST  # the card lost: the acquisition finds it
        why = servo._measure_before_spin(11.0, spin)
        assert why.startswith("re-measuring the target before the spin") and not tr.confirmed
        assert c.phase == Phase.LOST
        late = 11.0 + servo.cfg.remeasure_stand_s + 0.1
        assert servo._measure_before_spin(late, spin) == ""
        assert servo._spin_fault(late, spin) == TURN_BLOCKED  # never measured: stops
        servo._spin_stand_since = None
        assert servo._measure_before_spin(11.0, spin)
        servo._measured_t = 11.5  # measured again while it stood
        assert servo._measure_before_spin(11.6, spin) == ""
        assert servo._spin_fault(11.6, spin) == ""  # the fresh depth: 26 cm away, clear
        c.target_m = 0.80  # the fresh depth beside the robot: the spin still stops
        assert servo._spin_fault(11.6, spin) == TURN_BLOCKED
