"""The target kept true during the run: each re-measure of the nearest object (on a whole map
with the floor and the robot left out) follows it when it moves (median of the last three),
retargets onto a nearer object only once NearerObject vouches for it (three re-measures running
at the same place and depth, its two views agreeing: a flicker phantom moves and does not
match). When most of its area twice shows what lay behind it and its two views no longer agree
at its disparity (a map spoilt by flicker is not a box gone) the target is gone: the next
nearest object becomes the target once two running re-measures find it at the same place and
depth, its two views agreeing (the wall behind is no object); none within three more
re-measures, the run ends ("target vanished"; a pure state machine).
A depth gone old (aged: no re-measure for longer than a box move may go unseen, e.g. over a
turn) is confirmed afresh: by a reading agreeing with it, or, the target moved, by two
readings agreeing with each other (their mean at once, not a median with the old value);
until then it is unconfirmed (`confirmed` False) and the servo does not drive on it."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from host.camera.geometry import Geometry
from host.errors import HostError
from host.servo.inputs import NearerObject
from host.servo.perception import Target, fixed_cells, nearest_object, span_overlap

VANISHED = "target vanished"


def behind_px(d: float) -> float:
    """The disparity (px) under which a reading lies behind a target at d: what its region
    shows where the target has gone (a pixel, or a tenth of d, farther)."""
    return d - max(1.0, 0.1 * d)


@dataclass(frozen=True)
class TrackerConfig:
    history: int = 3  # re-measures the target's disparity is the median of
    agree: int = 2  # re-measures that must agree before a "vanished"
    overlap: float = 0.3  # of the narrower region's width: the same object
    still_there: float = 0.6  # views agreeing this well at the object's disparity: not gone
    successor: int = 2  # re-measures that must find the same next object once it is gone
    successor_tries: int = 3  # re-measures after "gone" without one: the run ends
    object_width: float = 0.6  # of the image's width: wider is the wall behind, no object
    same_depth: float = 0.35  # of its disparity: a target moved farther is another object
    fresh_agree: float = 0.01  # of its disparity: two readings this close agree (aged depth)


class TargetTracker:
    def __init__(self, target: Target, min_area: int, config: TrackerConfig = TrackerConfig()
                 ) -> None:
        self.target, self.min_area, self.cfg = target, min_area, config
        self.history = [target.disparity] * (config.history - 1)
        self.stop_reason = ""  # set when the run must end
        self.retargeted = False  # the last update moved the target to a new object
        self._doubt = (0, "")  # consecutive re-measures that disagree, and how
        self.nearer = NearerObject()
        self.successor = NearerObject(frames=config.successor)  # the next object, once gone
        self.gone = 0  # re-measures since the target was found gone (0: it is not)
        self.measured = False  # the last update measured the target's depth
        self.fresh: list[float] | None = None  # readings since the depth aged (None: not
        # aged, the depth confirmed)

    @property
    def confirmed(self) -> bool:
        """The target's depth is not an aged one waiting to be measured again."""
        return self.fresh is None

    def aged(self) -> None:
        """The target's depth has gone unmeasured too long: the next readings must confirm
        it (one agreeing with it) or replace it (two agreeing with each other)."""
        if self.fresh is None:
            self.fresh = []

    def update(self, disp: np.ndarray, agreement: Callable[[Target], float] = lambda t: 1.0
               ) -> Target:
        """Measure again on disp (px, NaN = invalid: floor and robot left out): the target.
        agreement: how well a region's two views match at its disparity (views_agree)."""
        self.retargeted = self.measured = False
        old = self.target
        bx, by, bw, bh = old.bbox
        there = disp[by:by + bh, bx:bx + bw]
        there = there[np.isfinite(there)]
        if there.size < self.min_area // 4:
            return old  # the robot hides the object: nothing to learn
        try:
            found: Target | None = nearest_object(disp, self.min_area, near=old.disparity)
        except HostError:
            found = None
        overlap = found is not None and span_overlap(
            bx, bx + bw, found.bbox[0], found.bbox[0] + found.bbox[2]) > self.cfg.overlap
        if overlap and found is not None and (
                found.bbox[2] > self.cfg.object_width * disp.shape[1]
                or abs(found.disparity - old.disparity) > self.cfg.same_depth * old.disparity):
            overlap = False  # the wall behind it, or another object: not the target moved
        nearer = found is not None and not overlap and found.disparity > old.disparity
        vouched = self.nearer.update(found if nearer else None,
                                     agreement(found) if nearer and found else float("nan"))
        if self.gone:
            return self._succeed(self._vouch(found, agreement, disp.shape[1]))
        if found is not None and overlap:
            if not agreement(found) >= self.cfg.still_there:
                return old  # its two views disagree there: a spoilt map (flicker), not it
            return self.update_found(found)
        # gone means seen through: most of the object's area now shows what lies behind it; a
        # region hidden by something nearer (or masked as the robot) is not gone
        behind = int(np.count_nonzero(there < behind_px(old.disparity)))
        if behind >= old.area // 2 and not agreement(old) >= self.cfg.still_there:
            moved = self._moved_back(disp, agreement)
            if moved is not None:  # the target moved farther, where it was: follow it,
                if self.fresh is None:  # at its new depth (aged: once two readings agree)
                    self.history = [moved.disparity] * (self.cfg.history - 1)
                return self.update_found(moved)
            n = self._doubt[0] + 1 if self._doubt[1] == "vanished" else 1
            self._doubt = (n, "vanished")
            # the next object is looked for from the first doubt on
            vouched = self._vouch(found if not overlap else None, agreement, disp.shape[1])
            if n >= self.cfg.agree:
                self.gone = 1
                return self._succeed(vouched)
            return old
        if vouched is None:
            here = None if overlap else self._in_place(disp, agreement)
            if here is not None:  # something else is nearest (a flicker phantom, a nearer
                return self.update_found(here)  # object not yet vouched for): the target
                # measured in its own columns at its depth (seed 17 #699: 4 s of phantoms)
            return old  # hidden, a nearer object not yet vouched for, or nothing clear
        return self._retarget(vouched)

    def _in_place(self, disp: np.ndarray, agreement: Callable[[Target], float]
                  ) -> Target | None:
        """The target where it was while something else is nearest (its map spoilt elsewhere
        by flicker, a nearer object not yet vouched for): the nearest object in its columns
        among the disparities from what counts as behind it (update's "gone") to same_depth
        nearer, agreeing in both views; None if there is none (a target moved farther waits
        for the whole map)."""
        old = self.target
        lo = behind_px(old.disparity)  # farther: what lay behind it (a
        hi = old.disparity * (1 + self.cfg.same_depth)  # wall seen through its columns)
        try:
            here = nearest_object(self._in_columns(disp, (disp >= lo) & (disp <= hi)),
                                  self.min_area, near=old.disparity)
        except HostError:
            return None
        if not (lo <= here.disparity <= hi and agreement(here) >= self.cfg.still_there):
            return None
        # its depth only: the band of columns cuts its region, its extent stays as it was
        return Target(here.disparity, old.area, old.bbox, here.spread)

    def _in_columns(self, disp: np.ndarray, keep: np.ndarray) -> np.ndarray:
        """The map within the target's columns where keep holds, NaN elsewhere."""
        bx, _, bw, _ = self.target.bbox
        cols = np.full_like(disp, np.nan)
        cols[:, bx:bx + bw] = np.where(keep[:, bx:bx + bw], disp[:, bx:bx + bw], np.nan)
        return cols

    def update_found(self, found: Target) -> Target:
        """The target found again (moved or not): its disparity the median of the last
        `history` measures; an aged depth, confirmed or replaced first (_confirm)."""
        self._doubt = (0, "")
        self.successor.reset()
        if self.fresh is not None:
            return self._confirm(found)
        self.measured = True
        self.history.append(found.disparity)
        del self.history[:-self.cfg.history]
        median = float(np.median(self.history))
        self.target = Target(median, found.area, found.bbox, found.spread)
        return self.target

    def _confirm(self, found: Target) -> Target:
        """A reading of an aged target: agreeing with its depth, it confirms it (and joins the
        median); else it waits for the next, and two agreeing with each other are the target
        moved: their mean at once. One reading alone moves nothing (a phantom, a spoilt map)."""
        assert self.fresh is not None
        d, held = found.disparity, self.target.disparity
        tol = self.cfg.fresh_agree * held
        if abs(d - held) <= tol:
            self.fresh = None
            return self.update_found(found)
        self.fresh.append(d)
        if len(self.fresh) < 2 or abs(self.fresh[-1] - self.fresh[-2]) > tol:
            return self.target
        self.history = self.fresh[-2:]
        self.fresh = None
        self.measured = True
        self.target = Target(float(np.mean(self.history)), found.area, found.bbox, found.spread)
        return self.target

    def _moved_back(self, disp: np.ndarray, agreement: Callable[[Target], float]
                    ) -> Target | None:
        """The target moved farther (toward a robot behind it, say) and still stands in its
        columns: the nearest object within them among the disparities that count as behind it
        (update's "gone") down to same_depth farther, agreeing in both views; None if there is
        none. Something nearer elsewhere (another robot beside the lane) must not become the
        target's successor while the target is still there, and a phantom nearer in its
        columns hides nothing (seed 17 #555: flicker blobs at 21 px over a box gone from 19.2
        to 16.2 px). Filling its columns edge to edge it is the wall seen through them, or the
        target grown past its old columns (cut by the picture's edge, its inner edge moved
        toward the centre: seed 17 #873): it is taken at its whole extent on the map, where
        that overlaps its columns and is no wider than an object."""
        old = self.target
        bx, _, bw, _ = old.bbox
        lo, hi = old.disparity * (1 - self.cfg.same_depth), behind_px(old.disparity)
        behind = (disp >= lo) & (disp <= hi)
        try:  # something real at its depth or nearer in its columns (the target's own rest
            # beside a walker read as 0 px, its views agreeing; a phantom's do not): it is no
            # move (review11: the wall above that rest, 16 px, became the target)
            if agreement(nearest_object(self._in_columns(disp, disp > hi), self.min_area,
                                        near=old.disparity)) >= self.cfg.still_there:
                return None
        except HostError:
            pass
        band = np.where(behind, disp, np.nan)
        try:
            here = nearest_object(self._in_columns(disp, behind), self.min_area,
                                  near=old.disparity)
            x0, x1 = here.bbox[0], here.bbox[0] + here.bbox[2]
            if not (x0 > bx or x1 < bx + bw):  # no edge of its own within its columns
                here = nearest_object(band, self.min_area, near=here.disparity)
                x0, x1 = here.bbox[0], here.bbox[0] + here.bbox[2]
                if here.bbox[2] > self.cfg.object_width * disp.shape[1] \
                        or span_overlap(bx, bx + bw, x0, x1) <= self.cfg.overlap:
                    return None  # the wall behind, or another object elsewhere
        except HostError:
            return None
        if not lo <= here.disparity < old.disparity:
            return None
        return here if agreement(here) >= self.cfg.still_there else None

    def _vouch(self, found: Target | None, agreement: Callable[[Target], float],
               width: int) -> Target | None:
        """Feed the successor's consistency check: an object (not the wall behind: narrower
        than object_width of the image) that agrees in both views."""
        if found is not None and found.bbox[2] > self.cfg.object_width * width:
            found = None
        return self.successor.update(found, agreement(found) if found else float("nan"))

    def _succeed(self, vouched: Target | None) -> Target:
        """The target is gone: the next nearest object (vouched: as _vouch returned it)
        becomes it; none after successor_tries more re-measures: the run ends (VANISHED)."""
        if vouched is None:
            self.gone += 1
            if self.gone > self.cfg.successor_tries:
                self.stop_reason = VANISHED
            return self.target
        self.gone = 0
        self.successor.reset()
        return self._retarget(vouched)

    def _retarget(self, new: Target) -> Target:
        """new becomes the target: no doubt left, the nearer-object check started again, its
        history its own disparity alone, measured now (not aged)."""
        self._doubt = (0, "")
        self.nearer.reset()
        self.target = new
        self.history = [new.disparity] * (self.cfg.history - 1)
        self.retargeted = self.measured = True
        self.fresh = None
        return new


