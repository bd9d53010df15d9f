"""The page's pictures and numbers: the colour map keeps invalid pixels apart, the colour bar
is labelled in px and m, the band is laid over the last full map, overlays carry depth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from host.view import render
from tests.view.snapshots import GEOMETRY, snapshot


def test_invalid_pixels_are_grey_and_no_valid_pixel_is():
    disp = np.linspace(0, 64, 64 * 32, dtype=np.float32).reshape(32, 64)
    disp[5, 7] = np.nan
    img = render.colour_disparity(disp, 0.0, 64.0)
    grey = np.all(img == render.INVALID_BGR, axis=2)
    assert grey[5, 7] and grey.sum() == 1


def test_near_is_red_and_far_is_blue():
    img = render.colour_disparity(np.array([[2.0, 62.0]], np.float32), 0.0, 64.0)
    (b_far, _, r_far), (b_near, _, r_near) = img[0].astype(int)
    assert b_far > r_far and r_near > b_near


def test_colour_bar_ticks_give_depth_where_disparity_is_positive():
    ticks = render.colour_ticks(0.0, 64.0, GEOMETRY)
    assert ticks[0] == {"px": 0.0, "m": None}
    assert ticks[-1]["px"] == 64.0
    assert ticks[-1]["m"] == pytest.approx(GEOMETRY.depth_m(64.0), abs=0.01)
    assert render.disparity_range(np.array([[3.0, 41.0, np.nan]])) == (0.0, 48.0)


def test_band_is_laid_over_the_last_full_map():
    full = np.full((10, 8), 5.0, np.float32)
    band = np.full((3, 8), 9.0, np.float32)
    out = render.compose_map(full, band, 4, (10, 8))
    assert (out[4:7] == 9.0).all() and (out[:4] == 5.0).all() and (out[7:] == 5.0).all()
    assert (full == 5.0).all()  # the servo's own map is not written to
    assert np.isnan(render.compose_map(None, band, 4, (10, 8))[0]).all()


def test_overlay_has_target_and_both_marker_views_with_depth():
    o = render.overlay(snapshot(robot_px=20.0))
    assert o["target"]["x"] == 100 and o["target"]["px"] == 21.3
    assert o["target"]["m"] == pytest.approx(426 * 0.06 / 21.3, abs=1e-3)
    assert o["marker"]["left"][0] - o["marker"]["right"][0] == 20.0
    assert o["marker"]["m"] == pytest.approx(426 * 0.06 / 20.0, abs=1e-3)
    assert all(math.isfinite(v) for v in o["marker"]["left"])
