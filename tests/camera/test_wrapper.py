"""A wrapped source (paced, recorded) is its inner source for all it does not do itself: the
inner's attributes, description and close; its own pairs come through the wrapper's _read."""

from __future__ import annotations

import numpy as np
import pytest

from host.camera.paced import PacedSource
from host.camera.source import StereoFrame, StereoSource
from host.camera.wrapper import WrappedSource


class Inner(StereoSource):
    def __init__(self, n: int) -> None:
        self.n, self.closed, self.clock = n, False, "the inner clock"

    def _read(self) -> StereoFrame | None:
        if not self.n:
            return None
        self.n -= 1
        image = np.zeros((4, 6), np.uint8)
        return StereoFrame(image, image, 0.0, 0.0)

    def describe(self) -> dict:
        return {"kind": "Inner", "left": self.n}

    def close(self) -> None:
        self.closed = True


def test_a_wrapped_source_is_its_inner_one_but_for_its_pairs() -> None:
    inner = Inner(2)
    with PacedSource(inner, speed=1000.0) as source:
        assert source.clock == "the inner clock"
        assert len(list(source)) == 2
        assert source.describe() == {"kind": "Inner", "left": 0}
        assert not inner.closed
    assert inner.closed


def test_a_wrapper_not_yet_given_its_source_says_so() -> None:
    bare = WrappedSource.__new__(WrappedSource)
    with pytest.raises(AttributeError):
        bare.clock  # noqa: B018