def with_target(reference: np.ndarray, target: Target, extent_m: tuple[float, float],
                baseline_m: float, cx: float, margin_px: float = 5.0) -> np.ndarray:
    """The reference map (px) with the target where it stands now: the lane's reference
    after the target moved. A box pushed farther shows its edge in columns where the reference
    saw the wall behind it, and the lane (perception.lane_obstacle: nearer than the reference
    is new) took its own corner for a new object in the lane (seed 12's trial 482). The
    target's face, at its disparity now, across its rows (target: object_extent's region) and
    the columns within extent_m (the object's lateral extent, m, as the reference measured it;
    margin_px more either side at the target's disparity: the matcher's fattening at an edge),
    raises the reference to that disparity: there the target's face is no new object, seen or
    hidden by the robot when the target was measured. What stands nearer than the face, or
    beside it, stays new. Returns a new map."""
    d = target.disparity
    _, y, _, bh = target.bbox
    out = reference.copy()
    lateral = baseline_m * (np.arange(reference.shape[1]) - cx) / d
    margin = margin_px * baseline_m / d
    cols = (lateral >= extent_m[0] - margin) & (lateral <= extent_m[1] + margin)
    out[y:y + bh, cols] = np.fmax(out[y:y + bh, cols], d)
    return out


def with_replaced(fixed: np.ndarray, disp: np.ndarray, replaced: Target, geometry: Geometry, *,
                  camera_height_m: float, cell_m: float) -> np.ndarray:
    """The fixed objects' cells (fixed_cells) with those of a target a nearer object replaced
    while it still stands (disp: the re-measure's map, floor and robot left out; replaced: the
    target as last found, at its disparity then): its face, within its region and max(1, 6 %)
    of its disparity, is a fixed object from now on. After a retarget the keep-out is the new
    object's extent alone and the lane's reference has the old target where it was last
    found (not new), so nothing else kept the robot out of it (seed 14's trial 446 with a
    sooner acquisition: the box moved to 1.686 m, a look-alike at 1.66 m, x +0.28, became the
    target, and the robot drove into the box's face; issue 23). A target gone (seen through)
    leaves no face there and adds nothing."""
    bx, by, bw, bh = replaced.bbox
    d = replaced.disparity
    region = np.full(disp.shape, np.nan)
    there = disp[by:by + bh, bx:bx + bw]
    with np.errstate(invalid="ignore"):
        region[by:by + bh, bx:bx + bw] = np.where(
            np.abs(there - d) <= max(1.0, 0.06 * d), there, np.nan)
    cells = fixed_cells(region, geometry, camera_height_m=camera_height_m, cell_m=cell_m)
    return np.concatenate([fixed.reshape(-1, 2), cells]) if len(cells) else fixed
