"""The simulated Minoru: renders the world's left and right views with their exact disparity,
then as the sensors and lenses spoil them (exposure, white balance, blur, noise, distortion).

The static scene (wall, floor, boxes) is painted once per layout as textured layers far to
near; the robot (and any person or second robot) goes on top each view, far to near, where it
is nearer than what the scene has there (a robot behind a box is hidden by it), with an
anti-aliased marker at its exact sub-pixel position. A rig knocked since its calibration
(pitch_deg) sees the ideal view through the rotation's homography; mains flicker (flicker)
modulates each row by the light at the time a rolling shutter reads it. Lens distortion maps
each raw pixel to where the ideal (rectified) camera saw it, so a calibration on rendered
chessboards recovers it as it would a real lens. A colour camera renders grey images for a
servo that matches in grey (grey=True: the trials), the white balance's gains weighted as the
host's grey conversion weighs them.

Speed: a sensor's grey level is a function of the ideal view's at that pixel alone, so with no
pitch, flicker or lens the bare scene's sensor image is made once per layout and noise field,
and each view sends only the rectangles drawn over (robot, marker, blur, people) through the
sensor again; with a lens (no pitch or flicker) the same, and only the pixels whose source
pixels meet that rectangle go through remap() again. The images are bit-identical to the full
computation (tests/sim/test_render_speedup.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from numba import njit

from host.camera.source import StereoFrame
from host.sim.faults import CameraFaults
from host.sim.hit_box import hit_of
from host.sim.world import Person, Robot, World
from host.stereo.synthetic import Layer, random_texture, render_view

MARKER_DARK = 25.0
MARKER_LIGHT = 235.0
GREY_WEIGHTS = np.array([0.114, 0.587, 0.299])  # B, G, R: cv2.COLOR_BGR2GRAY's
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
    hom: np.ndarray = k @ rt @ np.linalg.inv(k)
    return hom


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


def _coverage(qx: np.ndarray, qy: np.ndarray, ts: tuple[float, ...]) -> list[np.ndarray]:
    """For each t of ts, the fraction of each pixel's 4x4 samples with qx + qy <= t (float64,
    rows x columns), the samples' terms given per column (qx, columns x 4) and per row (qy,
    rows x 4). A sum rounded to float64 never decreases as a term grows, so a pixel whose
    largest terms pass is covered and one whose least fail is not; only the pixels between
    count their samples."""
    covs = _coverage_of(np.ascontiguousarray(qx, np.float64),
                        np.ascontiguousarray(qy, np.float64), np.asarray(ts, np.float64))
    return list(covs)


@njit(cache=True)
def _coverage_of(qx: np.ndarray, qy: np.ndarray, ts: np.ndarray) -> np.ndarray:
    """_coverage's fractions (ts, rows, columns) in one pass: the same sums and comparisons."""
    rows, cols = qy.shape[0], qx.shape[0]
    out = np.empty((ts.size, rows, cols))
    for i in range(rows):
        y_lo, y_hi = qy[i].min(), qy[i].max()
        for j in range(cols):
            hi = y_hi + qx[j].max()
            lo = y_lo + qx[j].min()
            for k in range(ts.size):
                t = ts[k]
                if hi <= t:
                    out[k, i, j] = 1.0
                elif lo > t:
                    out[k, i, j] = 0.0
                else:
                    n = 0
                    for a in range(qy.shape[1]):
                        for b in range(qx.shape[1]):
                            n += qx[j, b] + qy[i, a] <= t
                    out[k, i, j] = n / 16
    return out


