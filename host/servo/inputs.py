"""Inputs that lie: a frozen sensor, a camera moved since its reference, a phantom object.

Each check is a pure function or a small state machine fed once per frame (or once per
re-measure), returning a reason ("" when the input can be trusted) or the object it vouches
for; the servo loop decides what to do (stop, re-reference, ignore).

    FrozenSensors.update(frame)       -> ""  or "right sensor frozen: image repeated" ...
    camera_moved(disp, floor)         -> ""  or "the floor is 1.8 px off its reference ..."
    views_agree(left, right, box, d)  -> NCC of the region's two views at disparity d
    NearerObject.update(candidate, agreement) -> the candidate once it is real, else None
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from numba import njit

from host.camera.source import StereoFrame
from host.servo.perception import Floor, Target


class FrozenSensors:
    """Whether each frame brings, from both sensors, a new image with an advancing stamp.

    A live sensor never repeats an image exactly (its noise alone changes it), so a repeat is
    a frozen sensor or a driver handing out its last buffer again; a stamp that does not
    advance is an old frame, whatever the image. Compared: a subsample (every `step`-th row
    and column) of each raw image, and each sensor's stamp against its own last.

    Feed every frame as it arrives, before it is used (the loop's `_frame()`); update returns
    "" for a frame that can be used, else the reason it cannot (the robot must not drive on
    it: stop, and count it toward the stale limit like a missing observation).
    """

    SIDES = ("left", "right")

    def __init__(self, step: int = 4) -> None:
        self.step = step
        self._last: list[tuple[np.ndarray, float] | None] = [None, None]
        self.repeats = [0, 0]  # consecutive repeated images per sensor

    def update(self, frame: StereoFrame) -> str:
        reasons = []
        for side, (image, stamp) in enumerate(((frame.left, frame.t_left),
                                               (frame.right, frame.t_right))):
            sample = np.ascontiguousarray(image[::self.step, ::self.step]).copy()
            last = self._last[side]
            self._last[side] = (sample, stamp)
            if last is None:
                continue
            name = self.SIDES[side]
            if np.array_equal(sample, last[0]):
                self.repeats[side] += 1
                reasons.append(f"{name} sensor frozen: image repeated")
            else:
                self.repeats[side] = 0
            if not stamp > last[1]:
                reasons.append(f"{name} sensor frozen: its stamp did not advance")
        return "; ".join(reasons)


def _row_mode(row: np.ndarray) -> float:
    """The most common disparity of a row's valid pixels (0.25 px bins).

    np.histogram(row, bins=edges)'s fullest bin (the first of equal counts) is counted by
    _fullest_bin at a fraction of its CPU (it sorts the row and calls searchsorted per block:
    3.6 % of a trial's CPU; issue 25), with the same edges (np.arange's own, made here)."""
    lo, hi = _extremes(row)
    kind = row.dtype.type  # row.min() and row.max() as np.arange had them (+ 0.5 in their type)
    edges = np.arange(kind(lo), kind(hi) + 0.5, 0.25)
    k = _fullest_bin(row, edges)
    return float((edges[k] + edges[k + 1]) / 2)


@njit(cache=True)
def _extremes(values: np.ndarray) -> tuple[float, float]:
    """(values.min(), values.max()) in one pass; NaN for both if any value is NaN."""
    lo = hi = values[0]
    for v in values:
        if np.isnan(v):
            return np.nan, np.nan
        lo = min(lo, v)
        hi = max(hi, v)
    return lo, hi


@njit(cache=True)
def _fullest_bin(values: np.ndarray, edges: np.ndarray) -> int:
    """The index of np.histogram(values, bins=edges)'s first fullest bin: bin i holds
    edges[i] <= v < edges[i + 1], the last bin also v == edges[-1] (edges ascending; values
    outside them, or NaN, in none). The comparisons are in float64, as searchsorted's."""
    n = edges.size - 1
    counts = np.zeros(max(n, 1), np.int64)
    lo, hi = edges[0], edges[n]
    for v in values:
        f = np.float64(v)
        if not lo <= f <= hi:
            continue
        i = n - 1 if f == hi else np.searchsorted(edges, f, side="right") - 1
        counts[i] += 1
    best = 0
    for i in range(n):
        if counts[i] > counts[best]:
            best = i
    return best


def floor_shift_px(disp: np.ndarray, floor: Floor, min_rows: int = 10,
                   reference: np.ndarray | None = None) -> float:
    """How far (px of disparity) the floor in disp lies from the reference's floor line: the
    median over the lowest 40 % of rows of each row's most common disparity minus the line's
    (a pitch of the rig by a moves the floor's rows by f tan a, and so its disparity by the
    line's slope times that). With the reference map (the scene without the robot), only the
    rows that the floor dominates there, over the pixels valid in disp (with the robot's region
    left out, an object may dominate a row the floor dominated). NaN when fewer than min_rows
    rows show enough valid pixels."""
    h, w = disp.shape
    diffs = []
    for y in range(int(h * 0.6), h):
        valid = np.isfinite(disp[y])
        row = disp[y][valid]
        if row.size < w // 4:
            continue
        line = float(floor.disparity(np.array([y], np.float64))[0])
        if reference is not None:
            ref = reference[y][valid]
            ref = ref[np.isfinite(ref)]
            if ref.size < w // 4 or abs(_row_mode(ref) - line) > 0.5:
                continue  # not a floor row, seen as disp sees it
        diffs.append(_row_mode(row) - line)
    return float(np.median(diffs)) if len(diffs) >= min_rows else math.nan


def camera_moved(disp: np.ndarray, floor: Floor | None, max_shift_px: float = 0.6,
                 reference: np.ndarray | None = None) -> str:
    """"" while the reference phase's floor fit still fits the floor in disp, else the reason
    (the camera was knocked or tugged: the reference no longer removes the floor, and the
    floor's rows would pass for an object). disp: a whole map of this run (the robot's region
    NaN is fine), px; floor: the reference's fit (None: nothing to check). A moved camera must
    be re-referenced (with the robot out of view) or the run stopped, never reported "held".
    A yaw or a sideways shift leaves the floor's rows where they were and is not reported."""
    if floor is None:
        return ""
    shift = floor_shift_px(disp, floor, reference=reference)
    if math.isfinite(shift) and abs(shift) > max_shift_px:
        return (f"the floor is {shift:+.1f} px off its reference fit: the camera moved "
                f"since the reference")
    return ""


def views_agree(left: np.ndarray, right: np.ndarray, box: tuple[int, int, int, int],
                disparity: float) -> float:
    """How well the left view's region box (x, y, w, h) matches the right view shifted by
    disparity (px): the mean over rows of each row's zero-mean normalised cross-correlation,
    so that a gain and an offset per row (mains flicker read by a rolling shutter, a sensor's
    exposure) cancel. About 1 for a surface really at that disparity, near 0 for a region a
    matcher put there by mistake (a flicker band matched to the wrong place). NaN when the
    shifted region leaves the picture or has no texture. Images grey (or BGR: converted)."""
    lg, rg = (cv2.cvtColor(v, cv2.COLOR_BGR2GRAY) if v.ndim == 3 else v for v in (left, right))
    x, y, w, h = box
    if x - disparity < 0 or w < 4 or h < 1:
        return math.nan
    a = lg[y:y + h, x:x + w].astype(np.float32)
    xs = (np.arange(x, x + w, dtype=np.float32) - np.float32(disparity))[None, :]
    xs = np.repeat(xs, h, axis=0)
    ys = np.repeat(np.arange(y, y + h, dtype=np.float32)[:, None], w, axis=1)
    b = cv2.remap(rg.astype(np.float32), xs, ys, cv2.INTER_LINEAR)
    a = a - a.mean(axis=1, keepdims=True)
    b = b - b.mean(axis=1, keepdims=True)
    den = np.sqrt((a * a).sum(axis=1) * (b * b).sum(axis=1))
    ok = den > 1e-3 * w
    if not ok.any():
        return math.nan
    return float(np.mean((a * b).sum(axis=1)[ok] / den[ok]))


class NearerObject:
    """Temporal and two-view consistency before any retarget onto a nearer object.

    Feed each re-measure's nearer-object candidate (the Target nearest_object found nearer
    than the current one, or None when there is none) with its views_agree score. The
    candidate is vouched for (returned) once `frames` consecutive re-measures found it at the
    same place (bounding boxes overlapping by `overlap` of the smaller, centres within
    `still` of the wider's width) and depth (disparity within max(tol_px, tol_frac of it)),
    each with views agreeing by at least min_agreement. None, a disagreeing view or a
    different candidate starts the count again. Returns None until then: retarget only on
    what update returns.

    In the servo's own frames (30 fps, a re-measure a second) a flicker phantom at 100 Hz sits
    at the same place each time (a second is a whole number of flicker periods) but its two
    views disagree (views_agree 0.06-0.08, the real box 0.8-1); a person crossing agrees in
    both views but moves (0.4 m/s at 0.9 m: 60 px a second). A camera that moved makes a
    strip of floor that is real in both views and stays: check camera_moved first.
    """

    def __init__(self, frames: int = 3, min_agreement: float = 0.6, overlap: float = 0.5,
                 still: float = 0.1, tol_px: float = 1.0, tol_frac: float = 0.05) -> None:
        self.frames, self.min_agreement, self.overlap = frames, min_agreement, overlap
        self.still, self.tol_px, self.tol_frac = still, tol_px, tol_frac
        self._run: list[Target] = []

    def reset(self) -> None:
        self._run = []

    def _same(self, a: Target, b: Target) -> bool:
        ax, ay, aw, ah = a.bbox
        bx, by, bw, bh = b.bbox
        ix = min(ax + aw, bx + bw) - max(ax, bx)
        iy = min(ay + ah, by + bh) - max(ay, by)
        inter = max(0, ix) * max(0, iy)
        small = min(aw * ah, bw * bh)
        tol = max(self.tol_px, self.tol_frac * max(a.disparity, b.disparity))
        moved = abs((ax + aw / 2) - (bx + bw / 2)) + abs((ay + ah / 2) - (by + bh / 2))
        return (small > 0 and inter >= self.overlap * small
                and moved <= max(3.0, self.still * max(aw, bw))
                and abs(a.disparity - b.disparity) <= tol)

    def update(self, candidate: Target | None, agreement: float) -> Target | None:
        if candidate is None or not agreement >= self.min_agreement:
            self._run = []
            return None
        if self._run and not self._same(self._run[-1], candidate):
            self._run = []
        self._run.append(candidate)
        if len(self._run) >= self.frames:
            return candidate
        return None
