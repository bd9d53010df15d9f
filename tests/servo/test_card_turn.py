"""The card's signed turn from its two views (host/servo/card_turn.py, issue 23, branch sign):
a disc drawn wider in the left view than in the right (its +x edge nearer, at the larger
disparity: the body turned toward +x) reads a positive disparity across, the other way
negative, square about zero; the size of it within 20 % of the drawn difference. Seen failing
with the coverages swapped in across_px (b - a: every sign wrong), with the width left unscaled
(a - b alone: sizes off), and with from_square returning theta as it is (a body facing the
camera: its sign and size wrong).
"""

import math

import numpy as np
import pytest

from host.servo.card_turn import across_px, coverage, expected_px, from_square
from host.servo.marker import RING_RATIO, Blob, MarkerPair


def _view(u: float, v: float, rx: float, ry: float, shape: tuple[int, int] = (120, 160),
          ground: float = 128.0) -> np.ndarray:
    """A disc (grey 25) in its ring (235) on a flat ground, 4x4 supersampled."""
    h, w = shape
    sub = (np.arange(4) + 0.5) / 4 - 0.5
    ys = (np.arange(h)[:, None] + sub[None, :]).reshape(-1)
    xs = (np.arange(w)[:, None] + sub[None, :]).reshape(-1)
    q = ((xs[None, :] - u) / rx) ** 2 + ((ys[:, None] - v) / ry) ** 2
    img = np.where(q <= 1.0, 25.0, np.where(q <= RING_RATIO ** 2, 235.0, ground))
    return img.reshape(h, 4, w, 4).mean(axis=(1, 3))


def _pair(rx_left: float, rx_right: float, ry: float = 9.0, d: float = 20.0) -> tuple[
        np.ndarray, np.ndarray, MarkerPair]:
    u, v = 90.3, 60.6
    left, right = _view(u, v, rx_left, ry), _view(u - d, v, rx_right, ry)
    a = (rx_left + rx_right) / 2 / ry
    return left, right, MarkerPair(Blob(u, v, ry, a), Blob(u - d, v, ry, a))


@pytest.mark.parametrize("delta", [0.6, 1.0, -0.6, -1.0])
def test_the_nearer_edge_gives_the_sign_and_size(delta: float) -> None:
    # width_left - width_right = delta (px): rx differ by delta / 2 (each width is 2 rx)
    rx = 7.0
    left, right, pair = _pair(rx + delta / 4, rx - delta / 4)
    got = across_px(left, right, pair)
    assert math.copysign(1, got) == math.copysign(1, delta)
    assert abs(got - delta) <= 0.2 * abs(delta)


def test_a_square_card_reads_about_zero() -> None:
    left, right, pair = _pair(9.0, 9.0)
    assert abs(across_px(left, right, pair)) < 0.05


def test_no_contrast_or_off_the_image_is_not_read() -> None:
    flat = np.full((120, 160), 128.0)
    assert math.isnan(coverage(flat, Blob(80, 60, 9, 1.0)))
    left, _, _ = _pair(9.0, 9.0)
    assert math.isnan(coverage(left, Blob(5, 60, 9, 1.0)))


def test_expected_size() -> None:
    # 30 degrees, 1.2 m, 20 px: 20 * 0.06 * 0.5 / 1.2 = 0.5 px across the disc
    assert expected_px(math.radians(30), 1.2, 20.0, 0.03) == pytest.approx(0.5)
    assert expected_px(math.radians(-30), 1.2, 20.0, 0.03) == pytest.approx(-0.5)


@pytest.mark.parametrize("theta_deg,turn_deg", [(30, 30), (-30, -30), (150, -30), (-150, 30),
                                                (210, 30), (0, 0)])
def test_the_turn_from_square_whichever_way_the_body_faces(theta_deg: float,
                                                           turn_deg: float) -> None:
    # facing the camera (150 deg) the card's +x edge is its far one: the other sign
    assert math.degrees(from_square(math.radians(theta_deg))) == pytest.approx(turn_deg)
