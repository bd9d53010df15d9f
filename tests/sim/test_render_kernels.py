"""The renderer's compiled drawing (renderer._draw_surface for Renderer._paint,
renderer._draw_marker for Renderer._marker) against the numpy it replaced, on disparity maps
whose values sit on and beside the "scene nearer" limit, for a disparity given as a Python float
(numpy compares the float32 map with it in float32) and as a numpy float64 (in float64)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from host.sim import renderer
from host.sim.renderer import MARKER_DARK, MARKER_LIGHT, NEARER_PX, Renderer
from host.sim.world import World


def _numpy_paint(image: np.ndarray, disp: np.ndarray, box: tuple[int, int, int, int],
                 d: float, texture: np.ndarray | None) -> None:
    r0, r1, c0, c1 = box
    shown = ~(disp[r0:r1, c0:c1] > d + NEARER_PX)
    if texture is not None:
        th, tw = texture.shape
        surface = texture[np.arange(r1 - r0) % th][:, np.arange(c1 - c0) % tw]
        np.copyto(image[r0:r1, c0:c1], surface, where=shown)
    else:
        image[r0:r1, c0:c1][shown] = 60.0
    disp[r0:r1, c0:c1][shown] = d


def _numpy_marker(image: np.ndarray, disp: np.ndarray, u: float, v: float, rx: float,
                  ry: float, d: float, ring: float) -> None:
    h, w = image.shape
    c0, c1 = max(0, int(u - rx * ring) - 1), min(w, int(u + rx * ring) + 2)
    r0, r1 = max(0, int(v - ry * ring) - 1), min(h, int(v + ry * ring) + 2)
    sub = (np.arange(4) + 0.5) / 4 - 0.5
    qy = ((np.arange(r0, r1)[:, None] + sub - v) / ry) ** 2
    qx = ((np.arange(c0, c1)[:, None] + sub - u) / rx) ** 2
    ring_cov, disc_cov = renderer._coverage(qx, qy, (ring * ring, 1.0))
    patch = image[r0:r1, c0:c1]
    shown = ~(disp[r0:r1, c0:c1] > d + NEARER_PX)
    drawn = (patch * (1 - ring_cov) + MARKER_LIGHT * (ring_cov - disc_cov)
             + MARKER_DARK * disc_cov)
    patch[shown] = drawn[shown]
    disp[r0:r1, c0:c1][(ring_cov > 0.5) & shown] = d


def _scene(rng: np.random.Generator, d: float) -> tuple[np.ndarray, np.ndarray]:
    """A float32 image and disparity map whose values are NaN, far, or on the limit d +
    NEARER_PX as float32 and float64 round it and one float32 step either side."""
    image = rng.uniform(0, 255, (60, 80)).astype(np.float32)
    limit = d + NEARER_PX
    near = [np.float32(limit), np.float32(np.float64(limit))]
    near += [np.nextafter(x, np.float32(math.inf)) for x in near]
    near += [np.nextafter(x, np.float32(-math.inf)) for x in near[:2]]
    choices = np.array([np.nan, 0.5, d + 3.0, *near], np.float32)
    disp = choices[rng.integers(0, choices.size, image.shape)]
    return image, disp


@pytest.mark.parametrize("as_numpy", [False, True])
def test_paint_and_marker_are_the_numpy_drawing(as_numpy: bool) -> None:
    rng = np.random.default_rng(5)
    r = Renderer(World.for_size(80, 60, seed=0), seed=1)
    texture = rng.uniform(40, 200, (7, 9)).astype(np.float32)
    for _ in range(40):
        d = float(rng.uniform(2.0, 30.0)) + 1e-9 * float(rng.uniform())
        d = np.float64(d) if as_numpy else d
        image, disp = _scene(rng, d)
        want_img, want_disp = image.copy(), disp.copy()
        x0, y0 = float(rng.uniform(-5, 70)), float(rng.uniform(-5, 50))
        box = (x0, y0, x0 + float(rng.uniform(1, 30)), y0 + float(rng.uniform(1, 30)))
        tex = texture if rng.random() < 0.7 else None
        r._paint(image, disp, box, d, tex)
        c0, c1 = max(0, math.ceil(box[0])), min(80, math.ceil(box[2]))
        r0, r1 = max(0, math.ceil(box[1])), min(60, math.ceil(box[3]))
        if c0 < c1 and r0 < r1:
            _numpy_paint(want_img, want_disp, (r0, r1, c0, c1), d, tex)
        np.testing.assert_array_equal(image, want_img)
        np.testing.assert_array_equal(disp, want_disp)
        u, v = float(rng.uniform(5, 75)), float(rng.uniform(5, 55))
        ry = float(rng.uniform(1.0, 12.0))
        rx = ry * float(rng.uniform(0.6, 1.0))
        r._marker(image, disp, u, v, rx, ry, d, 1.6)
        _numpy_marker(want_img, want_disp, u, v, rx, ry, d, 1.6)
        np.testing.assert_array_equal(image, want_img)
        np.testing.assert_array_equal(disp, want_disp)
