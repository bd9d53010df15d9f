"""The depth-equalising control law, in metres: a pure state machine, one call per frame.

Error e = robot depth - target depth (m, from the calibrated geometry Z = f B / d). e < 0: the
robot is nearer than the object and must move away from the camera; e > 0: it must come back.
The robot starts facing away from the camera. Moving the way it faces, it drives forward;
otherwise it turns round in place (mode "turn", as in the paper) or reverses ("reverse").

Depth and its rate come from a straight-line fit over the last fit_frames observations (noise
averaged, speed measured). Speed: duty = floor + gain(z) |e| up to max_duty, gain scheduled with
depth (gain_per_m * ref_depth_m / z: depth noise grows as z^2, so far away the law is gentler).
The floor starts at min_duty and rises by creep_step whenever the robot is commanded but does
not move (stiction, a weak motor, a sagging battery). Near the target the robot creeps, and it
stops when the error predicted stop_lead_s ahead (measured speed times the stopping lag) reaches
zero, from either side: the hold is centred on zero error, not on the edge of a band. It holds
while the fitted error stays within tolerance_m and moves again beyond it.

Turn: spin until the marker, lost edge-on, is seen again; the card's apparent aspect (width /
height = |cos| of its angle) when it was lost and when it returned, and the time between, give
the turn rate actually achieved; the spin goes on for the remaining angle at that rate (an
absence shorter than min_gap_s is a missed detection, not the card's back, and is forgotten).
Then re-acquisition: driving waits for the marker; if the card is not seen after the turn (it
never came back, or the turn ended with it edge-on), the robot spins slowly on to find it.
Where a turn in place would sweep the body into the object (beside it, near its depth), the
robot does not turn (nor stop): it drives that leg in reverse along its line, as mode
"reverse" does, with every check of a drive. So it does, too, within block_m of the object's
depth (a short leg: a spin there loses the card for seconds beside the object, where a push
closes unseen), where the turn's circle clears another fixed object by less than
turn_slack_m beyond the servo's check (the body wanders in a spin), and where the drive after
the turn, its way not yet shown by its travel, would be refused by a fixed object within
turn_room_m along the way the robot faces now (the back wall behind a robot at 3 m): turn_tight.
Lateral: the marker's position x = B (u - cx) / d is held on a lane: where it was first seen,
unless that line passes the object (keep_out, the object's lateral extent at its depth, from the
servo) closer than clearance_m, centre to side; then the lane moves to the nearer clear side.
The drift from the lane and its rate steer the robot (PD, at most half the duty; not while
creeping, where the drift rate is mostly a sideways push rather than heading; while the robot
closes on its lane the drift's pull fades as the card's aspect shows it turned toward
square_deg, so a steep heading is turned back before the card leaves view), and a trim learnt
from the drift while driving (an integral, as a fraction of the duty) cancels the wheels'
unequal gains; no wheel is commanded below the least duty that moves it. When the
robot comes within block_m of the object's depth while its body still overlaps the object, it
stops: "the robot's line passes through the object". A robot pushed sideways onto the object
while it holds stops the run the same way (it cannot move sideways standing still).

Safety: an invalid observation (no marker, stale or skewed frame) stops the robot at once;
after lost_frames of them the phase is "lost" (stopped) until the marker returns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from host.servo.clearance import Body, in_the_way, lifted, own_body, run_fault
from host.servo.phase import Phase
from host.servo.robot_model import MAX_SPEED_MPS, REACT_S, WHEELBASE_M

LINE_BLOCKED = "the robot's line passes through the object"
PUSHED = "pushed sideways onto the object while holding"
DRIFTED = "drifting sideways onto the object while the marker is unseen"
TURN_BLOCKED = "turning here would sweep the robot's body into the object"
INTO_FIXED = "the robot's {} would run into a fixed object that is not the target"


def lane_pd(way: float, drift_m: float, xdot_mps: float, gain: float, damping: float,
            share: float = 1.0) -> float:
    """The lane law's steer (permille taken from the left wheel and given to the right): a PD
    on the body's offset from its lane (drift_m; gain permille a cm, share of that pull) and
    its sideways rate (xdot_mps; damping permille per cm/s), for a robot moving in depth the
    way way says (+1 away from the camera, -1 toward it)."""
    return way * (share * gain * 100 * drift_m + damping * 100 * xdot_mps) / 2


@dataclass(frozen=True)
class ControlConfig:
    tolerance_m: float = 0.01
    gain_per_m: float = 1500.0  # permille per m of error at ref_depth_m
    ref_depth_m: float = 1.0
    min_duty: int = 180
    max_duty: int = 600
    creep_m: float = 0.04  # within this error: the least duty that moves the robot
    creep_step: int = 15  # permille added to the floor per still frame while creeping
    stop_lead_s: float = 0.15  # stopping lag: actuation latency plus the wheels' run-down
    fit_frames: int = 6
    steer_gain: float = 25.0  # permille per cm of sideways drift
    steer_damping: float = 60.0  # permille per cm/s of sideways drift rate
    square_deg: float = 25.0  # the card's turn from square (its aspect) at which the lane's
    # pull is gone while the robot closes on its lane: the pull asks for a sideways rate, which
    # at a slow speed is a steep heading, and a far card turned past ~40 degrees is lost
    trim_gain: float = 0.004  # learnt wheel trim, fraction of duty per cm of drift per second
    max_trim: float = 0.25
    half_width_m: float = 0.08  # the robot's body, centre to side (square to the camera axis)
    # the body's reach across x turned (reach_m): the median of the last reach_frames
    # sightings' turn bounds (the card's turn from its line of sight, acos of its aspect, and
    # that line's bearing from the axis): the card's aspect is noisy near square (0.98 reads
    # 11.5 degrees), one sighting alone is not taken
    reach_frames: int = 10
    clearance_m: float = 0.15  # the lane's distance from the object's side: half the body,
    # and room for the lateral hold error and a sideways drift while holding
    block_m: float = 0.15  # within this depth of the object, the body must be clear of it
    block_margin_m: float = 0.02  # by this much (the object's edge is measured to a pixel or two)
    turn_radius_m: float = 0.115  # a turn in place sweeps this circle: half the body's diagonal
    # a turn round takes seconds and the body wanders in it (unequal wheels, a sideways push:
    # 2.2 cm in seed 14 trial 55's 2.4 s spin, the servo's check of its frames then ended the
    # run): it is started only with this much more room than that check asks, else the leg is
    # reversed (the drive's checks on every frame)
    turn_slack_m: float = 0.03
    # nor is it started where the drive after it, its way not yet shown by its travel, would
    # be refused: the servo checks that drive the other way too (the way the robot faces now)
    # within its stopping distance and the travel that shows the way, three of a sighting's
    # depth noise (loop.py _fixed_fault: seed 17 #105 and dev seed 1 #0 turned round 25 cm
    # from the back wall at 2.9 m, the card's half turn not witnessed, and the drive toward
    # the camera was refused 0.08-0.16 m on "if it faces the other way"): the leg is reversed
    turn_room_m: float = 0.20
    half_length_m: float = 0.08  # centre to front (and back): a run sweeps this rectangle
    # (clearance.swept), turned by the heading, grown by block_margin_m and half a cell
    path_margin_m: float = 0.10  # fixed objects this far beyond the target's depth are in its path
    # the lane keeps this much more from another fixed object's cells than from the object: the
    # servo's check sweeps the body on the learnt heading within its spread (up to 15 degrees:
    # the front corner and 10 cm of run 3-4 cm across), and at 15 cm centre to side by box 2's
    # end the spread's edge met its cells (seed 15: 6 of the 14 traced drive stops, the robot
    # within 3 cm of its lane); taken only where it leaves the lane on the same side (lane)
    spread_room_m: float = 0.03
    cell_m: float = 0.02  # the fixed objects' floor cells (perception.fixed_cells)
    # the target's own fixed cells (others leaves them out) are those across its keep-out from
    # the camera to this far behind its face, not at any depth: its face's cells spread a cell
    # or two about it (1.19-1.21 m for seed 3's face at 1.20 m), a face at 3 m reads about 9
    # cm off at 0.25 px, and its depth is re-measured while its cells are the reference's (a
    # push moves it by cm). Cells farther behind in its band are another thing's: the back
    # wall at 3.2 m behind the target was no obstacle to a robot standing by it in the band,
    # probing or backing away from the camera (issue 23)
    own_depth_m: float = 0.15
    push_horizon_s: float = 3.0  # standing, a sideways drift that would bring the body onto
    # the object within this long ends the run (it cannot move sideways in place)
    drift_s: float = 3.0  # the sideways drift beside the object is fitted over this long
    # the lane back beside the object after a push (Controller.pushed_mps, measured in this
    # run) is planned push_room_m wider on the side it pushes toward: held there, the push
    # check fires that much later (seed 18 #157, #211, #295 at a199819: pushed at 0.75-0.94
    # cm/s, backed off, came back to a lane no wider and were pushed again on arriving, then
    # too late for a back-off). A bounded room, not the fitted rate over push_horizon_s: #295's
    # fit read 0.39 cm/s of a true 0.75 (1.2 cm of room: pushed again on arriving), and the
    # creep in (unsteered, 3 s) drifts with the push before the hold begins
    push_room_m: float = 0.03
    unseen_horizon_s: float = 6.0  # the same with the card unseen: the last position moved on
    # by the last rate is a guess (the card's offset from the body, a rate from few sightings)
    mode: str = "turn"  # or "reverse"
    turn_duty: int = 400
    turn_timeout_s: float = 8.0
    min_gap_s: float = 0.3  # the card is edge-on at least this long in a turn (a flicker is not)
    search_duty: int = 300  # spin to find the marker again when it is lost after a turn
    search_s: float = 8.0
    steady_frames: int = 10  # the card seen this many frames running after a turn: found (a
    # glimpse of it, the turn ended short, does not end the search)
    lost_frames: int = 3
    # a turn that ended on the card's sweep is half a turn only when one edge-on pass accounts
    # for the card's absence: the rate over the gap at least this share of the rate from the
    # turn's start to the card's loss (that one over at least half_min_deg; _one_pass)
    half_share: float = 0.6
    half_min_deg: float = 10.0
    # near another fixed object's end the drive slows to slow_duty, so that the servo's check
    # (the body swept over the stopping distance at the command's speed) looks only a short
    # way on and the robot creeps by, re-checked every frame, instead of stopping on a swept
    # region its heading's spread widens (_near_end; seed 13, box 2's end: issue 23). Near: the
    # body, on the facing within slow_spread and the duties' arc, meets a cell within the
    # check's travel at this duty plus the way the measured speed takes to fall (slow_lag_s)
    slow_duty: int = 220
    slow_spread_deg: float = 15.0
    slow_lag_s: float = 0.6
    # the servo's check as the servo runs it (the Servo sets these from its own configs:
    # ServoConfig.react_s and wheelbase_m, EstimatorConfig.max_speed_mps)
    check_react_s: float = REACT_S
    max_speed_mps: float = MAX_SPEED_MPS
    wheelbase_m: float = WHEELBASE_M


@dataclass(frozen=True)
class Observation:
    """What perception made of one frame: the marker's depth (m) and sideways position (m), its
    aspect (width / height), at the frame's capture time; depth None = no valid marker."""

    t: float  # s, capture time
    depth_m: float | None
    lateral_m: float | None = None
    aspect: float = 1.0
    invalid: str = ""  # why the frame is not usable ("stale", "skew"), "" if it is