@njit(cache=True)
def _draw_marker(image: np.ndarray, disp: np.ndarray, r0: int, r1: int, c0: int, c1: int,
                 u: float, v: float, rx: float, ry: float, t_ring: float, t_disc: float,
                 d: float, weak: bool) -> None:
    """Renderer._marker's drawing in one pass over rows r0:r1, columns c0:c1 of the whole
    image and disparity (whole arrays: one compiled signature, where a slice's layout varies
    with its shape): each pixel's 4x4 samples' terms (((row + sub - v) / ry)^2 as numpy made
    them, the same for columns), its ring and disc coverage as _coverage_of makes them, and
    where the scene is not nearer (_nearer) its grey level made as numpy makes it (float64:
    level * (1 - ring) + light * (ring - disc) + dark * disc, then float32) and the disparity
    d where the ring covers over half the pixel."""
    rows, cols = r1 - r0, c1 - c0
    nearer = _nearer(d, weak)
    qy, qx = np.empty((rows, 4)), np.empty((cols, 4))
    for a in range(4):
        sub = (a + 0.5) / 4 - 0.5
        for i in range(rows):
            y = (np.float64(r0 + i) + sub - v) / ry
            qy[i, a] = y * y
        for j in range(cols):
            x = (np.float64(c0 + j) + sub - u) / rx
            qx[j, a] = x * x
    ts = (t_ring, t_disc)
    cov = np.empty(2)
    for i in range(rows):
        y_lo, y_hi = qy[i].min(), qy[i].max()
        for j in range(cols):
            hi = y_hi + qx[j].max()
            lo = y_lo + qx[j].min()
            for k in range(2):
                t = ts[k]
                if hi <= t:
                    cov[k] = 1.0
                elif lo > t:
                    cov[k] = 0.0
                else:
                    n = 0
                    for a in range(qy.shape[1]):
                        for b in range(qx.shape[1]):
                            n += qx[j, b] + qy[i, a] <= t
                    cov[k] = n / 16
            if np.float64(disp[r0 + i, c0 + j]) > nearer:
                continue
            ring, disc = cov[0], cov[1]
            drawn = (np.float64(image[r0 + i, c0 + j]) * (1 - ring)
                     + MARKER_LIGHT * (ring - disc) + MARKER_DARK * disc)
            image[r0 + i, c0 + j] = drawn
            if ring > 0.5:
                disp[r0 + i, c0 + j] = d


@njit(cache=True)
def _draw_surface(image: np.ndarray, disp: np.ndarray, r0: int, r1: int, c0: int, c1: int,
                  texture: np.ndarray, grey: float, d: float, weak: bool) -> None:
    """Renderer._paint's drawing in one pass over rows r0:r1, columns c0:c1 of the whole image
    and disparity: where the scene is not nearer (_nearer), the texture from its corner,
    repeated where the box is larger (or the uniform grey where the texture is empty), and the
    disparity d."""
    nearer = _nearer(d, weak)
    th, tw = texture.shape
    for i in range(r1 - r0):
        ti, tj = (i % th if th else 0), 0  # the texture's row and column (no % a pixel)
        for j in range(c1 - c0):
            if not np.float64(disp[r0 + i, c0 + j]) > nearer:  # NaN: no scene there
                image[r0 + i, c0 + j] = texture[ti, tj] if th else grey
                disp[r0 + i, c0 + j] = d
            tj += 1
            if tj == tw:
                tj = 0


_NO_TEXTURE = np.zeros((0, 1), np.float32)


@njit(cache=True)
def _nearer(d: float, weak: bool) -> float:
    """d + NEARER_PX as numpy compared a float32 disparity map with it (`disp > d +
    NEARER_PX`): rounded to float32 first when d is a Python float (weak: numpy takes it to the
    array's type), not when it is a numpy float64."""
    limit = d + NEARER_PX
    return np.float64(np.float32(limit)) if weak else limit


LensBounds = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _lens_bounds(mx: np.ndarray, my: np.ndarray) -> LensBounds:
    """Per row of the view, the least and greatest source row (my) of the lens map; per
    column, the least and greatest source column (mx). A mild lens bends each row and column
    by a few pixels only, so these ranges are narrow."""
    return my.min(1), my.max(1), mx.min(0), mx.max(0)


