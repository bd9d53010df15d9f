"""OpenCV SGBM penalties in the tuning space follow the channels the backend matches on."""

from __future__ import annotations

import pytest

from host.stereo import MatcherParams
from host.tuning.spaces import make_space


@pytest.mark.parametrize(("colour", "channels"), [(True, 3), (False, 1)])
def test_sgbm_p1_p2_scale_with_the_channel_count(colour: bool, channels: int) -> None:
    space = make_space("opencv-sgbm", MatcherParams(colour=colour))
    names = [d.name for d in space.dims]
    for state in space.states()[:: max(1, space.size // 50)]:
        values = space.values(state)
        p = space.params(state)
        area = channels * p.block_size ** 2
        assert p.p1 == int(values["p1_factor"] * area)
        assert p.p2 == int(max(values["p2_factor"], values["p1_factor"]) * area)
    assert "p1_factor" in names and "p2_factor" in names


def test_grey_penalties_are_a_third_of_colour_ones() -> None:
    grey = make_space("opencv-sgbm", MatcherParams(colour=False))
    colour = make_space("opencv-sgbm", MatcherParams(colour=True))
    state = grey.states()[len(grey.states()) // 2]
    assert 3 * grey.params(state).p1 == colour.params(state).p1
    assert 3 * grey.params(state).p2 == colour.params(state).p2
