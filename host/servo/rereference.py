"""The reference made again after the camera was pitched (a knock, a cable tug), and its checks:
pure functions.

A pitch moves the horizon, not the floor's growth of disparity with the row (d = B (y - y_h) / h
for a camera at height h: the slope B / h stays), so the new fit keeps the reference's slope and
finds the offset that most low rows agree on. A free line fit (perception.fit_floor) on a
pitched view can settle on the boxes that then fill more of the low rows.

A pitch moves the whole picture by the same rows and changes no depth: everything the
re-reference finds must be what the old reference showed, moved by the picture's measured shift
(rereference_fault). The floor's horizon (y_h = -offset / slope) moves with the picture; the
target is found where it was, shifted by those rows, at the disparity it had, and agrees in both
views. Anything else (the target moved or taken away meanwhile, a look-alike at a depth near the
target's elsewhere in the picture, a floor fitted on the wrong rows) is not a moved camera alone,
and the robot stays stopped.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import cv2
import numpy as np

from host.errors import HostError
from host.servo.perception import Floor, Target, nearest_object, span_overlap
from host.servo.tracker import TrackerConfig
from host.stereo.grey import to_grey


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


def horizon_row(floor: Floor) -> float:
    """The row where the floor's disparity reaches zero (the horizon), px."""
    return -floor.offset / floor.slope


@dataclass(frozen=True)
class RereferenceLimits:
    """How far a re-reference may stray from the old reference moved by the picture's shift.

    horizon_rows: the floor fit's offset is a median of rows' modes in 0.25 px bins (about 1
    row at the default scene's 0.24 px a row) and the picture's shift a phase correlation
    (sub-pixel); 2.5 rows leave room for both, a tenth of a degree of pitch less than
    ServoConfig.moved_rows' smallest move reported. disparity: a pitch of 2 degrees changes the
    depth of a point 0.3 m off the axis by 0.7 %; the target's measures scatter by 0.1-0.2 px;
    a move of the target by 3 % (4.5 cm at 1.5 m) is a move, not the camera's. overlap: of the
    narrower region, in both directions (nearest_object's region of one box varies between
    28 and 89 px wide from one measure to the next, always over the same box)."""

    horizon_rows: float = 2.5
    slope_frac: float = 0.02
    disparity_px: float = 0.5
    disparity_frac: float = 0.03
    overlap: float = 0.5
    agreement: float = 0.6
    # of the target's disparity: the farthest a target found at its place by two tries running
    # (rereference_fault's earlier) may have moved in depth: the tracker's own bound (farther,
    # and it is another object)
    moved_frac: float = TrackerConfig.same_depth
    width_factor: float = 2.0  # a target moved in depth (target_moved) keeps its width scaled
    # by the disparities' ratio within this factor either way (a narrower object nearer, in
    # front of the box, does not scale so: a person's legs, a chair). Measured on the dev
    # knock+move trials held by target_moved at 3a87aef (seeds 1:108 2:29 3:39 5:60 5:179
    # 6:194 7:8 8:184): new width / (old width * d_new / d_old) 0.580-1.323


def floor_follows_picture(floor_px: float, shift_rows: float, floor: Floor,
                          limits: RereferenceLimits = RereferenceLimits()) -> bool:
    """Whether the floor's rows, floor_px off their fit (inputs.floor_shift_px), moved as a
    pitch that moved the picture shift_rows moves them: the horizon by those rows, within
    horizon_rows (a floor row's disparity changes by -slope x rows). Someone walking past near
    the camera fills the floor's rows with what no pitch explains, and the phase correlation
    may read them as a shift for a moment: that is no moved camera."""
    return abs(-floor_px / floor.slope - shift_rows) <= limits.horizon_rows


