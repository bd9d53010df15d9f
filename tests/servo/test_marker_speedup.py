"""The faster marker search finds the same markers as before it was made faster: on rendered
frames of a faulty camera (near, far, turned, occluded, half out of view, a decoy, a person,
lens distortion, white balance) every candidate pair, with and without a last sighting, and
every blob of find_discs at both neighbourhood sizes, is exactly the frozen oracle's
(tests/servo/marker_oracle.py, host/servo/marker.py at edcebe3)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from host.servo import marker
from host.sim.faults import CameraFaults
from host.sim.renderer import Renderer
from host.sim.world import Person, Robot, World
from tests.servo import marker_oracle

CAMERA = CameraFaults(gain=(0.87, 1.13), bias=(-12.5, 9.25),
                      white=((0.9, 1.05, 1.12), (1.1, 0.95, 0.88)), exposure_ms=20.0,
                      noise=2.7, distortion=(-0.06, 0.03))
POSES = [dict(z_m=1.9), dict(z_m=0.45), dict(z_m=2.9, x_m=-0.3), dict(z_m=1.2, theta=0.7),
         dict(z_m=1.0, theta=math.pi), dict(z_m=1.1, occlusion=0.35), dict(z_m=0.7, x_m=0.45),
         dict(z_m=1.5, theta=1.3), dict(z_m=1.3, x_m=0.05, marker_hidden=True)]


def _tuples(found) -> list[tuple]:
    return [dataclasses.astuple(b) for b in found]


def _frames():
    for camera in (CameraFaults(), CAMERA):
        world = World(seed=5)
        renderer = Renderer(world, camera, seed=5)
        for i, pose in enumerate(POSES):
            world.robot = Robot(**pose)
            world.people = (Person(-0.3, 0.9),) if i % 3 == 1 else ()
            world.decoys = (Robot(x_m=0.3, z_m=1.6),) if i % 3 == 2 else ()
            blur = (0.8, 0.3) if i % 2 else (0.0, 0.0)
            yield (renderer.view(0, True, blur)[0], renderer.view(1, True, blur)[0])


FRAMES = list(_frames())


@pytest.mark.parametrize("k", range(len(FRAMES)))
def test_same_candidates_as_before(k: int) -> None:
    """(recentre=0: the centroid once, as the oracle takes it; issue 23's re-centring is
    tests/servo/test_marker_centre.py's)"""
    left, right = FRAMES[k]
    for window in (31, 121):
        for image in (left, right):
            assert _tuples(marker.find_discs(image, window=window, recentre=0)) == \
                _tuples(marker_oracle.find_discs(image, window=window))
    whole = marker.marker_candidates(left, right, radius_m=0.03, baseline_m=0.06, recentre=0)
    assert _tuples(whole) == _tuples(marker_oracle.marker_candidates(
        left, right, radius_m=0.03, baseline_m=0.06))
    near = marker_oracle.marker_candidates(left, right)
    if near:  # searched around a last sighting first, as the servo does
        pair = near[0]
        nb = marker.MarkerPair(marker.Blob(*dataclasses.astuple(pair.left)),
                               marker.Blob(*dataclasses.astuple(pair.right)))
        got = marker.marker_candidates(left, right, radius_m=0.03, baseline_m=0.06, near=nb,
                                       recentre=0)
        want = marker_oracle.marker_candidates(left, right, radius_m=0.03, baseline_m=0.06,
                                               near=pair)
        assert _tuples(got) == _tuples(want)


def test_frames_hold_markers() -> None:
    """The frames are worth comparing on: most show the marker, some do not."""
    found = [bool(marker_oracle.marker_candidates(*f)) for f in FRAMES]
    assert 0.5 * len(found) <= sum(found) < len(found)


def test_percentile_from_histogram() -> None:
    rng = np.random.default_rng(3)
    for _ in range(3000):
        shape = tuple(int(v) for v in rng.integers(1, 30, 2))
        lo, hi = sorted(int(v) for v in rng.integers(0, 256, 2))
        patch = rng.integers(lo, hi + 1, shape).astype(np.uint8)
        assert marker._p90_of(patch) == np.percentile(patch.astype(np.float64), 90)
