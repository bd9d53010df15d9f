"""Randomized trials of the servo in the simulated world (host servo --sim --trials N).

Each trial: the target box at a random depth, the robot at a random start 0.4-3.0 m from the
camera (in front of or behind the target), every fault of host.sim.faults at a random size
(none with nominal=True), one of CAMERAS cameras of the campaign (its lenses and their
chessboard calibration), now and then a reset of the robot's board (its BOOT frame sometimes
lost), run on the simulated clock by host.servo_run until the servo holds (after the last scene
event), stops itself, or 45 s pass. Trial i of seed s depends on (s, i) alone. Outcomes:

    held         holding, within 2 cm of the object's true depth (or within the tolerance the
                 servo announced it had to widen to)
    missed       holding, but farther than that from the object's true depth
    stopped      a safe stop, with its reason (target vanished, marker lost, link error ...)
    not settled  neither held nor stopped within 45 s: not a safe stop, not a success
    unsafe       the robot's body (its footprint with its heading) hit the object (the
                 target: "hit the object"; another box, the back wall or a look-alike robot:
                 named, with where it stands; a box's face or its side, an end of the face:
                 the world's boxes are faces; error_m stays the distance to the target; a
                 box the scene put down touching the robot is hit only when the robot
                 closes on it by CLOSED_ON_M) or the camera, its marker left
                 the view while the motors drove, the motors drove with no valid observation
                 for longer than the stale limit, or on a marker depth farther than
                 TRUTH_GAP_M + TRUTH_GAP_REL x depth from the robot's true depth
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from host.camera.source import CameraError
from host.emulator.emulator import Faults as LinkFaults
from host.link import protocol_gen as gen
from host.link.client import LinkError
from host.servo.controller import ControlConfig
from host.servo.loop import LogRow
from host.servo.phase import Phase
from host.servo_run import HELD, NOT_SETTLED, UNSAFE, Rules, run_servo
from host.sim.faults import WorldFaults, random_faults
from host.sim.run import Setup, SimRun, simulation
from host.sim.world import Box, Robot
from host.stereo.params import MatcherParams

MAX_S = 45.0
SETTLE_S = 1.0
LOST_GIVE_UP_S = 5.0
HOLD_WITHIN_M = 0.02
CAMERAS = 16  # cameras (lenses, calibration) of a campaign; trial i uses camera i % CAMERAS
RESET_P, BOOT_LOST_P = 0.02, 0.02  # chance of a board reset with its BOOT frame, without it
TRUTH_GAP_M, TRUTH_GAP_REL = 0.10, 0.05  # driving on a depth this far from the truth is unsafe
# the probe move (host.servo.acquire, at most probe_s at up to max_probe_duty) tests a sighting
# it does not yet trust, maybe another robot's card: it is judged by where it goes (collisions,
# the view, stale frames) and by this bound on its travel, not by the depth it tests
PROBE_TRAVEL_M = 0.15
# a box the scene puts down (moved, appeared) already touching the robot is the scene's doing,
# not the robot's: the robot hits it when it closes on it by more than this afterwards
CLOSED_ON_M = 0.01


@dataclass
class Trial:
    index: int
    start_m: float
    target_m: float  # the object's true depth at the start
    faults: str  # a short description
    events: list[str]  # the kinds of event drawn (scene events, silence, resets)
    outcome: str  # held / missed / stopped / not settled / unsafe
    reason: str
    error_m: float  # robot's true depth minus the object's, at the end
    tolerance_m: float  # as the servo announced it
    overshoot_m: float
    time_to_hold_s: float
    sim_s: float
    truth_gap_m: float  # largest |marker depth driven on - true depth|


def trial_setup(seed: int, index: int, size: tuple[int, int], params: MatcherParams,
                nominal: bool = False) -> Setup:
    rng = np.random.default_rng([seed, index])
    target_z = float(rng.uniform(1.0, 1.5))
    boxes = (Box(target_z, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30),
             Box(2.4, 0.60, 0.95, 0.55))
    start = float(rng.uniform(0.4, 3.0))
    x = float(rng.uniform(-0.04, 0.04)) * start
    theta = math.radians(float(rng.uniform(-4, 4)))
    faults = WorldFaults() if nominal else random_faults(rng, target_z)
    trial_seed = int(rng.integers(1 << 30))
    calib_seed = None
    if not nominal:  # lenses and resets from streams of their own: the rest stays as it was
        camera = index % CAMERAS
        lens = np.random.default_rng([seed, camera, 1]).uniform(-0.1, 0.04, 2)
        faults = dataclasses.replace(faults, camera=dataclasses.replace(
            faults.camera, distortion=(float(lens[0]), float(lens[1]))))
        calib_seed = seed * CAMERAS + camera
        faults = dataclasses.replace(faults, link=_reset(np.random.default_rng([seed, index, 2]),
                                                         faults.link))
    return Setup(size, start, x, theta, boxes, faults, seed=trial_seed,
                 params=params.replace(colour=False), control=ControlConfig(),
                 calib_seed=calib_seed)


def _reset(rng: np.random.Generator, link: LinkFaults) -> LinkFaults:
    """Now and then a reset of the board between 2 and 8 s (watchdog or brown-out), its BOOT
    frame lost in half of them."""
    u = float(rng.random())
    if u >= RESET_P + BOOT_LOST_P:
        return link
    cause = gen.ResetCause.WATCHDOG if rng.random() < 0.5 else gen.ResetCause.BROWN_OUT
    return dataclasses.replace(link, reset_at_ms=float(rng.uniform(2000, 8000)),
                               reset_cause=int(cause), boot_lost=u < BOOT_LOST_P)


def event_kinds(f: WorldFaults) -> list[str]:
    kinds = [e.kind for e in f.events]
    if f.link.silent_after_ms is not None:
        kinds.append("silent")
    if f.link.reset_at_ms is not None:
        kinds.append("reset, BOOT lost" if f.link.boot_lost else "reset")
    return kinds


def _describe(f: WorldFaults) -> str:
    m, c = f.motor, f.camera
    parts = [f"gain {m.gain[0]:.2f}/{m.gain[1]:.2f}", f"latency {m.latency_ms:.0f} ms",
             f"skew {c.skew_ms:.0f} ms", f"drop {c.drop:.2f}"]
    return ", ".join(parts + event_kinds(f))


def _touching(r: Robot, b: Box) -> tuple[float, float] | None:
    """How far the robot's body reaches into box b across x and along z (m) when they overlap,
    else None. The world models a box by its face alone (host.sim.world, the renderer: one
    layer at z_m, x0..x1, nothing behind it), so the box is that segment: the body hits its
    face, or its side (an end of the face, across the body's side)."""
    for ax, az, half in ((math.sin(r.theta), math.cos(r.theta), r.body_length_m / 2),
                         (math.cos(r.theta), -math.sin(r.theta), r.body_width_m / 2)):
        centre = r.x_m * ax + r.z_m * az
        ends = (b.x0_m * ax + b.z_m * az, b.x1_m * ax + b.z_m * az)
        if max(ends) <= centre - half or min(ends) >= centre + half:
            return None  # the body's own axes separate them
    hx, hz = r.half_extent()
    across = min(b.x1_m, r.x_m + hx) - max(b.x0_m, r.x_m - hx)
    along = hz - abs(r.z_m - b.z_m)
    return (across, along) if across > 0 and along > 0 else None


def _unsafe(sim: SimRun, last_valid: float, stale_s: float,
            put_down: dict[Box, tuple[float, float]] | None = None) -> str:
    """put_down: the boxes the scene put down touching the robot, with how far the body
    reached into them then (a contact it made, not the robot: the robot hits such a box only
    by closing on it, across or along, by CLOSED_ON_M)."""
    w, r = sim.world, sim.world.robot
    left, right = sim.emulator.motors()
    driving = abs(left + right) / 2 > 60
    target = w.nearest_box() if w.target_index is None else w.boxes[w.target_index]
    put_down = put_down or {}
    for b in w.boxes:
        reach = _touching(r, b)
        was = put_down.get(b)
        if reach is None or (was is not None and reach[0] <= was[0] + CLOSED_ON_M
                             and reach[1] <= was[1] + CLOSED_ON_M):
            continue
        end = b.x0_m if r.x_m < b.x0_m else b.x1_m if r.x_m > b.x1_m else None
        part = "" if end is None or reach[1] <= reach[0] else f", its side at x {end:+.2f} m"
        return ("hit the object" + part) if b == target else (
            f"hit another box, not the target: its face at {b.z_m:.2f} m, "
            f"x {b.x0_m:+.2f}..{b.x1_m:+.2f} m{part}")
    if r.z_m + r.half_extent()[1] > w.wall_z_m:
        return f"hit the back wall at {w.wall_z_m:.2f} m"
    o = w.decoy_touched()
    if o is not None:
        return f"hit the look-alike robot standing at {o.z_m:.2f} m, x {o.x_m:+.2f} m"
    if r.z_m < 0.3:
        return "hit the camera"
    u, v, _ = w.marker_truth()
    ring = w.geometry.focal_px * r.marker_radius_m * r.ring_ratio / r.z_m
    width, height = w.size
    if driving and not (ring <= u <= width - ring and ring <= v <= height - ring):
        return "the marker left the view while driving"
    if driving and sim.source.t - last_valid > stale_s + 0.05:
        return f"drove {sim.source.t - last_valid:.2f} s without a valid observation"
    return ""


def truth_gap(row: LogRow) -> float:
    """|marker depth - true depth| of a step whose command drove on its observation, else 0."""
    used = math.isfinite(row.depth_m) and not row.reason and (row.left or row.right)
    return abs(row.depth_m - row.truth_depth_m) if used else 0.0


class Judge:
    """The trial's watch over a run (host.servo_run's watch): a reason the run is unsafe."""

    def __init__(self, sim: SimRun) -> None:
        self.sim = sim
        self.last_valid = 0.0
        self.worst_gap = 0.0
        self.probe_from: tuple[float, float] | None = None  # where the probe move began (m)
        self.boxes = set(sim.world.boxes)  # as last seen: a box not among them was put down
        self.put_down: dict[Box, tuple[float, float]] = {}  # put down touching: reach then

    def _boxes_put_down(self) -> None:
        """Note the boxes the scene put down (moved or appeared) since the last step that
        touch the robot where it stands: the scene's contact, judged by what the robot does
        next (host.sim.source applies the events between steps)."""
        r, now = self.sim.world.robot, set(self.sim.world.boxes)
        for b in now - self.boxes:
            reach = _touching(r, b)
            if reach is not None:
                self.put_down[b] = reach
        self.boxes = now

    def __call__(self, row: LogRow) -> str:
        if math.isfinite(row.depth_m) and not row.reason:
            self.last_valid = row.t
        self._boxes_put_down()
        r = self.sim.world.robot
        if row.phase == Phase.PROBE:
            self.probe_from = self.probe_from or (r.x_m, r.z_m)
            travel = math.hypot(r.x_m - self.probe_from[0], r.z_m - self.probe_from[1])
            if travel > PROBE_TRAVEL_M:
                return f"the probe move went {travel * 100:.0f} cm on a sighting not yet trusted"
            return _unsafe(self.sim, self.last_valid, self.sim.servo.stale_s, self.put_down)
        self.probe_from = None
        gap = truth_gap(row)
        self.worst_gap = max(self.worst_gap, gap)
        if gap > TRUTH_GAP_M + TRUTH_GAP_REL * row.truth_depth_m:
            return (f"drove on a marker depth of {row.depth_m:.2f} m with the robot at "
                    f"{row.truth_depth_m:.2f} m")
        return _unsafe(self.sim, self.last_valid, self.sim.servo.stale_s, self.put_down)


def run_trial(job: tuple[int, int, tuple[int, int], MatcherParams, bool]) -> Trial:
    """One trial of a campaign, as its record (the workers' and Ray's task)."""
    return traced_trial(job)[0]


def traced_trial(job: tuple[int, int, tuple[int, int], MatcherParams, bool]
                 ) -> tuple[Trial, list[LogRow]]:
    """One trial, (seed, index, size, params, nominal), as its record and the servo's log
    rows (a trial traced alone: `host servo --sim --trials N --trial-index I --log run.csv`)."""
    seed, index, size, params, nominal = job
    setup = trial_setup(seed, index, size, params, nominal)
    target0 = setup.boxes[0].z_m if setup.boxes else math.nan
    last_event = max((e.t_s + e.duration_s for e in setup.faults.events), default=0.0)
    outcome, reason, tol = "stopped", "", math.nan
    with simulation(setup, reference=False) as sim:
        servo = sim.servo
        judge = Judge(sim)
        try:
            servo.reference()
            rules = Rules(settle_s=SETTLE_S, limit_s=MAX_S, lost_s=LOST_GIVE_UP_S,
                          hold_from_s=last_event + 2.5)
            end = run_servo(servo, rules, sim.source.clock, lambda: sim.world.robot.z_m,
                            watch=judge,
                            each=lambda row: sim.depths.append(sim.world.robot.z_m))
            tol = servo.tolerance_m
            reason = end.reason
            if end.how == UNSAFE:
                outcome = "unsafe"
            elif end.how == NOT_SETTLED:
                outcome = "not settled"
            elif end.how == HELD:
                err = sim.depth_error_m()
                within = abs(err) <= max(HOLD_WITHIN_M, tol if math.isfinite(tol) else 0.0)
                outcome = "held" if within else "missed"
            else:
                reason = reason or servo.outcome()[1]
        except (LinkError, CameraError) as e:
            reason = f"link: {e}" if isinstance(e, LinkError) else str(e)
        err = sim.depth_error_m() if sim.world.boxes else math.nan
        z = sim.depths or [setup.start_z_m]
        final = sim.world.nearest_box().z_m if sim.world.boxes else target0
        over = max(z) - final if setup.start_z_m < final else final - min(z)
        t_hold = math.nan
        if outcome in ("held", "missed"):
            rows = servo.rows
            k = len(rows) - 1
            while k > 0 and rows[k - 1].phase == Phase.HOLD:
                k -= 1
            t_hold = rows[k].t - rows[0].t
        return Trial(index, setup.start_z_m, target0, _describe(setup.faults),
                     event_kinds(setup.faults), outcome, reason, err, tol, max(0.0, over),
                     t_hold, sim.source.t, judge.worst_gap), servo.rows