def target_shift_rows(reference: np.ndarray, image: np.ndarray, box: tuple[int, int, int, int],
                      max_rows: int, max_cols: int = 4, min_score: float = 0.25,
                      hide: tuple[int, int, int, int] | None = None) -> float:
    """How many rows (positive: down) the picture of the region box (x, y, w, h) of reference
    (a picture of the target before the camera moved, rig.reference_image: grey float32)
    moved in image: the best normalised correlation of the region within max_rows up or down
    and max_cols across (within the picture), the pixels of hide (x0, y0, x1, y1: the robot
    where it stood in reference) left out. A region within max_rows of the picture's top or
    bottom is matched on its rows that stay in the picture however far the search goes up or
    down (a pitch moves a box standing on the floor near the bottom partly out of the
    picture: seed 11's trial 755, a region reaching 17 rows from the bottom searched 18 rows
    was NaN); the row found is the same. NaN when the best scores below min_score (the
    region's picture is not there: it was replaced, or something stands in front of it), when
    hide leaves less than a quarter of the region, or when fewer than half its rows (or 8)
    stay in the picture through the search. A pitch warps the picture a little and the
    sensor's noise is new: a box's front knocked 1.8 degrees scored 0.37-0.49 at its shifted
    place and under 0.1 elsewhere (dev seed 8's trial 45)."""
    grey = to_grey(image).astype(np.float32)
    h, w = grey.shape
    x, y, bw, bh = box
    top, bottom = max(0, max_rows - y), max(0, y + bh + max_rows - h)  # rows left out
    if bh - top - bottom < max(8, bh / 2):
        return math.nan
    y, bh = y + top, bh - top - bottom
    # across, the search stops at the picture's sides (a region cut by the picture's edge
    # reaches it); down, it must reach max_rows both ways
    y0, y1, x0, x1 = y - max_rows, y + bh + max_rows, max(0, x - max_cols), \
        min(w, x + bw + max_cols)
    if bw < 8 or bh < 8 or y0 < 0 or y1 > h or x < 0 or x + bw > w:
        return math.nan
    template = reference[y:y + bh, x:x + bw]
    mask = np.ones_like(template)
    if hide is not None:
        hx0, hy0, hx1, hy1 = hide
        mask[max(0, hy0 - y):max(0, hy1 - y), max(0, hx0 - x):max(0, hx1 - x)] = 0
        if mask.sum() < mask.size / 4:
            return math.nan
    scores = cv2.matchTemplate(grey[y0:y1, x0:x1], template, cv2.TM_CCOEFF_NORMED,
                               mask=mask if hide is not None else None)
    scores[~np.isfinite(scores)] = -1.0
    _, best, _, (_, row) = cv2.minMaxLoc(scores)
    return float(row - max_rows) if best >= min_score else math.nan


def nearest_agreeing(disp: np.ndarray, min_area: int, agreement: Callable[[Target], float],
                     limits: RereferenceLimits = RereferenceLimits(),
                     tries: int = 4) -> tuple[Target, float]:
    """The nearest object in disp (perception.nearest_object) whose two views do not
    disagree, with its agreement (inputs.views_agree via agreement): a region scoring below
    limits.agreement is a false one (flicker spoils one view: seed 11's trial 522 found
    regions 8 px nearer than the target agreeing -0.01 to -0.09 while the target stood where
    it was), and its pixels (its box's at its depth, within the larger of 1 px and its
    spread) are left out before looking again, up to `tries` times. A region without texture
    (NaN) is no proof of a false one and is returned as found (rereference_fault refuses it).
    HostError when no object is left."""
    disp = disp.copy()
    for _ in range(tries):
        found = nearest_object(disp, min_area)
        score = agreement(found)
        if not score < limits.agreement:  # agrees, or NaN: no texture to tell
            return found, score
        x, y, w, h = found.bbox
        part = disp[y:y + h, x:x + w]
        part[part >= found.disparity - max(1.0, found.spread)] = np.nan
    raise HostError(f"every nearest object's two views disagree ({tries} tried)")


def rereference_fault(old_floor: Floor | None, floor: Floor, shift_rows: float, old: Target,
                      new: Target, agreement: float, moved_rows: float = 0.0,
                      target_rows: float | None = None, last: float | None = None,
                      earlier: Target | None = None,
                      limits: RereferenceLimits = RereferenceLimits()) -> str:
    """Why a re-reference cannot be trusted ("" when it can): what it found (floor, the
    nearest object new, how well new's two views agree) against the old reference (old_floor,
    the target old) moved by the picture's measured vertical shift (shift_rows, positive: down;
    rig.vertical_shift_px). Checked: the picture moved at least moved_rows (the least move
    the servo calls a moved camera: less, and what moved the floor's rows was put down over
    them, a large box near the camera, which the phase correlation may read as a shift for a
    moment), the floor's slope kept, its horizon moved by the picture's shift, the target
    where the old one was (its region shifted by those rows overlapping the old by `overlap`
    across and down; and, target_rows given, its picture moved by the picture's shift:
    target_shift_rows, NaN when not found), at its disparity (old's, the median of the
    tracker's last measures, or last, the newest of them: a target that moved in depth shortly
    before the knock has been measured there once or twice, and the median lags), and
    agreeing in both views. A target moved in depth while the camera moved (the box pushed
    just before the knock, unmeasured over a turn, or during the wait: seed 16's trials 239,
    420) is another disparity: one try refuses it; earlier given (the nearest object the
    previous try of this wait found), the target's move is taken as the tracker takes an aged
    depth's (two readings agreeing with each other): new and earlier at the same place and
    depth (target_moved), within moved_frac of the target's disparity, every other check as
    before (the floor, the target's own picture moved with the picture, its place, its
    views)."""
    lim = limits
    if abs(shift_rows) < moved_rows:
        return (f"the picture did not move ({shift_rows:+.1f} rows): something stands over "
                f"the floor's rows, the camera did not move")
    if old_floor is not None:
        if abs(floor.slope - old_floor.slope) > lim.slope_frac * abs(old_floor.slope):
            return (f"the floor's slope changed from {old_floor.slope:.3f} to "
                    f"{floor.slope:.3f} px a row")
        moved = horizon_row(floor) - horizon_row(old_floor)
        if not abs(moved - shift_rows) <= lim.horizon_rows:
            return (f"the floor's horizon moved {moved:+.1f} rows where the picture moved "
                    f"{shift_rows:+.1f}")
    if target_rows is not None and not abs(target_rows - shift_rows) <= lim.horizon_rows:
        return (f"the target's picture moved {target_rows:+.0f} rows where the picture moved "
                f"{shift_rows:+.1f}" if math.isfinite(target_rows) else
                "the target's picture is not where the picture's shift puts it")
    if other_depth(old, new, last, lim) and not target_moved(old, new, earlier, lim):
        return (f"the nearest object is at {new.disparity:.2f} px, the target was at "
                f"{old.disparity:.2f} px")
    ox, oy, ow, oh = old.bbox
    nx, ny, nw, nh = new.bbox
    across = span_overlap(ox, ox + ow, nx, nx + nw)
    down = span_overlap(oy + shift_rows, oy + oh + shift_rows, ny, ny + nh)
    if across < lim.overlap or down < lim.overlap:
        return (f"the nearest object is not where the target was: ({nx}, {ny}) {nw}x{nh} px "
                f"for ({ox}, {oy + shift_rows:.0f}) {ow}x{oh}")
    if not agreement >= lim.agreement:
        shown = "no texture" if math.isnan(agreement) else f"{agreement:.2f}"
        return f"the target's region does not agree in both views ({shown})"
    return ""


