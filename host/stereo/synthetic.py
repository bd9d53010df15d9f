"""Synthetic rectified stereo pairs with exact ground truth, from textured layers.

A layer is a textured plane whose disparity varies linearly over the left image,
d(x, y) = d0 + dx * x + dy * y (px), cut to a rectangle or an ellipse given in left-image
coordinates. A view at shift s (0 = left, 1 = right) sees at pixel xv the layer point x with
xv = x - s * d(x, y). Views are painted far to near, so occlusions come out exact.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from host.stereo.scenes import Scene


@dataclass(frozen=True)
class Layer:
    """A textured plane; box = (x0, y0, x1, y1) in left-image px, None = whole plane."""

    d0: float
    texture: np.ndarray  # float32, indexed [y, x + margin] in left-image px
    margin: int = 0
    dx: float = 0.0
    dy: float = 0.0
    box: tuple[float, float, float, float] | None = None
    ellipse: bool = False

    def mean_disparity(self, width: int, height: int) -> float:
        """Disparity at the centre of the layer's visible part (the painting order)."""
        x0, y0, x1, y1 = self.box or (0, 0, width, height)
        x0, x1 = max(x0, 0), min(x1, width)
        y0, y1 = max(y0, 0), min(y1, height)
        return self.d0 + self.dx * (x0 + x1) / 2 + self.dy * (y0 + y1) / 2


def random_texture(rng: np.random.Generator, height: int, width: int, sigma: float = 1.0,
                   contrast: float = 60.0, mean: float = 128.0) -> np.ndarray:
    """Band-limited random texture (float32 grey levels): blurred noise, then stretched."""
    noise = rng.standard_normal((height, width)).astype(np.float32)
    tex = np.asarray(cv2.GaussianBlur(noise, (0, 0), sigma), np.float32)
    tex *= contrast / max(float(tex.std()), 1e-6)
    return tex + mean


def render_view(layers: list[Layer], width: int, height: int,
                shift: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Paint layers far to near at a view shift; returns (image float32, disparity, layer id)."""
    image = np.zeros((height, width), np.float32)
    disp = np.full((height, width), np.nan, np.float32)
    ids = np.full((height, width), -1, np.int32)
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float32)
    order = sorted(range(len(layers)), key=lambda i: layers[i].mean_disparity(width, height))
    for i in order:
        ly = layers[i]
        # xv = x - s (d0 + dx x + dy y)  =>  x = (xv + s (d0 + dy y)) / (1 - s dx)
        x = (xs + shift * (ly.d0 + ly.dy * ys)) / (1.0 - shift * ly.dx)
        inside = np.ones_like(image, bool)
        if ly.box is not None:
            x0, y0, x1, y1 = ly.box
            if ly.ellipse:
                cx, cy, rx, ry = (x0 + x1) / 2, (y0 + y1) / 2, (x1 - x0) / 2, (y1 - y0) / 2
                inside = ((x - cx) / rx) ** 2 + ((ys - cy) / ry) ** 2 <= 1.0
            else:
                inside = (x >= x0) & (x < x1) & (ys >= y0) & (ys < y1)
        sample = cv2.remap(ly.texture, x + ly.margin, ys, cv2.INTER_LINEAR,
                           borderMode=cv2.BORDER_REFLECT)
        image[inside] = sample[inside]
        disp[inside] = (ly.d0 + ly.dx * x + ly.dy * ys)[inside]
        ids[inside] = i
    return image, disp, ids


def render_pair(layers: list[Layer], width: int, height: int, noise: float = 0.0,
                rng: np.random.Generator | None = None) -> Scene:
    """Left and right uint8 views, left ground truth and the nonocc / all masks."""
    rng = rng or np.random.default_rng(0)
    left, gt, ids_l = render_view(layers, width, height, 0.0)
    right, _, ids_r = render_view(layers, width, height, 1.0)
    # a left pixel is non-occluded when the right view shows the same layer where it lands
    ys, xs = np.mgrid[0:height, 0:width]
    xr = xs - gt
    xi = np.clip(np.rint(np.nan_to_num(xr)), 0, width - 1).astype(int)
    nonocc = ids_r[ys, xi] == ids_l
    nonocc &= (xr >= 0) & (xr <= width - 1)
    views = []
    for v in (left, right):
        if noise > 0:
            v = v + rng.normal(0.0, noise, v.shape).astype(np.float32)
        views.append(np.clip(np.rint(v), 0, 255).astype(np.uint8))
    return Scene("synthetic", views[0], views[1], gt,
                 {"nonocc": nonocc, "all": np.isfinite(gt)}, float(np.nanmax(gt)))


def synthetic_scene(seed: int = 0, width: int = 320, height: int = 240, max_disp: float = 40.0,
                    boxes: int = 4, slanted: bool = True, noise: float = 1.0) -> Scene:
    """Random scene: a (slanted) background plane and boxes/discs nearer, with occlusions."""
    rng = np.random.default_rng(seed)
    margin = int(max_disp) + 8
    tex_w = width + 2 * margin

    def texture() -> np.ndarray:
        return random_texture(rng, height, tex_w, sigma=rng.uniform(0.8, 1.5),
                              contrast=rng.uniform(30, 60), mean=rng.uniform(90, 160))

    d_back = rng.uniform(0.1, 0.25) * max_disp
    dx = rng.uniform(0.0, 0.15) * max_disp / width if slanted else 0.0
    layers = [Layer(d_back, texture(), margin, dx=dx)]
    for _ in range(boxes):
        w = rng.uniform(0.15, 0.35) * width
        h = rng.uniform(0.2, 0.45) * height
        x0 = rng.uniform(0.05 * width + max_disp, width - w - 2)
        y0 = rng.uniform(2, height - h - 2)
        d = rng.uniform(0.35, 1.0) * max_disp
        layers.append(Layer(d, texture(), margin, box=(x0, y0, x0 + w, y0 + h),
                            ellipse=bool(rng.integers(0, 2))))
    scene = render_pair(layers, width, height, noise, rng)
    scene.name = f"synthetic-{seed}"
    return scene
