"""The simulated world of host servo --sim: the Minoru's geometry, a textured back wall and
floor, boxes at known depths, and the robot, a differential drive with a two-sided marker card.

World frame: the camera at the origin looking along +z (depth), x to the right, y up, its
optical centre height_m above the floor. Heading theta of the robot: 0 = facing away from the
camera (+z), positive turns to its right (+x). Stereo pairs are rendered with exact
disparity: the static scene (wall, floor, boxes) once as textured layers far to near, the
robot on top each frame with an anti-aliased marker at its exact sub-pixel position.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from host.camera.calibration import Geometry
from host.camera.source import StereoFrame
from host.stereo.synthetic import Layer, random_texture, render_view

MARKER_DARK = 25.0
MARKER_LIGHT = 235.0


@dataclass(frozen=True)
class Box:
    """A box whose front face is at depth z_m, spanning x0..x1 and up to height_m."""

    z_m: float
    x0_m: float
    x1_m: float
    height_m: float


@dataclass(frozen=True)
class Motors:
    """Motor model: no motion below the dead zone, then linear to v_max, first-order lag."""

    v_max_mps: float = 0.35
    dead_zone: int = 120  # permille
    tau_s: float = 0.08
    wheelbase_m: float = 0.14

    def turn_seconds(self, duty: int) -> float:
        """How long spinning in place at +duty/-duty takes to turn round (pi): the lag lost
        at the start comes back as the wheels run down after the stop."""
        return math.pi * self.wheelbase_m / (2 * self.speed(duty))

    def speed(self, duty: int) -> float:
        if abs(duty) <= self.dead_zone:
            return 0.0
        return math.copysign(self.v_max_mps * (abs(duty) - self.dead_zone)
                             / (1000 - self.dead_zone), duty)


@dataclass
class Robot:
    x_m: float = 0.0
    z_m: float = 1.5
    theta: float = 0.0
    v_left: float = 0.0  # wheel speeds, m/s
    v_right: float = 0.0
    marker_height_m: float = 0.20
    marker_radius_m: float = 0.03  # the dark disc; the light ring reaches ring_ratio times it
    ring_ratio: float = 1.7
    body_width_m: float = 0.16
    body_height_m: float = 0.12
    marker_hidden: bool = False  # something between the camera and the card (tests)


@dataclass
class World:
    geometry: Geometry = field(default_factory=lambda: Geometry(426.0, 0.060, 160.0, 120.0))
    size: tuple[int, int] = (320, 240)
    height_m: float = 0.25  # camera above the floor
    wall_z_m: float = 3.2
    boxes: tuple[Box, ...] = (Box(1.2, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30),
                              Box(2.4, 0.60, 0.95, 0.55))
    robot: Robot = field(default_factory=Robot)
    motors: Motors = field(default_factory=Motors)
    noise: float = 2.0
    seed: int = 0

    def __post_init__(self) -> None:
        self.rng = np.random.default_rng(self.seed)
        self._static = self._render_static()
        self._body_tex = random_texture(np.random.default_rng(self.seed + 1), 64, 64, 1.2, 45,
                                        110)

    # ------------------------------------------------------------------------- geometry

    @classmethod
    def for_size(cls, width: int, height: int, **kw) -> World:
        s = width / 320.0
        return cls(Geometry(426.0 * s, 0.060, width / 2, height / 2), (width, height), **kw)

    def nearest_box(self) -> Box:
        return min(self.boxes, key=lambda b: b.z_m)

    def project(self, x: float, y: float, z: float) -> tuple[float, float]:
        """Left-image pixel of a world point (y up, relative to the floor)."""
        g = self.geometry
        return g.cx + g.focal_px * x / z, g.cy + g.focal_px * (self.height_m - y) / z

    # ------------------------------------------------------------------------- kinematics

    def step(self, dt: float, duty_left: int, duty_right: int) -> None:
        """Move the robot for dt seconds under the given motor duties (permille)."""
        r, m = self.robot, self.motors
        a = 1.0 - math.exp(-dt / m.tau_s)
        r.v_left += (m.speed(duty_left) - r.v_left) * a
        r.v_right += (m.speed(duty_right) - r.v_right) * a
        v = (r.v_left + r.v_right) / 2
        r.theta += (r.v_left - r.v_right) / m.wheelbase_m * dt
        r.x_m += v * math.sin(r.theta) * dt
        r.z_m += v * math.cos(r.theta) * dt

    # -------------------------------------------------------------------------- rendering

    def _render_static(self) -> list[tuple[np.ndarray, np.ndarray]]:
        g, (w, h) = self.geometry, self.size
        rng = np.random.default_rng(self.seed)
        fb = g.focal_px * g.baseline_m
        margin = int(fb / 0.5) + 8

        def tex(sigma: float, contrast: float, mean: float) -> np.ndarray:
            return random_texture(rng, h, w + 2 * margin, sigma, contrast, mean)

        layers = [Layer(fb / self.wall_z_m, tex(1.2, 40, 150), margin)]
        # floor: a point at depth z is at row cy + f h / z, so d = B (y - cy) / h (y below cy)
        horizon = g.cy + g.focal_px * self.height_m / self.wall_z_m
        layers.append(Layer(-g.baseline_m * g.cy / self.height_m, tex(0.9, 35, 95), margin,
                            dy=g.baseline_m / self.height_m, box=(-1e4, horizon, 1e4, 1e4)))
        for b in sorted(self.boxes, key=lambda b: -b.z_m):
            x0, y0 = self.project(b.x0_m, b.height_m, b.z_m)
            x1, y1 = self.project(b.x1_m, 0.0, b.z_m)
            layers.append(Layer(fb / b.z_m, tex(1.0, 55, 140), margin, box=(x0, y0, x1, y1)))
        return [render_view(layers, w, h, s)[:2] for s in (0.0, 1.0)]

    def marker_truth(self) -> tuple[float, float, float]:
        """(left column, row, disparity) of the marker centre, exactly."""
        r = self.robot
        u, v = self.project(r.x_m, r.marker_height_m, r.z_m)
        return u, v, self.geometry.focal_px * self.geometry.baseline_m / r.z_m

    def _draw_robot(self, image: np.ndarray, disp: np.ndarray, shift: float) -> None:
        r, g = self.robot, self.geometry
        if r.z_m <= 0.2:
            return
        d = g.focal_px * g.baseline_m / r.z_m
        half_w = abs(math.cos(r.theta)) * r.body_width_m / 2 + abs(math.sin(r.theta)) * 0.08
        x0, y0 = self.project(r.x_m - half_w, r.body_height_m, r.z_m)
        x1, y1 = self.project(r.x_m + half_w, 0.02, r.z_m)
        self._paint(image, disp, (x0 - shift * d, y0, x1 - shift * d, y1), d, body=True)
        u, v, _ = self.marker_truth()
        ry = g.focal_px * r.marker_radius_m / r.z_m
        rx = ry * abs(math.cos(r.theta))  # the card turns edge-on as the robot turns
        # mast from the body to the card
        mx0, my0 = self.project(r.x_m - 0.006, r.marker_height_m, r.z_m + 0.01)
        mx1, my1 = self.project(r.x_m + 0.006, r.body_height_m, r.z_m + 0.01)
        self._paint(image, disp, (mx0 - shift * d, my0, mx1 - shift * d, my1), d, body=False)
        if not r.marker_hidden:
            self._marker(image, disp, u - shift * d, v, rx, ry, d, r.ring_ratio)

    def _paint(self, image, disp, box, d, body: bool) -> None:
        h, w = image.shape
        x0, y0, x1, y1 = box
        c0, c1 = max(0, int(math.ceil(x0))), min(w, int(math.ceil(x1)))
        r0, r1 = max(0, int(math.ceil(y0))), min(h, int(math.ceil(y1)))
        if c0 >= c1 or r0 >= r1:
            return
        if body:
            t = self._body_tex
            ys, xs = np.mgrid[r0:r1, c0:c1]
            image[r0:r1, c0:c1] = t[(ys - r0) % t.shape[0], (xs - c0) % t.shape[1]]
        else:
            image[r0:r1, c0:c1] = 60.0
        disp[r0:r1, c0:c1] = d

    def _marker(self, image, disp, u, v, rx, ry, d, ring) -> None:
        """Dark disc in a light ring, anti-aliased by 4x4 supersampling of each pixel."""
        if rx < 0.5:
            return
        h, w = image.shape
        rr = ring
        c0, c1 = max(0, int(u - rx * rr) - 1), min(w, int(u + rx * rr) + 2)
        r0, r1 = max(0, int(v - ry * rr) - 1), min(h, int(v + ry * rr) + 2)
        if c0 >= c1 or r0 >= r1:
            return
        sub = (np.arange(4) + 0.5) / 4 - 0.5
        ys = np.arange(r0, r1)[:, None, None, None] + sub[None, None, :, None]
        xs = np.arange(c0, c1)[None, :, None, None] + sub[None, None, None, :]
        q = ((xs - u) / rx) ** 2 + ((ys - v) / ry) ** 2
        ring_cov = (q <= rr * rr).mean(axis=(2, 3))
        disc_cov = (q <= 1.0).mean(axis=(2, 3))
        patch = image[r0:r1, c0:c1]
        light = ring_cov - disc_cov
        patch[:] = patch * (1 - ring_cov) + MARKER_LIGHT * light + MARKER_DARK * disc_cov
        disp[r0:r1, c0:c1][ring_cov > 0.5] = d

    def render(self, t: float = 0.0, with_robot: bool = True) -> tuple[StereoFrame, np.ndarray]:
        """A noisy rectified pair at time t and the exact disparity of its left view."""
        views, disp_left = [], None
        for shift, (img, disp) in zip((0.0, 1.0), self._static):
            img, disp = img.copy(), disp.copy()
            if with_robot:
                self._draw_robot(img, disp, shift)
            if self.noise:
                img += self.rng.normal(0.0, self.noise, img.shape).astype(np.float32)
            views.append(np.clip(np.rint(img), 0, 255).astype(np.uint8))
            if shift == 0.0:
                disp_left = disp
        return StereoFrame(views[0], views[1], t, t), disp_left
