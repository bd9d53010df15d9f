"""inputs._row_mode counts its 0.25 px bins with a compiled loop instead of np.histogram
(issue 25: 3.6 % of a trial's CPU); its answer must be np.histogram's fullest bin's centre
to the bit: on rows of a rendered scene's disparity map, on constant rows, values lying on
the bins' edges (the last edge too), ties between bins (the first wins), float32 and float64
rows, a single value and wide ranges."""

from __future__ import annotations

import numpy as np
import pytest

from host.servo import inputs
from host.servo.perception import match_exposure
from host.sim.faults import CameraFaults
from host.sim.renderer import Renderer
from host.sim.world import World
from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams


def histogram_mode(row: np.ndarray) -> float:
    """_row_mode as it was at 4db45a1 (the reference)."""
    hist, edges = np.histogram(row, bins=np.arange(row.min(), row.max() + 0.5, 0.25))
    k = int(np.argmax(hist))
    return float((edges[k] + edges[k + 1]) / 2)


def rows() -> list[np.ndarray]:
    rng = np.random.default_rng(25)
    out: list[np.ndarray] = []
    for dtype in (np.float32, np.float64):
        out += [np.full(200, 7.3, dtype), np.array([12.0], dtype), np.array([0.0, 0.25], dtype)]
        start = dtype(rng.uniform(0, 30))
        on_edges = np.arange(start, start + 5, 0.25).astype(dtype)  # every value on an edge
        out += [on_edges, np.repeat(on_edges, 3), np.concatenate([on_edges, on_edges[-1:]])]
        two = np.array([5.0] * 10 + [5.5] * 10 + [6.0] * 9, dtype)  # a tie: the first bin
        out += [two, two[::-1].copy()]
        for _ in range(200):
            n = int(rng.integers(1, 400))
            base = rng.uniform(0, 60)
            vals = base + rng.normal(0, rng.uniform(0.05, 3), n)
            if rng.random() < 0.5:  # sub-pixel disparities on a coarse grid: many equal values
                vals = np.round(vals * 4) / 4 + rng.choice([0.0, 0.125], n)
            if rng.random() < 0.3:
                vals[: n // 10] = rng.uniform(0, 64, n // 10)  # outliers far off
            out.append(vals.astype(dtype))
    return out


def test_the_mode_is_the_histograms_on_made_up_rows() -> None:
    for row in rows():
        got, want = inputs._row_mode(row), histogram_mode(row)
        assert np.float64(got).tobytes() == np.float64(want).tobytes(), row


def test_the_mode_is_the_histograms_on_a_rendered_maps_rows() -> None:
    world = World(seed=4)
    f = Renderer(world, CameraFaults(noise=2.0), seed=4).frame()
    disp = compute_disparity(f.left, match_exposure(f.left, f.right),
                             MatcherParams.for_matcher(MatcherParams.matcher).validate())
    seen = 0
    for y in range(disp.shape[0]):
        row = disp[y][np.isfinite(disp[y])]
        if row.size:
            seen += 1
            assert inputs._row_mode(row) == histogram_mode(row), y
    assert seen > 150


@pytest.mark.parametrize("values", [[1.0, np.nan, 2.0], [np.nan, 3.0]])
def test_nan_rows_fail_as_the_histogram_did(values: list[float]) -> None:
    """The servo never passes a NaN (it keeps the finite pixels); one would make np.arange's
    range NaN, and both versions raise alike."""
    row = np.array(values, np.float32)
    with pytest.raises(ValueError):
        histogram_mode(row)
    with pytest.raises(ValueError):
        inputs._row_mode(row)
