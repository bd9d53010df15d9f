"""What makes the loop fast keeps every observation it had: the target's re-measure on a map
matched a band of rows per frame is the whole-map measure, and no frame of the robot phase
matches more than one band; the marker window's match agrees with the whole map; the exposure
match by look-up table is the per-pixel formula; the first level of the nearest-object sweep
does not depend on where the search starts."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from host.servo.loop import marker_disparity
from host.servo.marker import find_marker
from host.servo.perception import (
    StripMap,
    fit_floor,
    match_exposure,
    nearest_object,
    without_floor,
)
from host.sim.faults import Event, WorldFaults
from host.sim.renderer import Renderer
from host.sim.run import Setup, simulation
from host.sim.world import Box, World
from host.stereo import MatcherParams, compute_disparity

ALONE = (Box(1.2, -0.50, -0.18, 0.38),)  # the target box and nothing else: no next object
# The camera's size and search range, where the re-measure's map takes four frames as it is
# (perception.STRIP_WORK); at the simulation's usual 320x240 / 48 it takes one.
CAMERA = dict(size=(640, 480), params=replace(Setup.params, num_disparities=64))


def _pair(size=(320, 240), z=1.6, seed=5):
    world = World.for_size(*size, seed=seed)
    world.robot.z_m = z
    return world, Renderer(world, seed=seed).frame()


@pytest.mark.parametrize("params", [
    MatcherParams(),
    MatcherParams(border="clip", median=5, fill=True, lr_check=1.0, uniqueness_ratio=10),
    MatcherParams(matcher="ncc", block_size=5, border="clip", num_disparities=48),
])
def test_strip_map_is_the_whole_map_of_the_frame(params: MatcherParams) -> None:
    _, frame = _pair()
    strips = StripMap(params, frame.left.shape, work=600_000)
    assert strips.strips >= 4
    for _ in range(strips.strips):
        assert strips.add(frame.left, frame.right) is None
    got = strips.add(frame.left, frame.right)
    assert got is not None and not strips.busy
    want = compute_disparity(frame.left, frame.right, params)
    np.testing.assert_array_equal(got, want)  # NaN where the whole map has none


def test_strip_map_leaves_out_each_frames_robot_box_in_that_frames_band() -> None:
    _, frame = _pair()
    strips = StripMap(MatcherParams(), frame.left.shape, work=1_000_000)
    box = (100, 0, 140, 240)  # the robot's box, the same in every frame here
    for _ in range(strips.strips):
        strips.add(frame.left, frame.right, box)
    got = strips.add(frame.left, frame.right)
    assert got is not None
    assert np.isnan(got[:, 100:140]).all()
    want = compute_disparity(frame.left, frame.right, MatcherParams())
    np.testing.assert_array_equal(got[:, :100], want[:, :100])
    np.testing.assert_array_equal(got[:, 140:], want[:, 140:])


@pytest.mark.parametrize("matcher", ["sgm", "opencv-bm"])
def test_matchers_that_are_not_row_local_get_the_whole_map_in_one_frame(matcher: str) -> None:
    strips = StripMap(MatcherParams(matcher=matcher, num_disparities=64), (480, 640), work=10)
    assert strips.strips == 1


def test_no_frame_of_the_robot_phase_matches_more_than_one_band() -> None:
    """Each frame matches at most one band of the re-measure's map (whole rows, the full
    search range), beside the marker's window and the lane ahead."""
    with simulation(Setup(start_z_m=0.8, **CAMERA)) as sim:
        strips = sim.servo.strips
        assert strips is not None and strips.strips == 4
        remeasures = bands = 0
        for _ in range(75):  # 2.5 s: two re-measures
            before, matched = sim.servo.tracker.history[:], strips.matched
            sim.step()
            remeasures += sim.servo.tracker.history != before
            assert strips.matched - matched <= 1
            bands += strips.matched - matched
    assert sim.servo.strips is strips  # the same map all run: its count is every band
    assert remeasures >= 2 and bands >= 8


def test_moved_target_is_followed_when_its_map_takes_several_frames() -> None:
    faults = WorldFaults(events=(Event(1.5, "move", 0, z_m=1.0),))
    with simulation(Setup(start_z_m=0.6, faults=faults, **CAMERA)) as sim:
        assert sim.servo.strips is not None and sim.servo.strips.strips == 4
        sim.run(4.5, settle=None)
        assert sim.servo.target_m == pytest.approx(1.0, abs=0.015)


def test_vanished_target_stops_the_run_when_its_map_takes_several_frames() -> None:
    faults = WorldFaults(events=(Event(1.0, "vanish", 0),))
    with simulation(Setup(start_z_m=0.8, faults=faults, boxes=ALONE, **CAMERA)) as sim:
        assert sim.servo.strips is not None and sim.servo.strips.strips == 4
        sim.run(9.0)  # two re-measures to find it gone, three to find no next object
        assert sim.servo.stop_reason == "target vanished"


@pytest.mark.parametrize("z", [0.5, 1.0, 2.0, 2.8])
def test_marker_window_match_agrees_with_the_whole_map(z: float) -> None:
    _, frame = _pair((640, 480), z)
    pair = find_marker(frame.left, frame.right, radius_m=0.03, baseline_m=0.06)
    assert pair is not None
    d_window = marker_disparity(frame.left, frame.right, MatcherParams(), pair)[0]
    d_whole = marker_disparity(frame.left, frame.right, MatcherParams(), pair, whole=True)[0]
    assert np.isfinite(d_window)
    assert d_window == pytest.approx(d_whole, abs=0.02)
    assert d_window == pytest.approx(pair.disparity, abs=1.0)


@pytest.mark.parametrize("channels", [1, 3])
def test_exposure_match_is_the_per_pixel_formula(channels: int) -> None:
    rng = np.random.default_rng(2)
    shape = (120, 160) if channels == 1 else (120, 160, 3)
    left = rng.integers(20, 230, shape, dtype=np.uint8)
    right = np.clip(left * 0.7 + 25 + rng.normal(0, 3, shape), 0, 255).astype(np.uint8)
    got = match_exposure(left, right)
    lf, rf = left.reshape(-1, channels).astype(float), right.reshape(-1, channels).astype(float)
    scale = lf.std(axis=0) / rf.std(axis=0)
    want = np.clip(np.rint((rf - rf.mean(axis=0)) * scale + lf.mean(axis=0)), 0, 255)
    assert got.shape == right.shape and got.dtype == np.uint8
    assert np.abs(got.reshape(-1, channels).astype(float) - want).max() <= 1
    assert (got.reshape(-1, channels) != want).mean() < 1e-3  # a tie at .5 may round apart
    np.testing.assert_allclose(got.reshape(-1, channels).mean(axis=0), lf.mean(axis=0), atol=0.5)


@pytest.mark.parametrize("near", [None, 0.0, 12.0, 30.0, 60.0, 500.0])
def test_nearest_object_does_not_depend_on_where_the_search_starts(near) -> None:
    world = World(seed=7)
    frame = Renderer(world, seed=7).frame(with_robot=False)
    disp = compute_disparity(frame.left, frame.right, MatcherParams(num_disparities=48))
    disp = without_floor(disp, fit_floor(disp))
    want = nearest_object(disp, 320 * 240 // 100)
    assert nearest_object(disp, 320 * 240 // 100, near=near) == want
    truth = world.geometry.disparity_px(world.nearest_box().z_m)
    assert want.disparity == pytest.approx(truth, abs=0.5)
