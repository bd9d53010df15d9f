"""Waiting out what passes instead of ending the run: a pure state machine, one call a frame.

A recoverable condition (the camera moved, the robot's board reset, an object in the lane, ...)
begins a wait: the robot stands (the servo sends STOP, the phase says so, the reason is in the
log) while the condition lasts. When the evidence says it has cleared, and has stayed clear for
the kind's clear_s, the wait ends and the servo resumes through its safe path (re-reference,
re-acquire through the estimator's gate). A condition that lasts longer than the kind's
limit_s, or that comes back more than `times` times in a run, ends the run with its reason, as
a safe stop: the same reason the servo stopped with before it could recover.

    kind       what clears it                          limit_s  times
    moved      re-referenced (floor, map, target)        10       2
    reset      STOP answered for clear_s                 10       3
    lane       the lane clear for clear_s                20       6
    stale      fresh frames from both sensors            10       6
    outside    the marker admitted again (re-acquired)   10       2
    lost       the card lost while driving, found again   5       5
               by a spin back (refind.py), or handed to
               the acquisition's whole-view search
    target     a nearer object that replaced the target went away, the target found
               again where it was, in both views          -        3
    beside     the robot's body near the object's side   10       3
               (pushed while holding, or its line through
               the object): the target measured again, the
               robot backed off along its line out of the
               object's depth (BackOff), re-acquired; the
               lane is planned anew clear of the object

The bounds, on reasoning rather than on any seed: a re-reference takes five frames and its
checks a few more, so 10 s is many tries; a board that resets comes back within a second
(handshake, configuration), and one that resets three times in a run is not well; a person
putting a box down and taking it away again takes a few seconds (the simulated world's boxes
stay 2-6 s), a box left for 20 s is not coming back soon; a sensor that delivers nothing new
for 10 s is broken; a marker that keeps leaving the gate after two re-acquisitions is not one
the servo can trust; the spin back after a card lost while driving takes at most 2 s (3 s
standing when nothing turned it away), and a robot that loses its card a sixth time in a run
steers in a way the servo does not follow. A robot pushed onto the object's side three times
in a run (the backing off and the lane anew take a few seconds each) is on a slope the hold
cannot stand on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from host.servo.clearance import lifted
from host.servo.controller import ControlConfig, lane_pd

MOVED, RESET, LANE, STALE, OUTSIDE, TARGET, LOST, BESIDE = "moved", "reset", "lane", \
    "stale", "outside", "target", "lost", "beside"
WAIT, RESUME, GIVE_UP = "wait", "resume", "give up"


@dataclass(frozen=True)
class Bound:
    limit_s: float  # the condition lasting this long ends the run
    clear_s: float  # cleared by evidence for this long before the servo resumes
    times: int  # waits of this kind in a run; one more ends it


BOUNDS: dict[str, Bound] = {
    MOVED: Bound(10.0, 0.0, 2),
    RESET: Bound(10.0, 0.5, 3),
    LANE: Bound(20.0, 1.0, 6),
    STALE: Bound(10.0, 0.3, 6),
    OUTSIDE: Bound(10.0, 0.0, 2),
    TARGET: Bound(0.0, 0.0, 3),
    LOST: Bound(5.0, 0.0, 5),
    BESIDE: Bound(10.0, 0.0, 3),
}


def no_recovery(lane_stop_s: float) -> dict[str, Bound]:
    """Bounds that recover from nothing (the servo as it was): every condition ends the run
    at once, an object in the lane after lane_stop_s."""
    return {**{k: Bound(0.0, 0.0, 0) for k in BOUNDS}, LANE: Bound(lane_stop_s, 1.0, 1 << 30)}


def servo_bounds(recover: bool, rereference: bool, lane_stop_s: float) -> dict[str, Bound]:
    """The servo's bounds: BOUNDS, without the re-reference unless asked for (a moved camera
    then ends the run at once, as before recovery existed); none at all without recover."""
    if not recover:
        return no_recovery(lane_stop_s)
    return dict(BOUNDS) if rereference else {**BOUNDS, MOVED: Bound(0.0, 0.0, 0)}


class Recovery:
    """At most one wait at a time (the first condition met); `fault` says why the run ends."""

    def __init__(self, bounds: dict[str, Bound] | None = None) -> None:
        self.bounds = dict(BOUNDS if bounds is None else bounds)
        self.kind = ""  # the condition waited out, "" when none
        self.reason = ""
        self.fault = ""  # why the run must end, "" if none
        self.counts: dict[str, int] = {}
        self.recovered: list[tuple[float, str, str]] = []  # (t, kind, reason) of each resume
        self._since = math.nan
        self._clear_since: float | None = None

    @property
    def active(self) -> bool:
        return bool(self.kind)

    def begin(self, t: float, kind: str, reason: str) -> bool:
        """The condition `kind` (reason: in words) is met at t: wait it out (True), or the run
        must end (False, fault set). A wait of the same kind already on goes on unchanged; so
        does a wait for a moved camera when anything but a reset begins (the robot stands in
        either; the other condition is met again, if it still holds, on the new reference)."""
        if self.fault:
            return False
        if self.kind == kind:
            self._clear_since = None
            return True
        n = self.counts.get(kind, 0) + 1
        self.counts[kind] = n
        bound = self.bounds[kind]
        if n > bound.times:
            self.fault = reason if bound.times == 0 else (
                f"{reason} (the {_nth(n)} time in this run)")
            return False
        if self.kind == MOVED and kind != RESET:  # nothing is judged on a reference the
            return True  # camera left (a lane on the old floor line): re-referenced first
        if self.kind:  # another wait is on: it ends in this one (the stricter is kept)
            self.kind = ""
        self.kind, self.reason, self._since, self._clear_since = kind, reason, t, None
        return True

    def update(self, t: float, clear: bool) -> str:
        """The frame at t, where the evidence says the condition has cleared (clear) or not:
        WAIT, RESUME (the wait ends: go the safe way back) or GIVE_UP (fault set)."""
        if self.fault:
            return GIVE_UP
        if not self.kind:
            return RESUME
        bound = self.bounds[self.kind]
        if not clear:
            self._clear_since = None
            if t - self._since >= bound.limit_s:
                self.fault = f"{self.reason} for {bound.limit_s:g} s"
                return GIVE_UP
            return WAIT
        if self._clear_since is None:
            self._clear_since = t
        if t - self._clear_since >= bound.clear_s:
            self.recovered.append((t, self.kind, self.reason))
            self.kind, self.reason, self._clear_since = "", "", None
            return RESUME
        return WAIT

    def give_up(self, why: str) -> None:
        """The recovery itself failed (why): the run ends."""
        self.fault = f"{self.reason}: {why}" if self.reason else why
        self.kind = ""


@dataclass(frozen=True)
class BackOffConfig:
    duty: int = 350  # permille, straight along the robot's line (the wheels' trim kept)
    clear_m: float = 0.10  # backed off to this far beyond block_m of the object's depth: the
    # run-up in which the new lane's steering moves the body sideways
    max_m: float = 0.40  # depth travelled backing off without clearing it: no way back
    camera_m: float = 0.6  # nor nearer the camera than this
    turn_m: float = 0.01  # the gap to the object's side shrinking this much backing off: the
    # robot is turned toward it, and backs off the other way
    turned: float = 0.3  # ... and by this much a metre of depth travelled (a heading ~17
    # degrees toward it; a 1 cm/s push at the back-off's ~8 cm/s is 0.12)
    side_m: float = 0.01  # the body this near the object's side (or across it): it backs
    # off only away from the face, and stands if that closes on the side level with the face
    # (or, beyond the face, takes the body from clear of the extent to across it: behind it)
    level_m: float = 0.12  # level with the face: the body's half diagonal (0.113) reaches it
    unseen_s: float = 1.0  # the card unseen this long backing off (turned away): re-acquired
    beyond_m: float = 0.02  # the robot this far beyond the object's face backs off deeper
    # toward the camera, out of the object's depth but not yet settled on the new lane (the
    # loop: off it by more than lane_m, or moving across faster than lane_mps, a heading of
    # ~6 degrees at the back-off's ~9 cm/s), it backs off up to settle_m more: a back-off
    # steered onto its lane ends turned 14-19 degrees the way that, driving in again, swings
    # the body 2-3 cm back toward the object's side, and the turned body's reach (the
    # controller's reach_m) took it within the check's margin before the lane was won
    # (tests/servo/test_back_off.py's closed loop, four times). Never nearer the camera than
    # camera_m + camera_room_m (that ends it done, not named; max_m bounds only the depth
    # travelled before it is out of the object's depth)
    settle_m: float = 0.15
    camera_room_m: float = 0.05
    lane_m: float = 0.01
    lane_mps: float = 0.01
    # the body's line this far or more off the depth axis (and beyond the heading's spread),
    # beside the object (not in front of its face by level_m): the first way is the one its
    # line takes away from the object's side (away_by_heading), not the one by depth alone
    # (dev seed 3 #4: 2.6 cm beyond the face, turned 21 degrees toward the side, it backed
    # off deeper and closed 1.7 cm on the side in 0.5 s: stopped, no safe way back)
    heading_min: float = math.radians(5)
    # the card showing the body turned (turned_m this far beyond half the width, ~8 degrees
    # or more), its line's closing is told from turned_turn_m of shrink, not turn_m: the way
    # is known turned one way or the other, and the 1 cm a push alone might close came too
    # late (#3/4: the heading unknown, spread 13 degrees, the flip due at 1 cm was one frame
    # behind the corner rule's stop). Only the first way: it flips sooner (the other way is
    # judged as ever); the second starts while the body still coasts the first way (#3/4:
    # 5 mm there stopped it, closing either way)
    turned_reach_m: float = 0.01
    turned_turn_m: float = 0.005
    corner_m: float = 0.033  # the body's half diagonal less its half width (0.113 - 0.08):
    # how far a corner of a body turned any way reaches beyond the side the gap is reckoned
    # for. Level with the face, closing, the other way runs the body past the object's end:
    # with a gap below this it stops (seed 15 trial 857: gap 1.0 cm reckoned, the heading
    # 2.5 degrees estimated, 23.5 true: the turned corner hit the side going deeper)
    half_width_m: float = ControlConfig.half_width_m  # the body: the rectangle front_clear
    half_length_m: float = ControlConfig.half_length_m  # turns
    coast_s: float = 0.5  # after the flip the body coasts the first way this long at most
    # (the wheels' latency, 60-120 ms, and run-down, 80 ms, at the back-off's ~8 cm/s): the
    # second way's closing counts from where its own travel begins (seed 17 trial 193: 0.9 cm
    # closed coasting 0.26 s after the flip stopped it "either way", while the second way
    # opened the gap; tests/servo/test_back_off_closing.py)


DONE = "done"


class BackOff:
    """The robot's body came near the object's side (controller: pushed while holding, or
    its line passes through the object): rather than end the run, the robot stands while the
    target is measured again (its depth may have moved: a stale depth puts the object beside
    the robot when it is not), then, still within block_m of the fresh depth, backs off
    straight along its line, away from the object's depth (toward the camera unless the
    robot is beyond the object's face), to block_m + clear_m from it; the servo re-acquires
    and the controller plans its lane anew, clear of the object. A robot turned toward the
    object's side closes on it backing off: its gap shrinking by turn_m, and by turned a
    metre of depth travelled, it backs off the other way instead (once; the body's far
    corner is then on the object's open side). A pure state machine, one call a frame:
    update gives the wheels' duties; `outcome` is DONE (resume) or why there is no safe way
    back (the run ends, named), "" while under way. The loop's checks of a drive (the
    marker in view, the fixed objects, the motion against the command) act on the
    back-off's commands as on any drive, the view's the way the back-off goes (`way`), and
    the lane watch looks that way too: a new object there within the stopping distance ends
    the back-off, named. Away from the camera the robot's own body hides a low object right
    behind it (perception.lane_obstacle sees only beside and above it): that way the travel
    is bounded by block_m + clear_m from the object's depth (at most 0.25 m), no more. It
    steers onto the lane the controller will hold (lane_steer)."""

    def __init__(self, block_m: float, cfg: BackOffConfig = BackOffConfig()) -> None:
        self.block_m, self.cfg = block_m, cfg
        self.outcome = ""
        self.deeper: bool | None = None  # the way it backs off, fixed once measured
        self.start_z: float | None = None
        self.start_gap: float | None = None  # the body's gap to the object's side then
        self.start_raw: float | None = None  # the centre's (half the width's) gap then
        self.flip_t: float | None = None  # when it flipped to the other way
        self.flipped = False
        self.seen_t: float | None = None  # the card last seen

    def _settle_spent(self, z: float, e: float) -> bool:
        """Backing off toward the camera past block_m + clear_m to settle on the lane: the
        most it goes (settle_m more), or as near the camera as leaves camera_room_m before
        the limit that ends it named (camera_m)."""
        cfg = self.cfg
        return (abs(e) >= self.block_m + cfg.clear_m + cfg.settle_m
                or z < cfg.camera_m + cfg.camera_room_m)

    @property
    def way(self) -> int | None:
        """The way it backs off in depth: +1 away from the camera, -1 toward it, None
        before its first move is decided (the lane watch looks this way: loop.py)."""
        return None if self.deeper is None else 1 if self.deeper else -1

    def update(self, t: float, z: float | None, gap: float | None, target_m: float,
               confirmed: bool, facing_away: bool, trim: float,
               pushed_m: float = 0.0, floor: int = 0, steer: float = 0.0,
               settled: bool = True, turned_m: float = 0.0, away: int = 0) -> tuple[int, int]:
        """z: the robot's depth this frame at t (None: not seen, it stands; unseen unseen_s
        once it has moved, the back-off ends: the re-acquisition looks for the card, its
        spin checked as any); gap: the body's clearance across from the object's extent
        (m, < 0 across it; None: not known; within side_m, no safe way back); target_m
        the object's depth, confirmed when measured again since the back-off began.
        pushed_m: how far the sideways drift fitted while the robot stood beside the object
        carries the body toward the object's side within the hold's push horizon (0: none,
        or the body across the object's extent). Standing for the re-measure with a gap
        below it, the push would bring the body onto the side before a back-off could begin
        and clear it: no safe way back (seed 14 trial 162: 1.9 cm closing at 0.9 cm/s, the
        re-measure not in 2.6 s). floor: the least duty that moves the robot now (the
        controller's, raised by stiction or a sagging battery): no wheel is driven below it,
        so the back-off moves where the drive would. steer: permille taken from the left
        wheel and given to the right (lane_steer: the new lane's pull), at most half the
        duty; none while the body is level with the object's face or behind it. settled:
        the body on the new lane and not moving across it (lane_m, lane_mps; the loop); not,
        toward the camera, it backs off up to settle_m beyond block_m + clear_m. turned_m:
        how much farther across than half its width the body reaches, turned as the card
        shows it (the controller's reach_m less half_width_m): every rule judges the gap
        less it, but for the pass by the end (corner_m: the half diagonal's reach, any turn,
        beyond half the width: already the most a turn adds). away: +1 backing off deeper
        takes the body's line away from the object's side, -1 toward it, 0 not known
        (away_by_heading): beside the object (not level_m in front of its face) the first way
        is the one away from the side; the rules that follow judge it as any way."""
        raw = gap
        gap = None if gap is None else gap - max(0.0, turned_m)
        if z is not None:
            self.seen_t = t
        elif self.start_z is not None and self.seen_t is not None and \
                t - self.seen_t > self.cfg.unseen_s and not self.outcome:
            self.outcome = DONE
        if not self.outcome and self.start_z is None and not confirmed and \
                gap is not None and pushed_m > 0 and gap < pushed_m:
            self.outcome = ("no safe way back: pushed toward the object's side while its "
                            "depth is measured again")
        if self.outcome or z is None or not confirmed:
            return 0, 0
        e = z - target_m
        cfg = self.cfg
        first = self.start_z is None
        if first:
            self.deeper, self.start_z, self.start_gap = e > cfg.beyond_m, z, gap
            self.start_raw = raw
            if away and e > -cfg.level_m:
                self.deeper = away > 0
        out = self.block_m + (0.0 if first else cfg.clear_m)
        if abs(e) >= out and (first or self.deeper or settled or self._settle_spent(z, e)):
            self.outcome = DONE  # out of the object's depth (measured again: never in it)
            return 0, 0
        assert self.start_z is not None
        if self.flip_t is not None and t - self.flip_t <= cfg.coast_s and \
                (z < self.start_z if self.deeper else z > self.start_z):
            self.start_z, self.start_raw = z, raw  # still coasting the first way
        # closing on the side as it goes: turned toward it (a push alone closes far less
        # per metre of depth travelled). The centre's approach, not the turned body's gap:
        # the card's turn bound (a median of ten aspects) moves by 0.5-1 cm from frame to
        # frame with the body's turn unchanged (seed 17 trials 226 and 364: 0.07 cm of
        # approach read as 0.6 cm of closing); a turn that grows is judged by the gap's
        # own rules (at the side, behind the face) on every frame
        shrunk = 0.0 if raw is None or self.start_raw is None else self.start_raw - raw
        least = cfg.turned_turn_m if turned_m >= cfg.turned_reach_m and not self.flipped \
            else cfg.turn_m  # the second way starts coasting the first: turn_m as ever
        closing = shrunk > max(least, cfg.turned * abs(z - self.start_z))
        # level with the object's face (within level_m of its depth) or behind it, the
        # body's side can reach the object's: a real object's sides run back from its face
        # for a depth the camera does not see (the simulation's box is its face alone; the
        # reference's fixed cells are faces too). In front of the face, across the object's
        # extent is only its line, and the way away from the face is the one way back (the
        # other way is into the face)
        level = abs(e) < cfg.level_m
        beside = e > -cfg.level_m
        tight = gap is not None and gap < cfg.side_m
        near = raw is not None and raw < cfg.corner_m  # too near to pass the end turned
        # in front of the face, going toward the camera: the body itself (the rectangle,
        # turned any way within the card's bound), not its bounds across and in depth apart,
        # clear of the side and what runs back from it by side_m from here until it is in
        # front of the face, the centre closing as it has: neither closing nor at the side
        # (seed 18 trial 46: the corner that reaches farthest across is not the one that
        # reaches deepest; truly clear by 4.3 cm either way, stopped "closes on its side")
        if not self.deeper and e < 0 and raw is not None:
            slope = max(0.0, shrunk) / max(abs(z - self.start_z), 1e-3)
            if front_clear(raw, e, turned_m, slope, cfg) >= cfg.side_m:
                closing, level = False, False
        if beside and closing and (self.flipped or near):
            self.outcome = ("no safe way back: backing off either way closes on its side"
                            if self.flipped else
                            "no safe way back: backing off closes on the object's side")
        elif e > 0 and gap is not None and gap < 0:
            # behind the face, across the object's extent: where a box's own depth is, which
            # the face hides from the camera, where an object pushed farther lands (seed 14
            # trial 609); no way there keeps out of it, whichever way the body came
            self.outcome = ("no safe way back: backing off takes the body behind the "
                            "object's face" if (self.start_gap or 0.0) >= 0 else
                            "no safe way back: the body is behind the object's face, "
                            "across its extent")
        elif level and gap is not None and gap < 0 <= (self.start_gap or 0.0):
            self.outcome = "no safe way back: the body is at the object's side"
        elif abs(z - self.start_z) > cfg.max_m and abs(e) < out:  # not yet out of its depth
            self.outcome = f"no safe way back: {cfg.max_m:.2f} m backed off and still beside it"
        elif not self.deeper and z < cfg.camera_m:
            self.outcome = "no safe way back: the camera is behind the robot"
        if self.outcome:
            return 0, 0
        if closing and not tight:  # turned toward the object's side: the other way
            self.deeper, self.flipped, self.start_z, self.start_gap = \
                not self.deeper, True, z, gap
            self.start_raw, self.flip_t = raw, t
        sign = 1 if self.deeper == facing_away else -1
        d = sign * max(cfg.duty, floor)
        # straight while level with the face or behind it (beside): the steer's yaw swings the
        # body's deeper end toward the object's side, which runs back from the face unseen and
        # which every rule here judges by the centre's gap only (reversing out from level with
        # the face, gap 1.2 cm, a lane 25 cm out: a corner behind the face 0.3 cm across the
        # side; tests/servo/test_back_off_steered.py); the lane is won in the run-up in front
        bend = 0.0 if beside else max(-abs(d) / 2, min(abs(d) / 2, steer))
        left, right = lifted(d * (1 - trim) - bend, d * (1 + trim) + bend, floor, d)
        return int(round(left)), int(round(right))


def front_clear(raw: float, e: float, turned_m: float, slope: float,
                cfg: BackOffConfig = BackOffConfig(), steps: int = 9) -> float:
    """The least clearance (m) of the body, in front of the object's face or level with it
    (e: the robot's depth less the face's, < 0 in front) backing off toward the camera, to
    the object's region beside it (across from its side, at or behind its face: its sides
    run back unseen): the rectangle (half_width_m across, half_length_m along) turned by any
    angle within the bound the card gives (turned_m: how much farther across than half its
    width it reaches), either way, its centre raw beyond half the width from the side's
    line, from here on toward the camera until no part of it can be behind the face, the
    centre closing on the side by slope a metre of depth (at least the bound's own slope).
    Negative: the body overlaps the region."""
    w, h = cfg.half_width_m, cfg.half_length_m
    big = math.hypot(w, h)
    bound = math.atan2(h, w) - math.acos(min(1.0, (w + max(0.0, turned_m)) / big))
    slope = max(slope, math.tan(bound))
    u0 = raw + w
    least = math.inf
    for k in range(steps):
        a = bound * (2 * k / (steps - 1) - 1)
        sa, ca = math.sin(a), math.cos(a)
        corners = [(i * h * sa + j * w * ca, i * h * ca - j * w * sa)
                   for i, j in ((1, 1), (1, -1), (-1, -1), (-1, 1))]
        s = 0.0
        while True:
            u, v = u0 - slope * s, e - s
            least = min(least, _rect_to_region([(u + du, v + dv) for du, dv in corners]))
            if v + big < 0 or s > 0.5:
                break
            s += 0.01
    return least


def _rect_to_region(corners: list[tuple[float, float]]) -> float:
    """The least distance from a convex polygon (corners in order, (u, v)) to the region
    u <= 0, v >= 0 (the object beside the body: u across from its side, v behind its face);
    negative (how deep, roughly) where they overlap."""
    inside = [min(-u, v) for u, v in corners if u <= 0 <= v]
    if inside:
        return -max(inside)
    n = len(corners)
    cross = [(corners[(i + 1) % n][0] - u) * (0.0 - v) - (corners[(i + 1) % n][1] - v) * (0.0 - u)
             for i, (u, v) in enumerate(corners)]
    if all(c > 0 for c in cross) or all(c < 0 for c in cross):
        return -1e-3  # the region's corner (the face's end) inside the body
    least = math.inf
    for i, (u1, v1) in enumerate(corners):
        u2, v2 = corners[(i + 1) % n]
        for k in range(17):
            f = k / 16
            u, v = u1 + f * (u2 - u1), v1 + f * (v2 - v1)
            if u <= 0 <= v:
                return 0.0  # an edge crosses the region between corners
            least = min(least, math.hypot(max(u, 0.0), max(-v, 0.0)))
    return least


def away_by_heading(heading: float | None, spread: float, lateral_m: float | None,
                    keep_out: tuple[float, float] | None,
                    cfg: BackOffConfig = BackOffConfig()) -> int:
    """Which way in depth the body's line takes it away from the object's side: +1 deeper
    (away from the camera), -1 toward the camera, 0 not known (no heading, the line within
    heading_min or its spread of the depth axis, no extent, or the body across it). heading:
    the robot's travel (rad from +z toward +x, clearance.Heading), either way along it."""
    if heading is None or lateral_m is None or keep_out is None:
        return 0
    x0, x1 = keep_out
    if x0 <= lateral_m <= x1:
        return 0
    slope = math.tan(heading)  # x gained per metre deeper along the line, either way
    if abs(math.atan(slope)) <= max(cfg.heading_min, spread):
        return 0
    side = 1 if lateral_m > x1 else -1  # away from the side is this way in x
    return 1 if slope * side > 0 else -1


def settled_on(lateral_m: float | None, lane_m: float | None, vx_mps: float,
               cfg: BackOffConfig = BackOffConfig()) -> bool:
    """Whether the body is on its new lane (within lane_m) and not moving across it (slower
    than lane_mps): BackOff.update's settled; True where either is not known."""
    if lateral_m is None or lane_m is None:
        return True
    return abs(lateral_m - lane_m) <= cfg.lane_m and abs(vx_mps) <= cfg.lane_mps


def lane_steer(way: int, lateral_m: float, lane_m: float, vx_mps: float, gain: float,
               damping: float) -> float:
    """The back-off's steer (permille, BackOff.update's steer): the controller's lane law
    (its PD: gain permille per cm off the lane, damping per cm/s of sideways rate) in the
    back-off's direction (way: +1 away from the camera, -1 toward it). Straight along a
    heading turned toward the object's side, backing off carried the body across it (seed 14
    trial 71: 17 degrees, 5 cm over 0.16 m of depth) and the new lane could not win it back
    in the run-up (line through the object, the fourth time); bent onto the lane, the body
    comes out of the object's depth clear of its side."""
    return lane_pd(way, lateral_m - lane_m, vx_mps, gain, damping)


def _nth(n: int) -> str:
    return {1: "first", 2: "second", 3: "third", 4: "fourth", 5: "fifth"}.get(n, f"{n}th")
