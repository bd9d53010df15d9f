"""A spin to find the card on an object's depth too old to trust (seed 13's trial 742)."""

from __future__ import annotations

from host.servo.controller import TURN_BLOCKED, Command
from host.servo.estimator import _State
from host.servo.phase import Phase
from host.sim.run import Setup, simulation


def test_a_search_spin_on_an_aged_depth_must_clear_the_objects_extent_at_any_depth() -> None:
    """Seed 13's trial 742 (979f477): turned round at 1.24 m beside the object (believed at
    1.056 m, x -0.325..-0.173 m; the robot at x -0.048 m), the card hidden by a box put in the
    lane at 3.93 s, the object moved to 1.257 m at 4.01 s, unseen: the search spin went on 3 s
    (no re-measure while spinning), the check 19 cm from the object's believed depth saw
    nothing, and the body's corner swept into the object's end at 7.07 s. With the depth
    measured 0.23 s before, the spin is clear (as it was); 2.04 s after (older than
    target_age_s), the spin beside the object's extent is refused at any depth; clear of that
    extent across, it spins."""
    with simulation(Setup(start_z_m=2.7, start_x_m=-0.1, seed=3)) as sim:
        servo = sim.servo
        c = servo.controller
        assert c is not None
        c.target_m, c.keep_out = 1.056, (-0.325, -0.173)
        servo.estimator.state = _State(3.90, 1.244, -0.048, 0.0, -0.002)
        servo._measured_t = 3.81
        spin = Command(300, -300, Phase.SEARCH, None)
        assert servo._spin_fault(4.04, spin) == ""
        assert servo.cfg.target_age_s < 5.85 - 3.81
        assert servo._spin_fault(5.85, spin) == TURN_BLOCKED
        servo.estimator.state = _State(3.90, 1.244, 0.10, 0.0, 0.0)  # 27 cm clear across
        assert servo._spin_fault(5.85, spin) == ""
        servo.estimator.state = _State(3.90, 1.244, -0.048, 0.0, -0.002)
        assert servo._spin_fault(5.85, Command(0, 0, Phase.WAIT, None)) == ""  # standing
