"""The floor fitted again after the camera was pitched (a knock, a cable tug): a pure function.

A pitch moves the horizon, not the floor's growth of disparity with the row (d = B (y - y_h) / h
for a camera at height h: the slope B / h stays), so the new fit keeps the reference's slope and
finds the offset that most low rows agree on. A free line fit (perception.fit_floor) on a
pitched view can settle on the boxes that then fill more of the low rows.
"""

from __future__ import annotations

import numpy as np

from host.servo.perception import Floor


def refit_floor(disp: np.ndarray, reference: Floor, min_rows: int = 10,
                tol_px: float = 0.5) -> Floor | None:
    """The floor in disp (px, NaN where unknown, e.g. the robot's region) with the reference
    fit's slope: the offset most of the lowest 40% of rows agree on (each row's most common
    disparity), refined as their median within tol_px. None when fewer than min_rows agree."""
    h, w = disp.shape
    offsets = []
    for y in range(int(h * 0.6), h):
        row = disp[y][np.isfinite(disp[y])]
        if row.size < w // 4:
            continue
        hist, edges = np.histogram(row, bins=np.arange(row.min(), row.max() + 0.5, 0.25))
        if hist.size:
            k = int(np.argmax(hist))
            offsets.append((edges[k] + edges[k + 1]) / 2 - reference.slope * y)
    if len(offsets) < min_rows:
        return None
    o = np.array(offsets)
    counts = [(np.abs(o - c) <= tol_px).sum() for c in o]
    best = o[int(np.argmax(counts))]
    agree = o[np.abs(o - best) <= tol_px]
    if agree.size < min_rows:
        return None
    return Floor(reference.slope, float(np.median(agree)))
