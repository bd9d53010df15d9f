"""nearest_object no longer labels a threshold level whose pixels number fewer than min_area
(no region there can reach it; issue 25: on dev 105 half its labellings were such levels).
Its Target must be the one it gave before (the 4db45a1 function, copied below) on rendered
maps, made-up maps with noise and a region of exactly min_area pixels, from any start."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from host.errors import HostError
from host.servo.perception import Target, fit_floor, match_exposure, nearest_object, without_floor
from host.sim.faults import CameraFaults
from host.sim.renderer import Renderer
from host.sim.world import Box, World
from host.stereo.matcher import compute_disparity
from host.stereo.params import MatcherParams


def labelled_every_level(disp: np.ndarray, min_area: int, step: float = 0.5,
                         near: float | None = None) -> Target:
    """nearest_object as it was at 4db45a1 (the reference)."""
    clean = cv2.medianBlur(np.nan_to_num(disp, nan=0.0).astype(np.float32), 5)
    clean[~np.isfinite(disp)] = 0.0
    top = float(np.percentile(clean[clean > 0], 99.9)) if (clean > 0).any() else 0.0
    levels = []
    level = top
    while level > step:
        levels.append(level)
        level -= step
    seen: dict[int, tuple[int, np.ndarray, np.ndarray]] = {}

    def reaches(k: int) -> bool:
        if k not in seen:
            mask = (clean >= levels[k]).astype(np.uint8)
            seen[k] = cv2.connectedComponentsWithStats(mask, connectivity=4)[:3]
        n, _, stats = seen[k]
        return n > 1 and int(stats[1:, cv2.CC_STAT_AREA].max()) >= min_area

    missing = f"no object of at least {min_area} px found in the reference scene"
    if not levels:
        raise HostError(missing)
    last = len(levels) - 1
    start = 0 if near is None else min(last, max(0, round((top - near) / step)))
    jump = 1
    if reaches(start):
        below, k = start - 1, start
        while below >= 0 and reaches(below):
            k, below, jump = below, max(-1, below - 2 * jump), 2 * jump
    else:
        below, k = start, min(last, start + 1)
        while not reaches(k):
            if k == last:
                raise HostError(missing)
            below, jump = k, 2 * jump
            k = min(last, k + jump)
    while k - below > 1:
        mid = (below + k) // 2
        below, k = (below, mid) if reaches(mid) else (mid, k)
    n, labels, stats = seen[k]
    best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    region = (labels == best) & (clean < levels[k] + 2.0)
    q1, q2, q3 = np.percentile(clean[region], [25, 50, 75])
    x, y, w, h = (int(v) for v in stats[best, :4])
    return Target(float(q2), int(stats[best, cv2.CC_STAT_AREA]), (x, y, w, h), float(q3 - q1))


def agree(disp: np.ndarray, min_area: int, near: float | None) -> None:
    try:
        want = labelled_every_level(disp, min_area, near=near)
    except (HostError, IndexError) as e:  # IndexError: a region with no pixel within 2 px
        with pytest.raises(type(e), match=str(e)):  # of its level (left as it was)
            nearest_object(disp, min_area, near=near)
        return
    got = nearest_object(disp, min_area, near=near)
    assert got == want, (min_area, near)


def rendered_maps() -> list[np.ndarray]:
    out = []
    for seed, robot in ((5, (0.8, 0.0)), (6, (1.6, 0.3))):
        world = World(seed=seed, boxes=(Box(1.2, -0.50, -0.18, 0.38),
                                        Box(1.8, 0.22, 0.55, 0.30)))
        world.robot.z_m, world.robot.x_m = robot
        f = Renderer(world, CameraFaults(noise=2.0), seed=seed).frame()
        disp = compute_disparity(f.left, match_exposure(f.left, f.right),
                                 MatcherParams.for_matcher(MatcherParams.matcher).validate())
        out += [disp, without_floor(disp, fit_floor(disp))]
    return out


def test_the_target_is_the_one_labelling_every_level_gave_on_rendered_maps() -> None:
    for disp in rendered_maps():
        for min_area in (50, 300, 768, 3000, 40000):
            for near in (None, 5.0, 12.0, 19.0, 40.0):
                agree(disp, min_area, near)


def test_a_region_of_exactly_min_area_pixels_is_found_at_its_level() -> None:
    """Speckle over a wall, and one block whose pixels at its level number exactly min_area:
    that level must be labelled, not passed over."""
    rng = np.random.default_rng(2)
    for _ in range(20):
        disp = np.full((240, 320), 6.0, np.float32) + rng.normal(0, 0.1, (240, 320)).astype(
            np.float32)
        h, w = (int(v) for v in rng.integers(12, 40, 2))
        y, x = int(rng.integers(0, 240 - h)), int(rng.integers(0, 320 - w))
        disp[y:y + h, x:x + w] = rng.uniform(12, 30)
        disp[rng.random(disp.shape) < 0.02] = np.nan
        clean = cv2.medianBlur(np.nan_to_num(disp, nan=0.0), 5)
        clean[~np.isfinite(disp)] = 0.0
        at_level = int(np.count_nonzero(clean >= disp[y + h // 2, x + w // 2] - 0.01))
        for min_area in (at_level - 1, at_level, at_level + 1, h * w // 2):
            for near in (None, 6.0, float(disp[y + h // 2, x + w // 2])):
                agree(disp, min_area, near)
