"""A campaign on worker processes calibrates each camera once and hands the calibration to the
workers (host.sim.campaign._calibrated_first): the key it computes for a trial is the one the
trial's simulation asks host.sim.run._calibration for, and a calibration given is used as it
is, without calibrating again."""

from __future__ import annotations

from typing import Any

import pytest

import host.sim.run as run
from host.sim.campaign import calibration_key
from host.sim.trials import trial_setup
from host.stereo.params import MatcherParams

PARAMS = MatcherParams(block_size=9, num_disparities=48, border="clip")


class Asked(Exception):
    pass


@pytest.mark.parametrize(("seed", "index"), [(105, 0), (105, 17), (3, 5), (107, 40)])
def test_the_key_is_what_the_trial_asks_for(seed: int, index: int,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    asked: list[Any] = []

    def record(*key: Any) -> Any:
        asked.append(key)
        raise Asked

    monkeypatch.setattr(run, "_calibration", record)
    job = (seed, index, (320, 240), PARAMS, False)
    with pytest.raises(Asked), run.simulation(trial_setup(*job), reference=False):
        pass
    assert asked == [calibration_key(job)]


def test_no_key_for_a_nominal_trial() -> None:
    assert calibration_key((105, 0, (320, 240), PARAMS, True)) is None


def test_a_calibration_given_is_used_without_calibrating(monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    def calibrate(*key: Any) -> Any:
        raise AssertionError(f"calibrated {key} again")

    monkeypatch.setattr(run, "_calibrate", calibrate)
    monkeypatch.setattr(run, "_given", {})
    given = object()
    key = ((320, 240), (-0.05, 0.01), 1234)
    run.keep_calibration(key, given)
    assert run._calibration(*key) is given
    with pytest.raises(AssertionError, match="again"):
        run._calibration((320, 240), (-0.05, 0.01), 1235)
