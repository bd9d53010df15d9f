"""The simulated camera's rectification (host.sim.rectify) gives the Rectifier's images, byte
for byte, while the robot moves, the noise field changes each view, the scene's layout changes
and a sensor freezes; an image the renderer did not make is rectified whole."""

from __future__ import annotations

import numpy as np

from host.camera.calibration import Rectifier
from host.camera.source import StereoFrame
from host.sim.faults import CameraFaults, Event
from host.sim.rectify import SimRectifier
from host.sim.renderer import Renderer
from host.sim.run import _calibration
from host.sim.source import SimSource
from host.sim.world import World

LENS = (-0.06, 0.03)


class Board:
    """Both wheels at a fixed duty."""

    def advance(self, ms: float) -> None:
        pass

    def motors(self) -> tuple[int, int]:
        return (500, 420)  # forward and turning: the marker crosses the view


def test_the_rectifiers_images_as_the_robot_moves_and_the_layout_changes() -> None:
    world = World.for_size(320, 240, seed=4)
    world.robot.z_m, world.robot.x_m = 0.9, -0.05
    renderer = Renderer(world, CameraFaults(distortion=LENS, noise=2.0, exposure_ms=8.0),
                        seed=4, grey=True)
    events = (Event(0.5, "move", index=0, z_m=1.3), Event(0.9, "freeze", sensor=1,
                                                          duration_s=0.2))
    source = SimSource(world, Board(), renderer=renderer, reference_frames=2, events=events)
    calib = _calibration((320, 240), LENS, 4)
    fast, plain = SimRectifier(calib, source), Rectifier(calib)
    partial = 0
    for _ in range(40):
        raw = source.read()  # no rectify set: the raw pair
        assert raw is not None
        got, want = fast(raw), plain(raw)
        assert np.array_equal(got.left, want.left) and np.array_equal(got.right, want.right)
        partial += sum(m is not None and m[1] is not None and m[1][1] is not None
                       for m in (source.made(0), source.made(1)))
    assert partial > 40  # most views were rectified in part, not whole
    # an image the renderer did not make (changed after it) is rectified whole
    raw = source.read()
    assert raw is not None
    edited = raw.left.copy()
    edited[100:110, 100:110] = 0
    got = fast(StereoFrame(edited, raw.right, raw.t_left, raw.t_right))
    assert np.array_equal(got.left, plain(StereoFrame(edited, raw.right, 0, 0)).left)


def test_the_remapped_box_holds_every_pixel_whose_source_meets_the_change() -> None:
    calib = _calibration((320, 240), LENS, 4)
    rect = SimRectifier(calib, source=None)  # type: ignore[arg-type]  # _hit needs no source
    m1 = rect._maps[0][0].astype(np.int64)
    rng = np.random.default_rng(1)
    for _ in range(30):
        r0, c0 = int(rng.integers(0, 230)), int(rng.integers(0, 310))
        box = (r0, r0 + int(rng.integers(1, 12)), c0, c0 + int(rng.integers(1, 12)))
        x, y = m1[..., 0], m1[..., 1]  # the 2x2 source pixels start at x, y
        meets = ((x + 1 >= box[2]) & (x < box[3]) & (y + 1 >= box[0]) & (y < box[1]))
        hit = rect_hit(rect, box)
        if not meets.any():
            assert hit is None
            continue
        assert hit is not None
        inside = np.zeros_like(meets)
        inside[hit[0]:hit[1], hit[2]:hit[3]] = True
        assert not (meets & ~inside).any()


def rect_hit(rect: SimRectifier, box: tuple[int, int, int, int]
             ) -> tuple[int, int, int, int] | None:
    from host.sim.rectify import _hit
    return _hit(rect._bounds[0], rect._maps[0][0], box)


def test_a_bare_image_shared_by_the_two_sides_is_rectified_with_each_sides_maps() -> None:
    """The rectified bare images are kept by side: one array given for both sides (a renderer
    that shared it) gives each side its own maps' image, as the Rectifier does."""
    calib = _calibration((320, 240), LENS, 4)
    rect = SimRectifier(calib, source=None)  # type: ignore[arg-type]  # _bare needs no source
    bare = np.random.default_rng(2).integers(0, 256, (240, 320), dtype=np.uint8)
    plain = Rectifier(calib)(StereoFrame(bare, bare, 0.0, 0.0))
    assert np.array_equal(rect._bare(0, bare), plain.left)
    assert np.array_equal(rect._bare(1, bare), plain.right)
