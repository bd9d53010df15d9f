"""A search spin refused only on the object's aged depth waits, standing, for the depth to be
measured again (loop._measure_before_spin; issue 23, seed 14's 12 "turning here would sweep"
stops, the robot 0.3-1.8 m behind the object's believed depth)."""

from __future__ import annotations

from host.servo.controller import TURN_BLOCKED, Command
from host.servo.estimator import _State
from host.servo.phase import Phase
from host.sim.run import Setup, simulation


def test_a_search_spin_on_an_aged_depth_stands_for_a_re_measure_then_spins_or_stops() -> None:
    """Seed 13's trial 742's geometry (test_spin_aged_depth): the depth 2.04 s old, the spin
    beside the object's extent across. The spin is not sent: the robot stands (phase wait)
    and the tracker must measure the depth again; measured, the spin is checked on the fresh
    depth as before (clear here: 19 cm from the object's depth); not measured within
    remeasure_stand_s, the aged check ends the run as before. A spin clear anyway, or a
    fresh depth, is not held."""
    with simulation(Setup(start_z_m=2.7, start_x_m=-0.1, seed=3)) as sim:
        servo = sim.servo
        c, tr = servo.controller, servo.tracker
        assert c is not None and tr is not None
        c.target_m, c.keep_out = 1.056, (-0.325, -0.173)
        servo.estimator.state = _State(3.90, 1.244, -0.048, 0.0, -0.002)
        servo._measured_t = 3.81
        spin = Command(300, -300, Phase.SEARCH, None)
        assert servo._measure_before_spin(4.04, spin) == ""  # fresh: spins
        assert tr.confirmed
        why = servo._measure_before_spin(5.85, spin)
        assert why.startswith("re-measuring the target before the spin") and not tr.confirmed
        assert servo._measure_before_spin(5.85 + servo.cfg.remeasure_stand_s - 0.1, spin)
        late = 5.85 + servo.cfg.remeasure_stand_s + 0.1
        assert servo._measure_before_spin(late, spin) == ""
        assert servo._spin_fault(late, spin) == TURN_BLOCKED  # never measured: stops
        servo._spin_stand_since = None
        assert servo._measure_before_spin(5.85, spin)
        servo._measured_t = 6.3  # measured again while it stood
        assert servo._measure_before_spin(6.4, spin) == ""
        assert servo._spin_fault(6.4, spin) == ""  # the fresh depth: 19 cm away, clear
        servo.estimator.state = _State(3.90, 1.244, 0.10, 0.0, 0.0)  # 27 cm clear across
        assert servo._measure_before_spin(9.0, spin) == ""