@dataclass(frozen=True)
class Command:
    left: int
    right: int
    phase: Phase
    error_m: float | None

    @property
    def is_stop(self) -> bool:
        return self.left == 0 and self.right == 0


class Controller:
    def __init__(self, target_m: float, config: ControlConfig = ControlConfig()) -> None:
        if config.mode not in ("turn", "reverse"):
            raise ValueError(f"mode must be turn or reverse, got {config.mode!r}")
        self.target_m = target_m
        self.cfg = config
        self.facing_away = True
        self.phase = Phase.WAIT
        self.seen = False
        self.missing = 0
        self.floor = config.min_duty
        self.lateral_ref: float | None = None  # the lane the robot holds (m)
        self.keep_out: tuple[float, float] | None = None  # the object's lateral extent (m)
        # the depths (m) of the re-measure's readings the target's median is made of: a move
        # shows in one reading before the median follows it (seed 16 #507), so a turn's circle
        # clears the object at each of them (sweeps)
        self.readings_m: tuple[float, ...] = ()
        # the floor cells (depth, lateral; m) of the scene's fixed objects (perception.
        # fixed_cells): the lane keeps clear of those between the robot and the target, and a
        # turn in place of all of them
        self.fixed: np.ndarray = np.zeros((0, 2))
        # cells never taken for the target's own, wherever the keep-out lies: the face of a
        # target a nearer object replaced while it still stands (tracker.with_replaced)
        self.kept: np.ndarray = np.zeros((0, 2))
        # where the robot stood when the reference was taken (its own body is in it), once known
        self.home: tuple[float, float] | None = None
        self._beside: list[tuple[float, float]] = []  # (t, lateral) seen near the target depth
        self.trim = 0.0  # fraction of duty added to the right wheel, taken from the left
        self.fault = ""  # why the robot must stay stopped (the run ends), "" if none
        self._last_t: float | None = None
        self.history: list[Observation] = []  # valid observations since the last turn
        # the recent sightings' bounds on the body's turn off the camera axis (rad; saw)
        self.turns: list[float] = []
        # the sideways push (m/s, +x) that ended a hold in this run (_pushed), 0 without one:
        # a back-off's re-acquire carries it to the controller it makes anew (loop.Servo.
        # _reacquire), whose lane back is planned wider on its side (push_room)
        self.pushed_mps = 0.0
        self._turn: dict[str, Any] | None = None
        self._search_until: float | None = None
        self._seen_run = 0  # frames the card has been seen running
        self._reversing = False  # this leg is reversed: a turn would sweep into the object
        # this frame a turn round ended, witnessed half a turn (the card's sweep, at a rate one
        # edge-on pass accounts for): when its spin was commanded (s); else None
        self.turned_half: float | None = None

    # ---------------------------------------------------------------------- estimates

    def fit(self) -> tuple[float, float, float] | None:
        """(depth now, depth rate m/s, lateral rate m/s) from the recent valid observations."""
        h = self.history[-self.cfg.fit_frames:]
        h = [o for o in h if h[-1].t - o.t <= 0.5]
        if not h:
            return None
        if len(h) < 3:
            return h[-1].depth_m or 0.0, 0.0, 0.0
        t = np.array([o.t for o in h]) - h[-1].t
        z = np.array([o.depth_m for o in h])
        zs, z0 = np.polyfit(t, z, 1)
        xs = 0.0
        lat = [o.lateral_m for o in h]
        if all(x is not None for x in lat):
            xs = float(np.polyfit(t, np.array(lat, float), 1)[0])
        return float(z0), float(zs), xs

    def _stop(self, phase: Phase, error: float | None) -> Command:
        self.phase = phase
        return Command(0, 0, phase, error)

    # ------------------------------------------------------------------------- update

    def others(self) -> np.ndarray:
        """The fixed objects' cells but for the target's own: across its extent (the
        keep-out), nearer the camera than own_depth_m behind its face. Farther behind, in its
        band, they are another thing's (the back wall) and stay; the kept cells (a replaced
        target's face) stay wherever they are: the new target may stand in front of it."""
        cells = self.fixed
        if len(cells) and self.keep_out is not None:
            cells = cells[~self._own_mask(cells)]
        return np.concatenate([cells.reshape(-1, 2), self.kept]) if len(self.kept) else cells

    def _own_mask(self, cells: np.ndarray) -> np.ndarray:
        """Which cells are the target's own (keep_out set): across its extent, nearer than
        own_depth_m behind its face."""
        assert self.keep_out is not None
        x0, x1 = self.keep_out
        c = self.cfg.cell_m
        own: np.ndarray = ((cells[:, 1] > x0 - c) & (cells[:, 1] < x1 + c)
                           & (cells[:, 0] < self.target_m + self.cfg.own_depth_m))
        return own

    def own(self) -> np.ndarray:
        """The target's own fixed cells, which others() leaves out (the robot holds beside its
        face): _own_mask's."""
        cells = self.fixed
        if not len(cells) or self.keep_out is None:
            return cells[:0].reshape(-1, 2)
        own: np.ndarray = cells[self._own_mask(cells)].reshape(-1, 2)
        return own

    def swept_body(self) -> Body:
        """The body as the fixed-object checks sweep it: grown by block_margin_m and half a
        cell (the cells are where the reference put them)."""
        cfg = self.cfg
        return Body(cfg.half_width_m, cfg.half_length_m, cfg.block_margin_m + cfg.cell_m / 2)

    def turn_bound(self) -> float:
        """The body's turn off the camera axis (rad), either way, as the recent sightings
        bound it (the median of saw's bounds; 0 with none): what reach_m turns the body by."""
        return float(np.median(self.turns)) if self.turns else 0.0

    def ahead(self, depth_m: float) -> np.ndarray:
        """The other fixed objects' cells in the robot's path from depth_m to the target (to
        path_margin_m beyond it)."""
        cells, cfg = self.others(), self.cfg
        if depth_m > self.target_m:
            lo, hi = self.target_m - cfg.path_margin_m, depth_m
        else:
            lo, hi = depth_m, self.target_m + cfg.path_margin_m
        return cells[(cells[:, 0] >= lo) & (cells[:, 0] <= hi)]

    def lane(self, depth_m: float | None = None) -> float | None:
        """The lateral position to hold: the first seen, moved clear of the object (and, given
        the robot's depth, of the fixed objects between it and the target) by clearance_m,
        centre to side, to the nearer side."""
        x = self.lateral_ref
        if x is None:
            return x
        base = self._planned(x, depth_m, 0.0)
        push = self.push_room()
        if push <= 0 or self.keep_out is None:
            return base
        # a push measured in this run (pushed_mps): its side of the object kept push_room
        # farther, where that lane is the one moved away from the object by at most that room
        # and no nearer another fixed object ahead than before (or than the lane keeps them)
        far = self._planned(x, depth_m, push)
        x0, x1 = self.keep_out
        away = far - base if base >= x1 else base - far if base <= x0 else -1.0
        if not 0.0 <= away <= push + 1e-9:
            return base
        if depth_m is not None:
            u = self.ahead(depth_m)[:, 1]
            keep = self.cfg.clearance_m + self.cfg.spread_room_m + self.cfg.cell_m / 2
            if len(u) and np.min(np.abs(u - far)) < min(np.min(np.abs(u - base)), keep):
                return base
        return far

    def _planned(self, x: float, depth_m: float | None, push: float) -> float:
        """The lane (lane) with push more room from the side pushed_mps pushes toward."""
        plain = self._lane(x, depth_m, 0.0, push)
        room = self.cfg.spread_room_m
        if depth_m is None or room <= 0:
            return plain
        # with spread_room_m more from the other fixed objects, where that lane is the same
        # one moved by at most that room (a gap it closes, or a side it changes, is not taken)
        wide = self._lane(x, depth_m, room, push)
        return wide if abs(wide - plain) <= room + 1e-9 else plain

    def push_room(self) -> float:
        """The room (m) the lane keeps beyond clearance_m from the side a push measured in
        this run (pushed_mps) comes toward: push_room_m, or none without one."""
        return self.cfg.push_room_m if self.pushed_mps else 0.0

    def _lane(self, x: float, depth_m: float | None, room: float, push: float = 0.0) -> float:
        """The lane from the first seen lateral x: clear of the object by clearance_m (and
        push more on the side pushed_mps pushes toward) and of the other fixed objects ahead
        (given depth_m) by clearance_m + room, centre to side."""
        c = self.cfg.clearance_m
        v = self.pushed_mps
        spans = [] if self.keep_out is None else [
            (self.keep_out[0] - c - (push if v > 0 else 0.0),
             self.keep_out[1] + c + (push if v < 0 else 0.0))]
        if depth_m is not None:
            r = c + room + self.cfg.cell_m / 2
            spans += [(float(u) - r, float(u) + r) for u in self.ahead(depth_m)[:, 1]]
        for lo, hi in merged(spans):
            if lo < x < hi:
                return lo if x - lo < hi - x else hi
        return x

    def obstacles(self, depth_m: float, lateral_m: float) -> np.ndarray:
        """The other fixed objects' cells (others) but for a body standing where the robot is
        seen (a look-alike that stood in the reference, while the probe tests it) and where it
        stood for the reference (home): clearance.own_body."""
        cells, cfg = self.others(), self.cfg
        own_m = cfg.turn_radius_m + cfg.cell_m
        for z, x in [(depth_m, lateral_m)] + ([self.home] if self.home else []):
            cells = cells[~own_body(cells, z, x, own_m, cfg.half_width_m / 2, 2 * cfg.cell_m)]
        return cells

    def sweeps(self, depth_m: float, lateral_m: float | None, aged: bool = False,
               slack_m: float = 0.0) -> bool:
        """Whether a turn in place here sweeps the body (a circle of turn_radius_m) within
        block_margin_m of the object's extent or of any other fixed object's cell, behind the
        robot as well as ahead (a turn sweeps the whole circle: a box a few cm farther than the
        robot's centre is as near as one in its path), but not a body standing there
        (obstacles: the sighting is then of a look-alike). aged: the object's depth is too old
        to trust (not measured again through a search; it may have moved beside the robot
        unseen, seed 13's trial 742): its extent across is swept at any depth. The object's
        extent is swept at its depth and at each reading's (readings_m: moved, it may stand
        where one reading put it). slack_m: room asked beyond that (a turn's wander,
        turn_tight)."""
        if lateral_m is None:
            return False
        cfg = self.cfg
        reach = cfg.turn_radius_m + cfg.block_margin_m + slack_m
        near = any(abs(depth_m - z) < reach for z in (self.target_m, *self.readings_m))
        if (aged or near) and self.overlaps(
                lateral_m, reach - cfg.turn_radius_m, cfg.turn_radius_m):
            return True
        return in_the_way(self.obstacles(depth_m, lateral_m), depth_m, lateral_m, None, 0.0,
                          reach + cfg.cell_m / 2) is not None

    def turn_tight(self, z: float, e: float, lateral: float | None) -> bool:
        """Whether a turn round here is refused for a reversed leg: within block_m of the
        object's depth (a short leg; a spin there loses the card for seconds beside the object
        while the servo guesses its drift, and a sideways push ended seed 14's trials 7 and
        235 in the spin: reversed, the card stays in view and the hold's own push check and
        back-off watch it), or its circle within turn_slack_m more than the check's reach of
        the object or another fixed object (sweeps)."""
        cfg = self.cfg
        return abs(e) < cfg.block_m or self.sweeps(z, lateral, slack_m=cfg.turn_slack_m) \
            or self._behind_turn(z, lateral)

    def _behind_turn(self, z: float, lateral: float | None) -> bool:
        """Whether a fixed object's cell lies where the drive after a turn round here would go
        if the turn had not turned the robot (its way unshown by the travel: the servo checks
        it the other way too): along the way the robot faces now, the body within turn_room_m
        (the drive's stopping distance and the travel that shows its way)."""
        if lateral is None:
            return False
        cfg = self.cfg
        cells = self.obstacles(z, lateral)
        if not len(cells):
            return False
        body = self.swept_body()
        heading = 0.0 if self.facing_away else math.pi
        return run_fault(cells, z, lateral, cfg.max_duty, cfg.max_duty, heading,
                         math.radians(cfg.slow_spread_deg), cfg.turn_room_m, body,
                         cfg.wheelbase_m) is not None

    def drift(self) -> tuple[float, float, float] | None:
        """(time, lateral, lateral rate) of the robot beside the object: a line through its
        sightings near the target's depth over the last drift_s (at least four over 1 s: a
        slow push shows over seconds, and a card seen now and then gives no rate over the
        controller's 0.5 s fit), or None."""
        h = self._beside
        if len(h) < 4 or h[-1][0] - h[0][0] < 1.0:
            return None
        t = np.array([o[0] for o in h]) - h[-1][0]
        x = np.array([o[1] for o in h])
        rate, x0 = np.polyfit(t, x, 1)
        return h[-1][0], float(x0), float(rate)

    def _pushed(self, t: float, seen: bool = True) -> bool:
        """Standing beside the object (holding, or the marker missing since): a sideways drift
        that brings the body within block_margin_m of it within push_horizon_s (or has
        already, where the marker was last seen and the drift has taken it since)."""
        fit = self.drift()
        if fit is None:
            return False
        t0, lateral, rate = fit
        if not self.closing(lateral + rate * (t - t0), rate, seen):
            return False
        if seen and abs(rate) > abs(self.pushed_mps):
            self.pushed_mps = rate  # the lane back is planned wider
        return True

    def closing(self, lateral: float, rate: float, seen: bool = True) -> bool:
        """Whether a body at this lateral position, drifting sideways at this rate (m/s), is
        within block_margin_m of the object's extent or comes so within push_horizon_s
        (unseen_horizon_s when the card is unseen)."""
        cfg = self.cfg
        if self.keep_out is None:
            return False
        if self.overlaps(lateral, cfg.block_margin_m):
            return True
        x0, x1 = self.keep_out
        reach = self.reach_m() + cfg.block_margin_m
        gap = lateral - reach - x1 if lateral > x1 else x0 - reach - lateral
        toward = -rate if lateral > x1 else rate
        horizon = cfg.push_horizon_s if seen else cfg.unseen_horizon_s
        return toward > 0 and gap < toward * horizon

    def overlaps(self, lateral: float | None, margin: float = 0.0,
                 across: float | None = None) -> bool:
        """Whether the robot's body at this lateral position comes within margin of the
        object's extent: the body's reach across x (reach_m: turned as the card shows it),
        or across, half an extent given (a turn's circle)."""
        if lateral is None or self.keep_out is None:
            return False
        x0, x1 = self.keep_out
        reach = (self.reach_m() if across is None else across) + margin
        return x0 - reach < lateral < x1 + reach

    def saw(self, depth_m: float | None, lateral_m: float | None, aspect: float) -> None:
        """A sighting (the marker's depth and lateral, m; the card's aspect) bounds the
        body's turn off the camera axis: the card's turn from its line of sight (aspect =
        its |cos|) and that line's bearing from the axis, either way. Kept for the last
        reach_frames sightings, through turns and back-offs (the loop tells a back-off's
        sightings, whose commands are not the controller's)."""
        if depth_m is None or depth_m <= 0:
            return
        bearing = abs(math.atan2(lateral_m or 0.0, depth_m))
        self.turns.append(math.acos(min(1.0, max(0.0, aspect))) + bearing)
        del self.turns[:-self.cfg.reach_frames]

    def reach_m(self) -> float:
        """Half the body's extent across x (m), the rectangle (half_width_m across,
        half_length_m along) turned by the median of the recent sightings' turn bounds
        (saw), never less than half its width (nothing seen: square). Every check of the
        body beside the object takes it (overlaps, closing, the back-off's gap): turned 29
        degrees past a turn round, seed 16 #470's body reached 10.8 cm across, not the 8 the
        checks took, and its edge walked into the side of the box it held beside (issue 23)."""
        cfg = self.cfg
        if not self.turns:
            return cfg.half_width_m
        # the most a rectangle reaches across is at its diagonal's angle: beyond that a
        # bound on the turn bounds the reach by the diagonal's
        # (a turn that has just come shows in the median of ten by its sixth sighting; the
        # median of the last three too, the larger, read the lane steer's passing turns and
        # blocked the closed-loop back-off's and the clearance's holds: session 10)
        a = min(float(np.median(self.turns)), math.atan2(cfg.half_length_m, cfg.half_width_m))
        return max(cfg.half_width_m,
                   cfg.half_width_m * math.cos(a) + cfg.half_length_m * math.sin(a))

    def update(self, obs: Observation) -> Command:
        self.turned_half = None
        if self.fault:
            return self._stop(Phase.BLOCKED, None)
        if self._turn is not None:
            return self._turning(obs)
        if obs.depth_m is None:
            self.missing += 1
            self._seen_run = 0
            standing = self.phase in (Phase.HOLD, Phase.WAIT, Phase.LOST)
            if standing and self._pushed(obs.t, seen=False):
                self.fault = PUSHED
                return self._stop(Phase.BLOCKED, None)
            if obs.invalid:
                return self._stop(Phase.STALE, None)
            if not self.seen:
                return self._stop(Phase.WAIT, None)
            # stopped at once; after lost_frames of them the marker is lost
            if self.missing <= self.cfg.lost_frames:
                return self._stop(Phase.WAIT, None)
            if self._search_until is not None and obs.t < self._search_until:
                self.phase = Phase.SEARCH  # turned, but the card is not back: spin on to find it
                d = self.cfg.search_duty
                return Command(d, -d, Phase.SEARCH, None)
            return self._stop(Phase.LOST, None)
        self.missing = 0
        self.seen = True
        self._seen_run += 1
        if self._seen_run >= self.cfg.steady_frames:
            self._search_until = None
        if self.lateral_ref is None:
            self.lateral_ref = obs.lateral_m
        self.history.append(obs)
        del self.history[:-30]
        self.saw(obs.depth_m, obs.lateral_m, obs.aspect)
        return self._drive(obs)

    def _drive(self, obs: Observation) -> Command:
        cfg = self.cfg
        z, zdot, xdot = self.fit() or (obs.depth_m or 0.0, 0.0, 0.0)
        e = z - self.target_m
        away = e < 0
        dt = obs.t - self._last_t if self._last_t is not None else 0.0
        self._last_t = obs.t
        if abs(e) < cfg.block_m and self.overlaps(obs.lateral_m, cfg.block_margin_m):
            self.fault = PUSHED if self.phase == Phase.HOLD else LINE_BLOCKED
            return self._stop(Phase.BLOCKED, e)
        if abs(e) < cfg.block_m and obs.lateral_m is not None:
            self._beside.append((obs.t, obs.lateral_m))
            self._beside = [o for o in self._beside if obs.t - o[0] <= cfg.drift_s]
        else:
            self._beside.clear()
        if self.phase == Phase.HOLD and self._pushed(obs.t):
            self.fault = PUSHED
            return self._stop(Phase.BLOCKED, e)
        if self.phase == Phase.HOLD and abs(e) <= cfg.tolerance_m:
            return self._stop(Phase.HOLD, e)
        moving_in = self.phase in (Phase.DRIVE, Phase.CREEP)
        predicted = e + zdot * cfg.stop_lead_s
        if moving_in and (predicted * e <= 0 or abs(predicted) < 0.1 * cfg.tolerance_m):
            return self._stop(Phase.HOLD, e)  # reached zero error (from either side): stop there
        if not moving_in and abs(e) <= 0.25 * cfg.tolerance_m:
            return self._stop(Phase.HOLD, e)
        if self.phase == Phase.CREEP and abs(e) <= cfg.tolerance_m and self._turned():
            # the creep, unsteered at the floor duty, turns the body with the wheels' unequal
            # offsets frame by frame: past square_deg the card is on its way edge-on (lost
            # near 40 degrees; dev seed 1 #2 lost it at 0.4 cm to go, spun to find it and the
            # unseen drift ended the run) and the body's reach grows; within tolerance it
            # holds here, the hold's checks on (issue 23)
            return self._stop(Phase.HOLD, e)
        forward = away == self.facing_away
        if forward:
            self._reversing = False
        elif cfg.mode == "turn" and not self._reversing:
            if not self.turn_tight(z, e, obs.lateral_m):
                return self._start_turn(obs, e)
            # a turn here would sweep the body into the object, or bring it there unseen: this
            # leg is driven in reverse instead, along the robot's line (the body checks as for
            # any drive, the card in view)
            self._reversing = True
        creeping = abs(e) <= cfg.creep_m
        if creeping and self.phase == Phase.CREEP and abs(zdot) < 0.004:
            self.floor = min(cfg.max_duty // 2 + 100, self.floor + cfg.creep_step)
        gain = cfg.gain_per_m * cfg.ref_depth_m / max(z, 0.3)
        duty = self.floor if creeping else min(cfg.max_duty, int(self.floor + gain * abs(e)))
        duty = duty if forward else -duty
        steer = 0.0
        lane = self.lane(z)
        if obs.lateral_m is not None and lane is not None:
            # x' = v sin(theta): to cancel a drift to the right, turn so that v cos(theta) * dtheta
            # is negative; v cos(theta) is positive exactly when moving away from the camera
            s = 1.0 if away else -1.0
            drift = obs.lateral_m - lane
            moving = abs(zdot) > 0.02  # the heading shows only in motion
            if moving and self.phase == Phase.DRIVE and 0 < dt < 0.5:
                # the wheel that lags stays the same one whichever way the robot faces
                w = s if forward else -s
                self.trim = max(-cfg.max_trim, min(cfg.max_trim, self.trim + w * cfg.trim_gain
                                                   * 100 * max(-0.05, min(0.05, drift)) * dt))
            # closing on its lane, the robot's heading already points there (the drift rate says
            # which way) and the card's aspect says how steeply: past half of square_deg the
            # lane's pull fades, gone at square_deg, so the damping alone turns the heading back
            # before the card is turned out of view (the drift rate lags the heading by the
            # fit's half second; the aspect is this frame's)
            off = math.degrees(math.acos(min(1.0, obs.aspect)))
            share = min(1.0, 2.0 - 2.0 * off / cfg.square_deg) if drift * xdot < 0 else 1.0
            pd = lane_pd(s, drift, xdot, cfg.steer_gain, cfg.steer_damping, max(0.0, share))
            # creeping (the last few cm) the drift rate is mostly a sideways push, not heading:
            # steering against it turns the robot off the card's visible range and, near the
            # dead zone, spins it in place; only the wheels' trim acts there
            steer = (0.0 if creeping else max(-abs(duty) / 2, min(abs(duty) / 2, pd)))
            steer += self.trim * duty
        self.phase = Phase.CREEP if creeping else Phase.DRIVE
        left, right = duty - steer, duty + steer
        if obs.lateral_m is not None and self._near_end(z, obs.lateral_m, left, right):
            left, right = self._by_the_end(z, obs.lateral_m, left, right)
        left, right = lifted(left, right, self.floor, duty)  # no wheel below the floor
        return Command(int(round(left)), int(round(right)), self.phase, e)

    def _turned(self) -> bool:
        """Whether the card shows the body turned from its line of sight by square_deg or
        more: the median of the last three sightings' aspects (one is noisy near square)."""
        a = [o.aspect for o in self.history[-3:]]
        if len(a) < 3:
            return False
        return math.degrees(math.acos(min(1.0, float(np.median(a))))) >= self.cfg.square_deg

    def _by_the_end(self, z: float, x: float, left: float, right: float
                    ) -> tuple[float, float]:
        """Near another fixed object's end (_near_end): the duties at most slow_duty, on the
        arc the controller asked for if that one stays clear within the slowed run's travel,
        else straight, else bent away by a quarter or a half of the duty (the first clear of
        these, or the one that meets a cell farthest on): the servo's check sweeps the arc
        commanded, and a steer back onto the lane bends it onto the end."""
        cfg = self.cfg
        duty = (left + right) / 2
        if duty == 0:
            return left, right
        k = min(1.0, cfg.slow_duty / abs(duty))
        d, steer = duty * k, (right - left) / 2 * k
        best: tuple[float, float] | None = None
        far = -1.0
        for st in (steer, 0.0, abs(d) / 4, -abs(d) / 4, abs(d) / 2, -abs(d) / 2):
            lo, hi = lifted(d - st, d + st, self.floor, d)
            hit = self._end_hit(z, x, lo, hi)
            if hit is None:
                return lo, hi
            if hit > far:
                best, far = (lo, hi), hit
        assert best is not None
        return best

    def _end_hit(self, z: float, x: float, left: float, right: float) -> float | None:
        """Where (m on) a run under these duties from (z, x) brings the body (as the servo's
        check sweeps it: clearance.run_fault, grown by block_margin_m and half a cell) onto
        another fixed object's cell within the check's travel at this duty and slow_lag_s
        more, the robot on its facing within slow_spread_deg, or None."""
        cfg = self.cfg
        cells = self.obstacles(z, x)
        if not len(cells) or left + right == 0:
            return None
        speed = cfg.max_speed_mps * abs(left + right) / 2000
        travel = cfg.block_margin_m + speed * (cfg.check_react_s + cfg.slow_lag_s)
        body = self.swept_body()
        heading = 0.0 if self.facing_away else math.pi
        return run_fault(cells, z, x, int(left), int(right), heading,
                         math.radians(cfg.slow_spread_deg), travel, body, cfg.wheelbase_m)

    def _near_end(self, z: float, x: float, left: float, right: float) -> bool:
        """Whether the run these duties ask for meets another fixed object's cell within the
        check's travel and slow_lag_s more (_end_hit): the drive slows and keeps clear
        (_by_the_end; a heuristic that only lowers the duty and picks the arc: the servo's
        check still stops any run that would hit)."""
        return self._end_hit(z, x, left, right) is not None

    # --------------------------------------------------------------------------- turn

    def _start_turn(self, obs: Observation, e: float) -> Command:
        self._seen_run = 0  # the card seen after the turn counts afresh
        self._turn = {"t0": obs.t, "lost_t": None, "lost_aspect": 1.0, "end": None,
                      "last_seen": (obs.t, obs.aspect), "seen": [(obs.t, obs.aspect)],
                      "half": False}
        return self._spin(e)

    def _spin(self, e: float | None) -> Command:
        self.phase = Phase.TURN
        d = self.cfg.turn_duty
        return Command(d, -d, Phase.TURN, e)

    def _turning(self, obs: Observation) -> Command:
        """Spin until the card, lost edge-on, comes back and has turned the remaining angle."""
        turn, cfg = self._turn, self.cfg
        assert turn is not None
        seen = obs.depth_m is not None
        if turn["end"] is not None:
            if obs.t < turn["end"]:
                return self._spin(None)
            return self._end_turn(obs.t)
        if obs.t - turn["t0"] > self.cfg.turn_timeout_s:
            return self._end_turn(obs.t)  # the card never came back: look for it
        if seen and turn["lost_t"] is None:
            turn["last_seen"] = (obs.t, obs.aspect)
            turn["seen"].append((obs.t, obs.aspect))
        elif not seen and turn["lost_t"] is None and not obs.invalid:
            turn["lost_t"], turn["lost_aspect"] = turn["last_seen"]
        elif seen and turn["lost_t"] is not None and obs.t - turn["lost_t"] < cfg.min_gap_s:
            # back within min_gap_s: a missed detection, not the card's back; forget the loss,
            # or a later sighting (min_gap_s after it) would end the turn there
            turn["lost_t"], turn["last_seen"] = None, (obs.t, obs.aspect)
            turn["seen"].append((obs.t, obs.aspect))
        elif seen and turn["lost_t"] is not None:
            a_lost = min(1.0, turn["lost_aspect"])
            a_now = min(1.0, obs.aspect)
            swept = math.pi - math.acos(a_lost) - math.acos(a_now)
            rate = swept / max(obs.t - turn["lost_t"], 1e-3)
            remaining = math.acos(a_now) / rate - self.cfg.stop_lead_s
            turn["end"] = obs.t + max(0.0, remaining)
            turn["half"] = self._one_pass(turn, rate)
            if remaining <= 0:
                return self._end_turn(obs.t)
        return self._spin(None)

    def _one_pass(self, turn: dict[str, Any], rate: float) -> bool:
        """Whether one edge-on pass accounts for the card's absence in this turn: the card is
        two-sided, so the same sweep ends half a turn and, had the card been missed (hidden,
        frames lost) through its square view between two passes, a turn and a half: the
        rate over the gap is then about a third of the spin's. It must reach half_share of
        the rate from the turn's start to the loss (the card's angle at the start the median
        of its first three aspects: far away one reads square amid 20-25 degree ones), that
        over at least half_min_deg; that rate is low, if anything (the spin starts from
        rest), so a slow start makes this check lenient, never a real half turn refused."""
        cfg, lost_t = self.cfg, turn["lost_t"]
        first = [a for t, a in turn["seen"] if t < lost_t][:3]
        if not first or lost_t <= turn["t0"]:
            return False
        start = math.acos(min(1.0, float(np.median(first))))
        angle = math.acos(min(1.0, turn["lost_aspect"])) - start
        if angle < math.radians(cfg.half_min_deg):
            return False
        return bool(rate >= cfg.half_share * angle / (lost_t - turn["t0"]))

    def _end_turn(self, t: float) -> Command:
        if self._turn is not None and self._turn["half"]:
            self.turned_half = self._turn["t0"]
        self._turn = None
        # the card not back after the turn (it never came back, or the turn ended edge-on: an
        # occluded card misread the angle): spin on to find it, whenever it goes missing
        self._search_until = t + self.cfg.search_s
        self.facing_away = not self.facing_away
        self.history.clear()
        self.turns.clear()  # the body's turn before it bounds nothing now (reach_m)
        self.missing = 0
        return self._stop(Phase.WAIT, None)


def merged(spans: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Overlapping intervals joined (sorted by their start)."""
    out: list[tuple[float, float]] = []
    for lo, hi in sorted(spans):
        if out and lo <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], hi))
        else:
            out.append((lo, hi))
    return out