def _lens_hit_box(bounds: LensBounds, mx: np.ndarray, my: np.ndarray,
                  limits: tuple[float, float, float, float]) -> tuple[int, int, int, int] | None:
    """The rows y0:y1 and columns x0:x1 round the pixels whose lens source (mx, my) lies
    strictly inside limits (lo_x, hi_x, lo_y, hi_y), None if none does. Such a pixel is in a
    row whose source rows reach into (lo_y, hi_y) and a column whose source columns reach
    into (lo_x, hi_x): the pixels are looked for in those rows and columns alone."""
    # the limits as float32, as numpy compares a float32 array with a Python float
    row_lo, row_hi, col_lo, col_hi = bounds
    lo_x, hi_x, lo_y, hi_y = (np.float32(v) for v in limits)
    got = hit_of(row_lo, row_hi, col_lo, col_hi, mx, my, float(lo_x), float(hi_x),
                 float(lo_y), float(hi_y))
    return None if got[0] < 0 else got


# lens maps and their bounds by (geometry, size, k1), shared: a campaign's trials meet its
# 16 cameras over and over, and each Renderer made its two maps anew (cv2.undistortPoints on
# every pixel, ~5 ms a sensor at 320x240)
_LENSES: dict[tuple[object, ...], tuple[tuple[np.ndarray, np.ndarray], LensBounds]] = {}
_KEEP_LENSES = 64


def _kept_lens(world: World, k1: float
               ) -> tuple[tuple[np.ndarray, np.ndarray], LensBounds] | None:
    """lens_maps(world, k1) and their _lens_bounds, made once a process for each geometry,
    size and k1 (shared by the Renderers: nothing writes to them; left writeable, as numba's
    kernels that read them were compiled for)."""
    if not k1:
        return None
    key = (world.geometry, tuple(world.size), float(k1))
    got = _LENSES.get(key)
    if got is None:
        maps = lens_maps(world, k1)
        assert maps is not None
        got = (maps, _lens_bounds(*maps))
        if len(_LENSES) >= _KEEP_LENSES:
            _LENSES.clear()
        _LENSES[key] = got
    return got


