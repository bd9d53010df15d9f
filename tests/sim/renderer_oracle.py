"""FROZEN ORACLE for tests/sim/test_render_speedup.py: host/sim/renderer.py as it was at 6fb3425,
before it was made faster. Not used by the program. If the renderer's images change on purpose,
replace this file with the new reference (or retire the test); never edit it to make the test pass.

The original docstring: the simulated Minoru renders the world's left and right views with their
exact disparity, then as the sensors and lenses spoil them.
The static scene (wall, floor, boxes) is painted once per layout as textured layers far to
near; the robot (and any person or second robot) goes on top each view, far to near, where it
is nearer than what the scene has there (a robot behind a box is hidden by it), with an
anti-aliased marker at its exact sub-pixel position. A rig knocked since its calibration
(pitch_deg) sees the ideal view through the rotation's homography; mains flicker (flicker)
modulates each row by the light at the time a rolling shutter reads it. Lens distortion maps
each raw pixel to where the ideal (rectified) camera saw it, so a calibration on rendered
chessboards recovers it as it would a real lens.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from host.camera.source import StereoFrame
from host.sim.faults import CameraFaults
from host.sim.world import Person, Robot, World
from host.stereo.synthetic import Layer, random_texture, render_view

MARKER_DARK = 25.0
MARKER_LIGHT = 235.0
NEARER_PX = 0.25  # a drawn surface shows where the scene is not nearer than it by this much


@dataclass(frozen=True)
class Flicker:
    """Light varying by +-amplitude (fraction) at hz, read row by row: a rolling shutter reads
    row y readout_s * y / height after its first; the right sensor's capture begins gap_s after
    the left's."""

    amplitude: float
    hz: float = 100.0
    gap_s: float = 0.0
    readout_s: float = 0.030

    def gains(self, t_s: float, side: int, height: int) -> np.ndarray:
        """Each row's light factor (float32, height) for a capture that began at t_s."""
        rows = np.arange(height, dtype=np.float64)
        t = t_s + (self.gap_s if side else 0.0) + self.readout_s * rows / height
        return (1.0 + self.amplitude * np.sin(2 * math.pi * self.hz * t)).astype(np.float32)


def rotation_homography(world: World, pitch_deg: float) -> np.ndarray:
    """The homography that maps the ideal view to the view of a rig pitched by pitch_deg
    (positive: tilted down) about its baseline: the pair stays rectified, the scene moves."""
    g, a = world.geometry, math.radians(pitch_deg)
    k = np.array([[g.focal_px, 0, g.cx], [0, g.focal_px, g.cy], [0, 0, 1]], np.float64)
    rt = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    return k @ rt @ np.linalg.inv(k)


def lens_maps(world: World, k1: float) -> tuple[np.ndarray, np.ndarray] | None:
    """remap() maps that turn an ideal view into the view through a lens with radial k1."""
    if not k1:
        return None
    g, (w, h) = world.geometry, world.size
    k = np.array([[g.focal_px, 0, g.cx], [0, g.focal_px, g.cy], [0, 0, 1]], np.float64)
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float32)
    raw = np.stack([xs.ravel(), ys.ravel()], axis=1)[:, None, :]
    ideal = cv2.undistortPoints(raw, k, np.array([k1, 0, 0, 0, 0], np.float64), P=k)
    ideal = ideal.reshape(h, w, 2)
    return ideal[..., 0].copy(), ideal[..., 1].copy()


