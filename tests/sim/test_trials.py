"""The trials runner's judgement: what counts as unsafe, and the summary's figures."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from host.sim.trials import Trial, _unsafe, summary
from host.sim.world import World


def sim_with(z: float, x: float = 0.0, duty: tuple[int, int] = (300, 300), t: float = 5.0):
    world = World()
    world.robot.z_m, world.robot.x_m = z, x
    return SimpleNamespace(world=world, emulator=SimpleNamespace(motors=lambda: duty),
                           source=SimpleNamespace(t=t))


def test_unsafe_outcomes_are_named() -> None:
    assert _unsafe(sim_with(1.5), last_valid=4.99, stale_s=0.3) == ""
    assert _unsafe(sim_with(1.2, x=-0.3), 4.99, 0.3) == "hit the object"
    assert _unsafe(sim_with(0.25), 4.99, 0.3) == "hit the camera"
    assert "left the view" in _unsafe(sim_with(1.5, x=0.6), 4.99, 0.3)
    assert "without a valid observation" in _unsafe(sim_with(1.5), 4.0, 0.3)
    # stopped motors are never unsafe for want of observations
    assert _unsafe(sim_with(1.5, duty=(0, 0)), 0.0, 0.3) == ""


def test_summary_counts_outcomes_and_percentiles() -> None:
    def trial(i: int, outcome: str, err: float, t: float, reason: str = "") -> Trial:
        return Trial(i, 1.0, 1.2, "", outcome, reason, err, 0.01, 0.0, t, 10.0)

    trials = [trial(i, "held", 0.001 * i, float(i)) for i in range(8)]
    trials += [trial(8, "stopped", math.nan, math.nan, "target vanished"),
               trial(9, "unsafe", 0.5, math.nan, "hit the object")]
    s = summary(trials)
    assert (s["trials"], s["held"], s["stopped"], s["unsafe"]) == (10, 8, 1, 1)
    assert s["hold_rate"] == pytest.approx(0.8)
    assert s["error_cm_max"] == pytest.approx(0.7)
    assert s["error_cm_p50"] == pytest.approx(0.35)
    assert s["reasons"] == {"stopped: target vanished": 1, "unsafe: hit the object": 1}


def test_a_trial_index_beyond_the_trials_is_refused() -> None:
    from host.errors import HostError
    from host.sim.trials import run_trials
    from host.stereo.params import MatcherParams

    with pytest.raises(HostError, match="--trial-index 5 is not among the 5 trials"):
        run_trials(5, 1, (320, 240), MatcherParams(), indices=[5])


def test_trial_setups_do_not_depend_on_which_others_run() -> None:
    """--trial-index I reproduces trial I of a full run: its world comes from (seed, I) only."""
    from host.sim.trials import trial_setup
    from host.stereo.params import MatcherParams

    a = trial_setup(1, 51, (320, 240), MatcherParams())
    trial_setup(1, 50, (320, 240), MatcherParams())
    assert trial_setup(1, 51, (320, 240), MatcherParams()) == a
