"""The picture's vertical shift since the reference (host/servo/rig.py) leaves the reference as
it was, so the checks that use it after (the target's picture, rereference.target_shift_rows;
the deflicker) see the scene and not the phase correlation's window."""

from __future__ import annotations

import cv2
import numpy as np

from host.servo.rereference import target_shift_rows
from host.servo.rig import reference_image, vertical_shift_px


def _scene(seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return cv2.GaussianBlur(rng.uniform(0, 255, (240, 320)).astype(np.float32), (5, 5),
                            1.5).astype(np.uint8)


def test_the_shift_is_measured_and_the_reference_is_left_as_it_was() -> None:
    scene = _scene()
    reference = reference_image(scene)
    kept = reference.copy()
    moved = np.roll(scene, -13, axis=0)
    for _ in range(6):  # a wait for a moved camera measures it every re-measure
        assert abs(vertical_shift_px(reference, moved) + 13) < 0.3
    np.testing.assert_array_equal(reference, kept)


def test_the_targets_picture_near_the_edge_is_found_after_repeated_measures() -> None:
    """A target region 26 px from the left edge (seed 3's trial 41): with the reference
    windowed in place by each measure, its picture there faded to the window's edge and was
    matched 14 rows down for a picture moved 15 up."""
    rng = np.random.default_rng(2)
    scene = _scene(2)
    reference = reference_image(scene)
    moved = np.clip(np.roll(scene, -15, axis=0).astype(np.float32)
                    + rng.normal(0, 3, scene.shape), 0, 255).astype(np.uint8)
    for _ in range(6):
        vertical_shift_px(reference, moved)
    assert target_shift_rows(reference, moved, (26, 147, 37, 60), 19) == -15