class Renderer:
    def __init__(self, world: World, camera: CameraFaults = CameraFaults(), seed: int = 0
                 ) -> None:
        self.world, self.camera = world, camera
        self.rng = np.random.default_rng(seed)
        self.seed = seed
        self._static_key: tuple | None = None
        self._static: list[tuple[np.ndarray, np.ndarray]] = []
        self._box_tex: dict[tuple[float, float, float], np.ndarray] = {}
        self._body_tex = random_texture(np.random.default_rng(seed + 1), 64, 64, 1.2, 45, 110)
        self._person_tex = random_texture(np.random.default_rng(seed + 2), 256, 256, 2.0, 50, 120)
        self.pitch_deg = 0.0  # the rig's pitch since it was calibrated (a knock)
        self._last_noise = [-1, -1]  # the noise field each sensor got last
        self._row0 = 0  # rows of the canvas above the view's first (a pitched rig sees them)
        self.flicker: Flicker | None = None
        self._lens = [lens_maps(world, k1) for k1 in camera.distortion]
        w, h = world.size
        # sensor noise: a bank of independent fields, one drawn at random per view (drawing a
        # fresh field per view costs more than the rest of the rendering)
        self._noise = (self.rng.normal(0.0, camera.noise, (8, h, w)).astype(np.float32)
                       if camera.noise else None)

    # ------------------------------------------------------------------------ static scene

    def _static_views(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Both views of the scene without robots, on a canvas of the view's size, or with
        rows above and below it for a pitched rig to see."""
        g = self.world.geometry
        pad = (int(math.ceil(g.focal_px * math.tan(math.radians(abs(self.pitch_deg))))) + 2
               if self.pitch_deg else 0)
        key = (self.world.boxes, pad)
        if key != self._static_key:
            self._static, self._static_key = self._render_static(pad), key
        return self._static

    def _render_static(self, pad: int) -> list[tuple[np.ndarray, np.ndarray]]:
        """The static views with pad extra rows above and below (0: the view itself); the
        view's rows are the same with or without them, to a thousandth of a grey level (the
        extra rows of texture come from a stream of their own, the layers paint in the same
        order)."""
        world = self.world
        g, (w, h) = world.geometry, world.size
        rng = np.random.default_rng(self.seed)
        extra = np.random.default_rng(self.seed + 3)
        fb = g.focal_px * g.baseline_m
        margin = int(fb / 0.5) + 8

        def tex(sigma: float, contrast: float, mean: float,
                t: np.ndarray | None = None) -> np.ndarray:
            t = random_texture(rng, h, w + 2 * margin, sigma, contrast, mean) if t is None else t
            if not pad:
                return t
            above, below = (random_texture(extra, pad, w + 2 * margin, sigma, contrast, mean)
                            for _ in range(2))
            return np.vstack([above, t, below])

        layers = [Layer(fb / world.wall_z_m, tex(1.2, 40, 150), margin)]
        # floor: a point at depth z is at row cy + f h / z, so d = B (y - cy) / h (y below cy)
        horizon = g.cy + g.focal_px * world.height_m / world.wall_z_m + pad
        floor_d0, floor_dy = -g.baseline_m * (g.cy + pad) / world.height_m, g.baseline_m / \
            world.height_m
        floor_tex = tex(0.9, 35, 95)
        # the floor in the view's rows is one layer, as without the extra rows (render_view
        # paints in the order of each layer's mean disparity over its visible part: a floor
        # reaching lower would be painted over boxes it was painted under), the rows below
        # another
        layers.append(Layer(floor_d0, floor_tex, margin, dy=floor_dy,
                            box=(-1e4, horizon, 1e4, h + pad if pad else 1e4)))
        if pad:
            layers.append(Layer(floor_d0, floor_tex, margin, dy=floor_dy,
                                box=(-1e4, h + pad, 1e4, 1e4)))
        first = not self._box_tex  # a box keeps its texture (host/sim/renderer.py)
        for b in sorted(world.boxes, key=lambda b: -b.z_m):
            x0, y0 = world.project(b.x0_m, b.height_m, b.z_m)
            x1, y1 = world.project(b.x1_m, 0.0, b.z_m)
            key = (b.x0_m, b.x1_m, b.height_m)
            if key not in self._box_tex:
                own = rng if first else np.random.default_rng(
                    [self.seed, 4, len(self._box_tex)])
                self._box_tex[key] = random_texture(own, h, w + 2 * margin, 1.0, 55, 140)
            layers.append(Layer(fb / b.z_m, tex(1.0, 55, 140, self._box_tex[key]), margin,
                                box=(x0, y0 + pad, x1, y1 + pad)))
        return [render_view(layers, w, h + 2 * pad, s)[:2] for s in (0.0, 1.0)]

    def _project(self, x: float, y: float, z: float) -> tuple[float, float]:
        """A world point's pixel on the canvas being drawn (world.project, below its extra
        rows)."""
        u, v = self.world.project(x, y, z)
        return u, v + self._row0

    # ------------------------------------------------------------------------------- robot

    def _draw_person(self, image: np.ndarray, disp: np.ndarray, shift: float,
                     p: Person) -> None:
        g = self.world.geometry
        if p.z_m <= 0.2:
            return
        d = g.focal_px * g.baseline_m / p.z_m
        x0, y0 = self._project(p.x_m - p.width_m / 2, p.height_m, p.z_m)
        x1, y1 = self._project(p.x_m + p.width_m / 2, 0.0, p.z_m)
        self._paint(image, disp, (x0 - shift * d, y0, x1 - shift * d, y1), d, self._person_tex)

    def _draw_robot(self, image: np.ndarray, disp: np.ndarray, shift: float,
                    blur_px: tuple[float, float], r: Robot) -> None:
        g = self.world.geometry
        if r.z_m <= 0.2:
            return
        d = g.focal_px * g.baseline_m / r.z_m
        half_w = abs(math.cos(r.theta)) * r.body_width_m / 2 + abs(math.sin(r.theta)) * 0.08
        x0, y0 = self._project(r.x_m - half_w, r.body_height_m, r.z_m)
        x1, y1 = self._project(r.x_m + half_w, 0.02, r.z_m)
        before = image.copy() if max(abs(blur_px[0]), abs(blur_px[1])) >= 0.5 else None
        self._paint(image, disp, (x0 - shift * d, y0, x1 - shift * d, y1), d, self._body_tex)
        u, v = self._project(r.x_m, r.marker_height_m, r.z_m)
        ry = g.focal_px * r.marker_radius_m / r.z_m
        rx = ry * abs(math.cos(r.theta))  # the card turns edge-on as the robot turns
        mx0, my0 = self._project(r.x_m - 0.006, r.marker_height_m, r.z_m + 0.01)
        mx1, my1 = self._project(r.x_m + 0.006, r.body_height_m, r.z_m + 0.01)
        self._paint(image, disp, (mx0 - shift * d, my0, mx1 - shift * d, my1), d, None)
        if not r.marker_hidden:
            self._marker(image, disp, u - shift * d, v, rx, ry, d, r.ring_ratio)
        if r.occlusion > 0:  # a post just in front of the card hides its left part
            dp = g.focal_px * g.baseline_m / (r.z_m - 0.05)
            ring = r.ring_ratio * max(rx, 1.0)
            left = u - ring
            box = (left - shift * dp, v - 3 * ry, left + 2 * ring * r.occlusion - shift * dp,
                   v + 3 * ry)
            self._paint(image, disp, box, dp, self._body_tex)
        if before is not None:
            self._blur(image, before, (min(x0, u - 2 * ry) - shift * d, min(y0, v - 2 * ry),
                                       max(x1, u + 2 * ry) - shift * d, y1), blur_px)

    @staticmethod
    def _blur(image: np.ndarray, before: np.ndarray, box, blur_px) -> None:
        """Motion blur over the robot's region: the image averaged along its motion (px over
        the exposure); the background it passes over takes part, as on a sensor."""
        h, w = image.shape
        n = int(math.ceil(max(abs(blur_px[0]), abs(blur_px[1])))) + 1
        pad = n + 2
        c0, c1 = max(0, int(box[0]) - pad), min(w, int(box[2]) + pad + 1)
        r0, r1 = max(0, int(box[1]) - pad), min(h, int(box[3]) + pad + 1)
        if c0 >= c1 or r0 >= r1:
            return
        k = np.zeros((2 * n + 1, 2 * n + 1), np.float32)
        for i in range(2 * n + 1):
            s = i / (2 * n) - 0.5
            k[int(round(n + s * blur_px[1])), int(round(n + s * blur_px[0]))] += 1.0
        k /= k.sum()
        region = image[r0:r1, c0:c1]
        region[:] = cv2.filter2D(region, -1, k, borderType=cv2.BORDER_REPLICATE)

    @staticmethod
    def _paint(image, disp, box, d, texture: np.ndarray | None) -> None:
        """A surface at disparity d over box (texture, or a uniform grey 60), where the scene
        is not nearer."""
        h, w = image.shape
        x0, y0, x1, y1 = box
        c0, c1 = max(0, int(math.ceil(x0))), min(w, int(math.ceil(x1)))
        r0, r1 = max(0, int(math.ceil(y0))), min(h, int(math.ceil(y1)))
        if c0 >= c1 or r0 >= r1:
            return
        shown = ~(disp[r0:r1, c0:c1] > d + NEARER_PX)
        if texture is not None:
            ys, xs = np.mgrid[r0:r1, c0:c1]
            surface = texture[(ys - r0) % texture.shape[0], (xs - c0) % texture.shape[1]]
            image[r0:r1, c0:c1][shown] = surface[shown]
        else:
            image[r0:r1, c0:c1][shown] = 60.0
        disp[r0:r1, c0:c1][shown] = d

    @staticmethod
    def _marker(image, disp, u, v, rx, ry, d, ring) -> None:
        """Dark disc in a light ring, anti-aliased by 4x4 supersampling of each pixel."""
        if rx < 0.5:
            return
        h, w = image.shape
        c0, c1 = max(0, int(u - rx * ring) - 1), min(w, int(u + rx * ring) + 2)
        r0, r1 = max(0, int(v - ry * ring) - 1), min(h, int(v + ry * ring) + 2)
        if c0 >= c1 or r0 >= r1:
            return
        sub = (np.arange(4) + 0.5) / 4 - 0.5
        ys = np.arange(r0, r1)[:, None, None, None] + sub[None, None, :, None]
        xs = np.arange(c0, c1)[None, :, None, None] + sub[None, None, None, :]
        q = ((xs - u) / rx) ** 2 + ((ys - v) / ry) ** 2
        ring_cov = (q <= ring * ring).mean(axis=(2, 3))
        disc_cov = (q <= 1.0).mean(axis=(2, 3))
        patch = image[r0:r1, c0:c1]
        shown = ~(disp[r0:r1, c0:c1] > d + NEARER_PX)
        light = ring_cov - disc_cov
        drawn = patch * (1 - ring_cov) + MARKER_LIGHT * light + MARKER_DARK * disc_cov
        patch[shown] = drawn[shown]
        disp[r0:r1, c0:c1][(ring_cov > 0.5) & shown] = d

    # ------------------------------------------------------------------------------ views

    def view(self, side: int, with_robot: bool = True,
             blur_px: tuple[float, float] = (0.0, 0.0), t_s: float | None = None
             ) -> tuple[np.ndarray, np.ndarray]:
        """One sensor's image now (side 0 left, 1 right) as it leaves the camera (uint8, grey
        or BGR), and the exact disparity of the ideal left view (side 0; NaN where none).
        t_s: when the capture began (the flicker's phase; default the world's time). People
        and other robots are part of the scene: drawn with or without the robot."""
        static = self._static_views()[side]
        img, disp = (a.copy() for a in static)
        world = self.world
        self._row0 = (img.shape[0] - world.size[1]) // 2
        things: list[tuple[float, object]] = [(p.z_m, p) for p in world.people]
        things += [(r.z_m, r) for r in world.decoys]
        if with_robot:
            things.append((world.robot.z_m, world.robot))
        for _, thing in sorted(things, key=lambda zt: -zt[0]):  # far to near
            if isinstance(thing, Person):
                self._draw_person(img, disp, float(side), thing)
            else:
                blur = blur_px if thing is world.robot else (0.0, 0.0)
                self._draw_robot(img, disp, float(side), blur, thing)
        if self.pitch_deg:  # the canvas's rows seen through the pitched rig
            hom = rotation_homography(world, self.pitch_deg) @ np.array(
                [[1, 0, 0], [0, 1, -self._row0], [0, 0, 1]], np.float64)
            img = cv2.warpPerspective(img, hom, world.size, flags=cv2.INTER_LINEAR,
                                      borderMode=cv2.BORDER_REPLICATE)
            disp = cv2.warpPerspective(disp, hom, world.size, flags=cv2.INTER_NEAREST,
                                       borderMode=cv2.BORDER_CONSTANT, borderValue=math.nan)
        if self.flicker is not None:
            t = world.t if t_s is None else t_s
            img = img * self.flicker.gains(t, side, img.shape[0])[:, None]
        cam = self.camera
        img = img * cam.gain[side] + cam.bias[side]
        if self._noise is not None:  # never the last field again: a live sensor never
            # repeats its image exactly (a repeat is what a frozen one does)
            k = int(self.rng.integers(len(self._noise)))
            if k == self._last_noise[side]:
                k = (k + 1) % len(self._noise)
            self._last_noise[side] = k
            img += self._noise[k]
        if cam.white:
            img = img[..., None] * np.asarray(cam.white[side], np.float32)
        lens = self._lens[side]
        if lens is not None:
            img = cv2.remap(img.astype(np.float32), lens[0], lens[1], cv2.INTER_LINEAR,
                            borderMode=cv2.BORDER_REPLICATE)
        return np.clip(np.rint(img), 0, 255).astype(np.uint8), disp

    def image_velocity(self) -> tuple[float, float]:
        """The marker's motion in the left image, px/s, from the robot's velocity."""
        r, g, world = self.world.robot, self.world.geometry, self.world
        v = (r.v_left + r.v_right) / 2
        xd, zd = v * math.sin(r.theta) + world.motor_faults.push_mps, v * math.cos(r.theta)
        z = r.z_m
        return (g.focal_px * (xd * z - r.x_m * zd) / z ** 2,
                -g.focal_px * (world.height_m - r.marker_height_m) * zd / z ** 2)

    def frame(self, with_robot: bool = True) -> StereoFrame:
        """Both views now, captured together (time: the world's)."""
        left, _ = self.view(0, with_robot)
        right, _ = self.view(1, with_robot)
        return StereoFrame(left, right, self.world.t, self.world.t)
