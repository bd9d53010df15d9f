"""The simulated camera's rectification, remapped again only where a view differs from its bare
scene: the same images as host.camera.calibration.Rectifier's, for a fraction of its CPU.

The renderer makes each view from the sensor's image of the bare scene (one per noise field of
its bank and layout) with a rectangle drawn over it (Renderer.changed). remap() makes each
output pixel from its map's entry and the 2x2 source pixels there alone (INTER_LINEAR, fixed
point, a constant border), so the rectified bare image, made once, holds every pixel whose
source misses the rectangle; only the others are remapped, with the same maps' entries. A view
made whole (a pitched rig, flicker) or an image the renderer did not make last for that side
is remapped whole, as the Rectifier does.
"""

from __future__ import annotations

from typing import Protocol

import cv2
import numpy as np

from host.camera.calibration import Calibration, Rectifier
from host.camera.source import StereoFrame
from host.sim.hit_box import hit_of

Changed = tuple[np.ndarray, tuple[int, int, int, int] | None]  # Renderer.changed


class Made(Protocol):
    def made(self, side: int) -> tuple[np.ndarray, Changed | None] | None:
        """The side's last image and how it was made (Renderer.changed), None before any."""


class SimRectifier(Rectifier):
    """A Rectifier for the frames of one SimSource (source.made tells how each was made)."""

    MAX_BARE = 64  # rectified bare images kept (a bank of 8 noise fields, 2 sides, layouts)

    def __init__(self, calib: Calibration, source: Made) -> None:
        super().__init__(calib)
        self.source = source
        self._rectified: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
        # (side, id of the bare image): (bare, rectified with that side's maps)
        # per output row, the least and greatest source row of the maps; per column, the
        # same of the source columns (the 2x2 source pixels start there)
        self._bounds = [(m[..., 1].min(1), m[..., 1].max(1), m[..., 0].min(0), m[..., 0].max(0))
                        for m, _ in self._maps]

    def __call__(self, frame: StereoFrame) -> StereoFrame:
        h, w = frame.left.shape[:2]
        if (w, h) != self.calib.size:
            return super().__call__(frame)  # its error
        left, right = (self._side(side, img) for side, img in enumerate((frame.left,
                                                                         frame.right)))
        return StereoFrame(left, right, frame.t_left, frame.t_right)

    def _side(self, side: int, img: np.ndarray) -> np.ndarray:
        m1, m2 = self._maps[side]
        made = self.source.made(side)
        if made is None or made[0] is not img or made[1] is None:
            return cv2.remap(img, m1, m2, cv2.INTER_LINEAR)
        bare, box = made[1]
        out = self._bare(side, bare).copy()
        if box is None:
            return out
        hit = _hit(self._bounds[side], m1, box)
        if hit is not None:
            y0, y1, x0, x1 = hit
            out[y0:y1, x0:x1] = cv2.remap(img, m1[y0:y1, x0:x1], m2[y0:y1, x0:x1],
                                          cv2.INTER_LINEAR)
        return out

    def _bare(self, side: int, bare: np.ndarray) -> np.ndarray:
        """The bare image rectified with the side's maps, made once (kept with the image it is
        of, by side: one array shared by the two sides is rectified once for each)."""
        key = (side, id(bare))
        kept = self._rectified.get(key)
        if kept is None or kept[0] is not bare:
            if len(self._rectified) >= self.MAX_BARE:
                self._rectified.clear()
            m1, m2 = self._maps[side]
            kept = self._rectified[key] = (bare, cv2.remap(bare, m1, m2, cv2.INTER_LINEAR))
        return kept[1]


def _hit(bounds: tuple[np.ndarray, ...], m1: np.ndarray, box: tuple[int, int, int, int]
         ) -> tuple[int, int, int, int] | None:
    """The rows y0:y1 and columns x0:x1 round the output pixels whose 2x2 source pixels (from
    m1's x, y to x + 1, y + 1) meet the source rows r0:r1 and columns c0:c1 of box, None if
    none does: the source x in c0 - 1 .. c1 - 1 and y in r0 - 1 .. r1 - 1, looked for in the
    rows and columns whose bounds reach there."""
    r0, r1, c0, c1 = box
    row_lo, row_hi, col_lo, col_hi = bounds
    # whole source pixels: x in c0 - 1 .. c1 - 1 is strictly inside (c0 - 2, c1)
    got = hit_of(row_lo, row_hi, col_lo, col_hi, m1[..., 0], m1[..., 1], c0 - 2, c1, r0 - 2, r1)
    return None if got[0] < 0 else got