class Renderer:
    def __init__(self, world: World, camera: CameraFaults = CameraFaults(), seed: int = 0,
                 grey: bool = False) -> None:
        """grey: a colour camera (white balance) sends grey images: each pixel's BGR levels
        before rounding weighted as OpenCV's BGR2GRAY weighs them (0.114, 0.587, 0.299), then
        rounded once: within a grey level of the grey of its colour image where no channel
        saturates, with one plane's work instead of three."""
        self.world, self.camera, self.grey = world, camera, grey
        # each sensor's white balance: its BGR gains, or the one gain of the grey image
        self._white: list[tuple[float, ...]] = [
            (float(GREY_WEIGHTS @ np.asarray(w, np.float64)),) if grey else w
            for w in camera.white]
        self.rng = np.random.default_rng(seed)
        self.seed = seed
        self._static_key: tuple[object, ...] | None = None
        self._static: list[tuple[np.ndarray, np.ndarray]] = []
        # each box's texture (by its sides and height), kept when other boxes come or go or it
        # moves in depth: a real box keeps its face
        self._box_tex: dict[tuple[float, float, float], np.ndarray] = {}
        self._body_tex = random_texture(np.random.default_rng(seed + 1), 64, 64, 1.2, 45, 110)
        self._person_tex = random_texture(np.random.default_rng(seed + 2), 256, 256, 2.0, 50, 120)
        self.pitch_deg = 0.0  # the rig's pitch since it was calibrated (a knock)
        self._last_noise = [-1, -1]  # the noise field each sensor got last
        self._row0 = 0  # rows of the canvas above the view's first (a pitched rig sees them)
        self.flicker: Flicker | None = None
        self._touched: list[tuple[int, int, int, int]] = []  # rows, columns drawn this view
        # drawing over the static views in place (image()): each rectangle's pixels as they were
        # before it was drawn, put back after the view (None: drawing on copies, view())
        self._undo: list[tuple[int, int, int, int, np.ndarray, np.ndarray | None]] | None = None
        # the last view as the bare scene's image (never written to) and the rows, columns
        # y0, y1, x0, x1 where it differs from it (None: nowhere); None: a whole new image
        self.changed: tuple[np.ndarray, tuple[int, int, int, int] | None] | None = None
        self._bare_key: tuple[object, ...] | None = None  # the layout _bare_images are of
        self._bare_images: dict[tuple[object, ...], np.ndarray] = {}
        lenses = [_kept_lens(world, k1) for k1 in camera.distortion]
        self._lens = [None if m is None else m[0] for m in lenses]
        self._lens_bounds = [None if m is None else m[1] for m in lenses]
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
        first = not self._box_tex  # the first layout's boxes from rng, as they always were
        for b in sorted(world.boxes, key=lambda b: -b.z_m):
            x0, y0 = world.project(b.x0_m, b.height_m, b.z_m)
            x1, y1 = world.project(b.x1_m, 0.0, b.z_m)
            key = (b.x0_m, b.x1_m, b.height_m)
            if key not in self._box_tex:  # a box new to the scene: a stream of its own
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
        half_w = r.half_extent()[0]
        x0, y0 = self._project(r.x_m - half_w, r.body_height_m, r.z_m)
        x1, y1 = self._project(r.x_m + half_w, 0.02, r.z_m)
        blurred = max(abs(blur_px[0]), abs(blur_px[1])) >= 0.5
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
        if blurred:
            self._blur(image, (min(x0, u - 2 * ry) - shift * d, min(y0, v - 2 * ry),
                                       max(x1, u + 2 * ry) - shift * d, y1), blur_px)

    def _blur(self, image: np.ndarray, box: tuple[float, float, float, float],
              blur_px: tuple[float, float]) -> None:
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
        self._touch(image, None, r0, r1, c0, c1)
        region = image[r0:r1, c0:c1]
        region[:] = cv2.filter2D(region, -1, k, borderType=cv2.BORDER_REPLICATE)

    def _paint(self, image: np.ndarray, disp: np.ndarray, box: tuple[float, float, float, float],
               d: float, texture: np.ndarray | None) -> None:
        """A surface at disparity d over box (texture, or a uniform grey 60), where the scene
        is not nearer."""
        h, w = image.shape
        x0, y0, x1, y1 = box
        c0, c1 = max(0, int(math.ceil(x0))), min(w, int(math.ceil(x1)))
        r0, r1 = max(0, int(math.ceil(y0))), min(h, int(math.ceil(y1)))
        if c0 >= c1 or r0 >= r1:
            return
        self._touch(image, disp, r0, r1, c0, c1)
        # in one compiled pass, the same as:
        #   shown = ~(disp[r0:r1, c0:c1] > d + NEARER_PX)
        #   np.copyto(image[r0:r1, c0:c1], texture from its corner (tiled), where=shown), or
        #   image[r0:r1, c0:c1][shown] = 60.0 without one; disp[r0:r1, c0:c1][shown] = d
        _draw_surface(image, disp, r0, r1, c0, c1, _NO_TEXTURE if texture is None else texture,
                      60.0, d, type(d + NEARER_PX) is float)

    def _marker(self, image: np.ndarray, disp: np.ndarray, u: float, v: float, rx: float,
                ry: float, d: float, ring: float) -> None:
        """Dark disc in a light ring, anti-aliased by 4x4 supersampling of each pixel."""
        if rx < 0.5:
            return
        h, w = image.shape
        c0, c1 = max(0, int(u - rx * ring) - 1), min(w, int(u + rx * ring) + 2)
        r0, r1 = max(0, int(v - ry * ring) - 1), min(h, int(v + ry * ring) + 2)
        if c0 >= c1 or r0 >= r1:
            return
        self._touch(image, disp, r0, r1, c0, c1)
        # in one compiled pass, the same arithmetic as (tests/sim/test_render_kernels.py):
        #   sub = (np.arange(4) + 0.5) / 4 - 0.5
        #   qy = ((np.arange(r0, r1)[:, None] + sub - v) / ry) ** 2  # rows x 4 sub-rows
        #   qx = ((np.arange(c0, c1)[:, None] + sub - u) / rx) ** 2  # columns x 4 sub-columns
        #   ring_cov, disc_cov = _coverage(qx, qy, (ring * ring, 1.0))
        #   shown = ~(disp[r0:r1, c0:c1] > d + NEARER_PX)
        #   drawn = patch * (1 - ring_cov) + MARKER_LIGHT * light + MARKER_DARK * disc_cov
        #   patch[shown] = drawn[shown]; disp[r0:r1, c0:c1][(ring_cov > 0.5) & shown] = d
        _draw_marker(image, disp, r0, r1, c0, c1, u, v, rx, ry, ring * ring, 1.0, d,
                     type(d + NEARER_PX) is float)

    # ------------------------------------------------------------------------------ views

    def view(self, side: int, with_robot: bool = True,
             blur_px: tuple[float, float] = (0.0, 0.0), t_s: float | None = None
             ) -> tuple[np.ndarray, np.ndarray]:
        """One sensor's image now (side 0 left, 1 right) as it leaves the camera (uint8, grey
        or BGR), and the exact disparity of the ideal left view (side 0; NaN where none).
        t_s: when the capture began (the flicker's phase; default the world's time). People
        and other robots are part of the scene: drawn with or without the robot."""
        return self._view(side, with_robot, blur_px, t_s, in_place=False)

    def image(self, side: int, with_robot: bool = True,
              blur_px: tuple[float, float] = (0.0, 0.0), t_s: float | None = None
              ) -> np.ndarray:
        """view()'s image alone, the same to the byte. Without a pitch or flicker the robots
        and people are drawn over the static view itself and their rectangles put back after
        (only the drawn rectangle is used from then on): no copy of the whole canvas and its
        disparity each view."""
        return self._view(side, with_robot, blur_px, t_s, in_place=True)[0]

    def _touch(self, image: np.ndarray, disp: np.ndarray | None, r0: int, r1: int, c0: int,
               c1: int) -> None:
        """Rows r0:r1, columns c0:c1 are about to be drawn over (of image, and of disp unless
        None): noted, and kept as they were when drawing in place."""
        self._touched.append((r0, r1, c0, c1))
        if self._undo is not None:
            self._undo.append((r0, r1, c0, c1, image[r0:r1, c0:c1].copy(),
                               None if disp is None else disp[r0:r1, c0:c1].copy()))

    def _view(self, side: int, with_robot: bool, blur_px: tuple[float, float],
              t_s: float | None, in_place: bool) -> tuple[np.ndarray, np.ndarray]:
        static = self._static_views()[side]
        in_place = in_place and not self.pitch_deg and self.flicker is None
        img, disp = static if in_place else (static[0].copy(), static[1].copy())
        world = self.world
        self._row0 = (img.shape[0] - world.size[1]) // 2
        self._touched = []
        self._undo = [] if in_place else None
        things: list[tuple[float, Person | Robot]] = [(p.z_m, p) for p in world.people]
        things += [(r.z_m, r) for r in world.decoys]
        if with_robot:
            things.append((world.robot.z_m, world.robot))
        box: tuple[int, int, int, int] | None = None
        try:
            for _, thing in sorted(things, key=lambda zt: -zt[0]):  # far to near
                if isinstance(thing, Person):
                    self._draw_person(img, disp, float(side), thing)
                else:
                    blur = blur_px if thing is world.robot else (0.0, 0.0)
                    self._draw_robot(img, disp, float(side), blur, thing)
            if self._touched:  # one rectangle round them all: the drawings overlap
                r0, r1, c0, c1 = (f(t[i] for t in self._touched)
                                  for i, f in enumerate((min, max, min, max)))
                box = (r0, r1, c0, c1)
            # what was drawn there (a copy while the static view is drawn on: it is put back)
            drawn = None if box is None else img[r0:r1, c0:c1]
            if in_place and drawn is not None:
                drawn = drawn.copy()
        finally:
            if self._undo is not None:
                for y0, y1, x0, x1, kept_img, kept_disp in reversed(self._undo):
                    img[y0:y1, x0:x1] = kept_img
                    if kept_disp is not None:
                        disp[y0:y1, x0:x1] = kept_disp
                self._undo = None
        k = self._noise_field(side)
        self.changed = None
        if not self.pitch_deg and self.flicker is None and self._lens[side] is not None:
            return self._through_lens(drawn, box, side, k), disp
        if not self.pitch_deg and self.flicker is None and self._lens[side] is None:
            # each pixel's grey level is a function of the ideal view's there alone: the scene's
            # pixels come from the sensor's image of the bare scene with this noise field, and
            # only the pixels drawn over go through the sensor again
            out = self._bare(side, k).copy()
            self.changed = (self._bare(side, k), None)
            if box is not None and drawn is not None:
                r0, r1, c0, c1 = box
                out[r0:r1, c0:c1] = self._sensor(drawn, side, k, box)
                self.changed = (self._bare(side, k), box)
            return out, disp
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
        return self._sensor(img, side, k), disp

    def _noise_field(self, side: int) -> int | None:
        """The bank's noise field for this view: never the last field again (a live sensor
        never repeats its image exactly; a repeat is what a frozen one does)."""
        if self._noise is None:
            return None
        k = int(self.rng.integers(len(self._noise)))
        if k == self._last_noise[side]:
            k = (k + 1) % len(self._noise)
        self._last_noise[side] = k
        return k

    def _sensor(self, img: np.ndarray, side: int, k: int | None,
                region: tuple[int, int, int, int] | None = None) -> np.ndarray:
        """The ideal view's grey levels (float32; or a region of them: rows r0:r1, columns
        c0:c1) as the sensor and lens turn them into the image (uint8): gain and black level,
        noise field k, white balance, distortion. Pixel by pixel the same arithmetic for a
        region as for the whole view."""
        cam = self.camera
        img = np.multiply(img, cam.gain[side])  # a new array: img may be the caller's
        np.add(img, cam.bias[side], out=img)
        if k is not None:
            assert self._noise is not None  # k is a field of the bank
            noise = self._noise[k]
            img += noise if region is None else noise[region[0]:region[1], region[2]:region[3]]
        lens = self._lens[side]
        if lens is None and img.dtype == np.float32:
            # OpenCV's conversion to uint8 rounds half to even and saturates, as rint and clip
            # do, and scales in float32 as numpy does: the same image, without the temporaries
            np.maximum(img, 0.0, out=img)  # then |x w| is x w, and what was below 0 is 0 still
            if not cam.white:
                return cv2.convertScaleAbs(img)
            planes = [cv2.convertScaleAbs(img, alpha=float(np.float32(c)))
                      for c in self._white[side]]
            return planes[0] if self.grey else cv2.merge(planes)
        if cam.white:
            img = self._balanced(img, side)
        if lens is not None:
            img = cv2.remap(img.astype(np.float32, copy=False), lens[0], lens[1],
                            cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
            np.maximum(img, 0.0, out=img)  # rounded and saturated as above
            return cv2.convertScaleAbs(img)
        np.rint(img, out=img)
        np.clip(img, 0, 255, out=img)
        return img.astype(np.uint8)

    def _before_lens(self, img: np.ndarray, side: int, k: int | None,
                     region: tuple[int, int, int, int] | None = None) -> np.ndarray:
        """_sensor's arithmetic up to the lens (float32): gain, black level, noise field k,
        white balance; pixel by pixel the same for a region as for the whole view."""
        cam = self.camera
        img = np.multiply(img, cam.gain[side])
        np.add(img, cam.bias[side], out=img)
        if k is not None:
            assert self._noise is not None  # k is a field of the bank
            noise = self._noise[k]
            img += noise if region is None else noise[region[0]:region[1], region[2]:region[3]]
        if cam.white:
            img = self._balanced(img, side)
        return img.astype(np.float32, copy=False)

    def _balanced(self, img: np.ndarray, side: int) -> np.ndarray:
        """The white balance's gains applied: a plane each (BGR), or the one grey plane."""
        gains = np.asarray(self._white[side], np.float32)
        return img * gains[0] if self.grey else img[..., None] * gains

    def _through_lens(self, drawn: np.ndarray | None, box: tuple[int, int, int, int] | None,
                      side: int, k: int | None) -> np.ndarray:
        """_sensor(img) with a lens (no pitch, flicker), from the bare scene's image: remap()
        makes each pixel from its map's entry and the 2x2 source pixels there alone, so only
        the pixels whose source meets the rectangle drawn over (box: rows r0:r1, columns
        c0:c1, round everything drawn; drawn: the ideal view's pixels there) are remapped
        again."""
        out = self._bare(side, k).copy()
        self.changed = (self._bare(side, k), None)
        if box is None or drawn is None:
            return out
        r0, r1, c0, c1 = box
        key = ("before lens", side, k)
        if key not in self._bare_images:
            self._bare_images[key] = self._before_lens(self._static[side][0], side, k)
        src = self._bare_images[key]
        lens, bounds = self._lens[side], self._lens_bounds[side]
        assert lens is not None and bounds is not None  # view() sends lens views only
        mx, my = lens
        # a source pixel on the image's edge also stands for the ones beyond it (replicated)
        h, w = mx.shape
        lo_x, hi_x = (-math.inf if c0 == 0 else c0 - 2), (math.inf if c1 >= w else c1 + 1)
        lo_y, hi_y = (-math.inf if r0 == 0 else r0 - 2), (math.inf if r1 >= h else r1 + 1)
        box = _lens_hit_box(bounds, mx, my, (lo_x, hi_x, lo_y, hi_y))
        if box is None:
            return out
        y0, y1, x0, x1 = box
        self.changed = (self._bare(side, k), box)
        # the drawn rectangle goes into the bare scene's image for the remap and is taken out
        # again: the same source as a copy with the rectangle in it, without copying the rest
        kept = src[r0:r1, c0:c1].copy()
        src[r0:r1, c0:c1] = self._before_lens(drawn, side, k, (r0, r1, c0, c1))
        try:
            part = cv2.remap(src, mx[y0:y1, x0:x1], my[y0:y1, x0:x1], cv2.INTER_LINEAR,
                             borderMode=cv2.BORDER_REPLICATE)
        finally:
            src[r0:r1, c0:c1] = kept
        np.maximum(part, 0.0, out=part)
        out[y0:y1, x0:x1] = cv2.convertScaleAbs(part)
        return out

    def _bare(self, side: int, k: int | None) -> np.ndarray:
        """The sensor's image (no pitch, flicker or lens) of the bare scene with noise field k,
        made once per scene layout."""
        self._static_views()
        if self._bare_key != self._static_key:
            self._bare_images, self._bare_key = {}, self._static_key
        key = (side, k)
        if key not in self._bare_images:
            self._bare_images[key] = self._sensor(self._static[side][0], side, k)
        return self._bare_images[key]

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
        left = self.image(0, with_robot)
        right = self.image(1, with_robot)
        return StereoFrame(left, right, self.world.t, self.world.t)