def other_depth(old: Target, new: Target, last: float | None = None,
                limits: RereferenceLimits = RereferenceLimits()) -> bool:
    """Whether new is at another disparity than the target old's (the median of the tracker's
    measures) and than last (its newest measure, None: none): a re-reference that takes it
    takes the target moved in depth (target_moved), and the loop keeps old among the targets
    a nearer object replaced (it may be an object in front of the target after all)."""
    lim = limits

    def near(d: float) -> bool:
        return abs(new.disparity - d) <= max(lim.disparity_px, lim.disparity_frac * d)

    return not (near(old.disparity) or last is not None and near(last))


def target_moved(old: Target, new: Target, earlier: Target | None,
                 limits: RereferenceLimits = RereferenceLimits()) -> bool:
    """Whether new, found by a re-reference at another disparity than the target old had, is
    the target moved in depth: earlier (the previous try's find, None: no previous try)
    found at new's disparity (within limits' disparity_px or disparity_frac) and overlapping
    new by limits.overlap across and down (two tries running saw the same object still, not a
    person passing, nor a phantom), new within limits.moved_frac of old's disparity (the
    tracker follows a move no larger), and new's width old's scaled by the disparities'
    ratio within limits.width_factor (a box moved in depth looks wider or narrower with it;
    a narrower object nearer in front of it, which span_overlap's share of the narrower
    region places where the box was, does not). Where it stands (old's place moved by the
    picture) and what it shows (its picture, its views) are rereference_fault's own checks."""
    if earlier is None:
        return False
    lim = limits
    d = earlier.disparity
    if not abs(new.disparity - d) <= max(lim.disparity_px, lim.disparity_frac * d):
        return False
    if not abs(new.disparity - old.disparity) <= lim.moved_frac * old.disparity:
        return False
    ow, nw = old.bbox[2], new.bbox[2]
    scaled = ow * new.disparity / old.disparity  # the old target's width at new's depth
    if not scaled / lim.width_factor <= nw <= scaled * lim.width_factor:
        return False  # not the target's width at its new depth: another object in front
    ex, ey, ew, eh = earlier.bbox
    nx, ny, nw, nh = new.bbox
    return (span_overlap(ex, ex + ew, nx, nx + nw) >= lim.overlap
            and span_overlap(ey, ey + eh, ny, ny + nh) >= lim.overlap)


def fill_hidden(new: np.ndarray, old: np.ndarray, box: tuple[int, int, int, int],
                shift_rows: float) -> np.ndarray:
    """The new reference map with the robot's region (box: x0, y0, x1, y1), where the robot
    hid the scene, taken from the old reference moved by the picture's shift (a pitch moves
    every pixel's row and keeps its disparity); what the old one did not show stays NaN."""
    out = new.copy()
    h = new.shape[0]
    x0, y0, x1, y1 = box
    dy = int(round(shift_rows))
    ys = np.arange(y0, y1)
    src = ys - dy
    ok = (src >= 0) & (src < h)
    region = out[ys[ok], x0:x1]
    moved = old[src[ok], x0:x1]
    hole = ~np.isfinite(region)
    region[hole] = moved[hole]
    out[ys[ok], x0:x1] = region
    return out
