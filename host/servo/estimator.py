"""The robot's state from its marker, never from one reading: every sighting is gated against
where the robot can be, given what it was commanded since the last one it trusted, and its
motion is checked against the commands (a pure state machine, one call per frame).

State: depth z and lateral position x (m, camera frame: z along the optical axis, x to the
right) and their rates, on each axis the steady-state Kalman filter of a constant rate (an
alpha-beta filter with the gains of Kalata's tracking index, `gains`) on the sightings it
accepts, weighed by each sighting's own noise on that axis: the depth's grows as z^2 (3.5 cm
at 3 m, 0.8 cm at 1.4 m for 0.1 px), the lateral position's, from the image column, grows
as z too but with the bearing: sqrt(B^2/2 - x B + x^2) / z of the depth's, at least 1 mm
(noise_m; at 0.1 px on the 320x240 rig: 0.03 of it on the axis at 3 m, 0.06 at 2 m, 0.13 at
1.4 m and 0.18 at 1.2 m by the floor, 0.15-0.19 half-way to the picture's edge and 0.31-0.36
near it), so x follows its sightings more closely than a far depth, which is smoothed (with
one gain pair for both, x lagged and the far depth's rate was its noise); the motion model's
acceleration is the command's: a drive's starts and stops, or, told to stand for run_down_s,
a push's slow onset alone. The gate of a new
sighting is the reach of the robot since the last accepted one: nothing while it was told to
stand but a slow drift (a push, a slope) and the run-down of its last motion; what its duties
allow while it was told to move (max_speed_mps at full duty; a spin in place only the share
unequal wheels turn into travel); always margin_m (the card's offset from the turn axis, blur)
and sigmas times the sighting's own noise (depth noise grows as z^2). Its size
must fit its disparity: the disc's vertical radius against the ratio learnt from the accepted
sightings. A sighting outside the gate is not used; seen only outside it for outlier_stop_s,
the run stops with that reason.

Motion check: while the robot is driven straight one way, its depth must move that way. Moved
against_m (and three of a sighting's noise; medians of five) the other way, the robot faces
the other way than assumed ("against"); driven at still_duty or more for still_s without the
marker moving ("still"), what is seen is not the robot moving (a marker painted on the wall, a
frozen picture, a stuck robot).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from host.camera.geometry import Geometry
from host.servo.robot_model import MAX_SPEED_MPS

AGAINST, STILL = "against", "still"
OUTSIDE = "the marker is seen only where the robot cannot be"


@dataclass(frozen=True)
class EstimatorConfig:
    max_speed_mps: float = MAX_SPEED_MPS  # the robot's speed at full duty, with room
    drift_mps: float = 0.03  # motion while told to stand (a push, a slope)
    run_down_s: float = 0.35  # actuation latency and the wheels' run-down after a stop
    margin_m: float = 0.04  # always allowed: the card's offset from the turn axis, blur
    sigmas: float = 5.0  # a sighting's own noise allowed, in standard deviations
    size_tolerance: float = 0.3  # the disc's radius against its disparity, relative
    outlier_stop_s: float = 2.0
    min_depth_m: float = 0.2  # a sighting nearer than this or farther than max_depth_m (or at
    max_depth_m: float = 8.0  # a disparity <= 0) is not the robot, even as the first one
    accel_mps2: float = 0.5  # the robot's unmodelled acceleration along the depth (one sd):
    # starts and stops; across, lateral_accel_mps2 (a drive's curve, a push's onset)
    lateral_accel_mps2: float = 0.3
    stand_accel_mps2: float = 0.05  # either way, told to stand for run_down_s: a push's onset
    lateral_floor_m: float = 0.001  # the least lateral noise: the disc's centre, not only the
    # disparity's noise (a card turning, blur)
    spin_share: float = 0.15  # of a spin's duty that unequal wheels may turn into travel
    settle_s: float = 0.3  # a command's effect shows this long after it (latency and lag)
    against_m: float = 0.025
    still_s: float = 1.0
    still_duty: int = 350
    still_m: float = 0.015
    # the lateral rate is taken as learnt standing (Estimator.rate_stood) after this many
    # sightings standing since the last one taken while driven: the stand gains spend a driven
    # rate to a tenth in 10-15 sightings at 1 mm lateral noise, to a third at 2 mm (30 fps)
    stood_sightings: int = 12


@dataclass(frozen=True)
class Sighting:
    """One marker sighting: its capture time (s), disparity (px, skew-free), left-image column
    (px) and the disc's vertical radius (px)."""

    t: float
    disparity: float
    u: float
    radius_px: float


@dataclass
class _State:
    t: float
    z: float
    x: float
    vz: float = 0.0
    vx: float = 0.0


class Estimator:
    def __init__(self, geometry: Geometry, config: EstimatorConfig = EstimatorConfig(),
                 sigma_px: float = 0.1) -> None:
        self.g, self.cfg = geometry, config
        self.sigma_px = sigma_px  # the disparity's noise a frame (px), from the noise phase
        self.state: _State | None = None
        self.rejected = 0  # sightings rejected since the last accepted one
        self.why = ""  # why the last sighting was rejected
        self._ratios: list[float] = []  # accepted radius / disparity
        self._moving_s = 0.0  # time told to go since the last accepted sighting
        self._travel_m = 0.0  # the most its commands since then can have moved it
        self._cmd: tuple[float, int, int] | None = None  # the command in force since t
        self._outside_since: float | None = None
        self._stopped_since: float | None = None  # told to stand since (s)
        self._driven_rate = False  # the state's rate was learnt while the robot was driven
        self._stood = 0  # sightings taken standing since the last one taken while driven
        self._lateral_driven = False  # the lateral rate carries sightings taken while driven
        self._segment: list[tuple[float, float, float]] = []  # (t, z, x) while driven one way
        self._segment_cmd: tuple[int, bool] = (0, False)  # its direction, duty >= still
        self._segment_t0 = 0.0

    # --------------------------------------------------------------------------- metres

    def noise_m(self, z: float, x: float) -> tuple[float, float]:
        """A sighting's noise (m, one sd) in depth and laterally at (z, x), from the
        disparity's sigma_px: depth z^2 sigma / (f B); lateral x = B (uL - cx) / d with
        d = uL - uR, the two columns' errors apart and each of half the disparity's variance
        (u and d are not independent: x's sd is z sigma / f sqrt(0.5 - x/B + (x/B)^2)), at
        least lateral_floor_m."""
        g, sd = self.g, self.sigma_px
        depth = z * z * sd / (g.focal_px * g.baseline_m)
        r = x / g.baseline_m
        lateral = z * sd / g.focal_px * math.sqrt(0.5 - r + r * r)
        return depth, max(self.cfg.lateral_floor_m, lateral)

    def position(self, s: Sighting) -> tuple[float, float]:
        """(depth, lateral) in metres of a sighting."""
        z = self.g.depth_m(s.disparity)
        return z, self.g.baseline_m * (s.u - self.g.cx) / s.disparity

    # ---------------------------------------------------------------------- prediction

    def commanded(self, t: float, left: int, right: int) -> None:
        """The command sent at t (permille per wheel), in force until the next one."""
        self._account(t)
        self._cmd = (t, left, right)
        if left or right:
            self._stopped_since = None
        elif self._stopped_since is None:
            self._stopped_since = t
        self._run_down(t)

    def _run_down(self, t: float) -> None:
        """Told to stand for run_down_s, the depth rate a drive gave the state is spent: the
        state's depth moves on to where that run-down took it and its rate is dropped (kept,
        the rate ran on in the checks for seconds after a stop, the drive's own motion taken
        for a drift). The lateral rate stays: a push learnt while driven goes on (until
        rate_stood, the loop stands rather than ends the run on it: Servo._drift_stand)."""
        st = self.state
        if st is None or not self._driven_rate or self._stopped_since is None \
                or t - self._stopped_since < self.cfg.run_down_s:
            return
        st.z = self.predicted(t)[0]
        st.vz = 0.0
        self._driven_rate = False

    def _account(self, t: float) -> None:
        """Add the command in force since its time up to t to the travel allowed."""
        if self._cmd is None:
            return
        t0, left, right = self._cmd
        dt = max(0.0, t - t0)
        ahead, spin = abs(left + right) / 2, abs(left - right) / 2
        if ahead > spin:  # told to go (a spin in place goes nowhere)
            self._moving_s += dt
        # the most it can go: full speed at full duty, and unequal wheels' share of a spin
        self._travel_m += self.cfg.max_speed_mps * (ahead + self.cfg.spin_share * spin) \
            / 1000 * dt
        self._cmd = (t, left, right)

    def reach_m(self, t: float) -> float:
        """How far (m) the robot can have gone from its last accepted sighting by t: its
        motion then running down, what its commands since allow (and that motion running
        down), a drift, and the margin."""
        assert self.state is not None
        cfg = self.cfg
        self._account(t)
        dt = max(0.0, t - self.state.t)
        run_down = cfg.max_speed_mps * cfg.run_down_s if self._moving_s > 0 else 0.0
        speed = math.hypot(self.state.vz, self.state.vx)
        return (cfg.margin_m + self._travel_m + run_down + cfg.drift_mps * dt
                + speed * min(dt, cfg.run_down_s))

    def predicted(self, t: float) -> tuple[float, float]:
        """(depth, lateral) in metres expected at t: the last accepted position moved on at the
        filtered rate while the robot was told to go, and as its motion ran down."""
        assert self.state is not None
        s = self.state
        dt = min(max(0.0, t - s.t), self._moving_s + self.cfg.run_down_s)
        return s.z + s.vz * dt, s.x + s.vx * dt

    # --------------------------------------------------------------------------- gating

    def gate(self, s: Sighting) -> str:
        """Why the sighting cannot be the robot ("" if it can)."""
        if not (s.disparity > 0 and self.cfg.min_depth_m <= self.g.depth_m(s.disparity)
                <= self.cfg.max_depth_m):  # a skew correction across a jump makes anything
            return f"its disparity ({s.disparity:.1f} px) is no depth a robot can be at"
        z, x = self.position(s)
        if self._ratios and len(self._ratios) >= 5:
            ratio = float(np.median(self._ratios))
            if abs(s.radius_px / s.disparity - ratio) > self.cfg.size_tolerance * ratio:
                return (f"its size ({s.radius_px:.1f} px) does not fit its disparity "
                        f"({s.disparity:.1f} px)")
        if self.state is None:
            return ""
        zp, xp = self.predicted(s.t)
        noise = self.cfg.sigmas * self.sigma_px * z * z / (self.g.focal_px * self.g.baseline_m)
        reach = self.reach_m(s.t) + noise
        jump = math.hypot(z - zp, x - xp)
        if jump > reach:
            return f"{jump:.2f} m from where the robot can be (within {reach:.2f} m)"
        return ""

    def reject(self, t: float, why: str) -> None:
        """A sighting at t was outside the gate (why): it is not used."""
        self.rejected += 1
        self.why = why
        if self._outside_since is None:
            self._outside_since = t

    def outside_too_long(self, t: float) -> bool:
        """Whether the marker has been seen only outside the gate for outlier_stop_s."""
        return self._outside_since is not None and t - self._outside_since >= \
            self.cfg.outlier_stop_s

    def accept(self, s: Sighting) -> None:
        """Take a sighting that passed the gate into the state."""
        z, x = self.position(s)
        self._ratios.append(s.radius_px / s.disparity)
        del self._ratios[:-30]
        st = self.state
        if st is None:
            self.state = _State(s.t, z, x)
        else:
            dt = s.t - st.t
            zp, xp = self.predicted(s.t)
            cfg = self.cfg
            nz, nx = self.noise_m(z, x)
            standing = self._stopped_since is not None and \
                s.t - self._stopped_since >= cfg.run_down_s
            if not standing:
                self._driven_rate = self._lateral_driven = True
            self._stood = self._stood + 1 if standing else 0
            if self._stood >= cfg.stood_sightings:
                self._lateral_driven = False
            az, bz = gains(nz, cfg.stand_accel_mps2 if standing else cfg.accel_mps2, dt)
            ax, bx = gains(nx, cfg.stand_accel_mps2 if standing else cfg.lateral_accel_mps2, dt)
            rz, rx = z - zp, x - xp
            st.z, st.x = zp + az * rz, xp + ax * rx
            if 0 < dt <= 0.5:  # further apart, the rate is not known
                top = cfg.max_speed_mps
                st.vz = max(-top, min(top, st.vz + bz * rz / dt))
                st.vx = max(-top, min(top, st.vx + bx * rx / dt))
            else:
                st.vz = st.vx = 0.0
            st.t = s.t
        self._account(s.t)
        self._moving_s = self._travel_m = 0.0
        self.rejected = 0
        self.why = ""
        self._outside_since = None

    @property
    def rate_stood(self) -> bool:
        """Whether the lateral rate is one the robot showed standing: stood_sightings taken
        standing since the last taken while driven (or none taken driven since the state
        began). A rate learnt driven (a drive's curve, a spin's swinging card) runs on over a
        stop (_run_down) and may be no push at all (seed 17: 5 of 7 false "drifting unseen"
        stops)."""
        return not self._lateral_driven

    def forget(self) -> None:
        """Drop the state (a re-acquisition): the next sighting is taken as it comes."""
        self.state = None
        self._ratios.clear()
        self._outside_since = None
        self._driven_rate = self._lateral_driven = False
        self._stood = 0
        self._segment.clear()

    # ---------------------------------------------------------------------- motion check

    def motion(self, t: float, left: int, right: int, facing_away: bool,
               accepted: bool) -> str:
        """Check the motion under the command (left, right) in force at t: "against" when the
        depth moved against the commanded direction, "still" when driven without moving, else
        "". accepted: the frame's sighting was accepted (the state is this frame's)."""
        straight = left * right > 0 and abs(left - right) < abs(left + right)
        sign = (1 if left > 0 else -1) * (1 if facing_away else -1) if straight else 0
        duty = min(abs(left), abs(right)) if straight else 0
        key = (sign, duty >= self.cfg.still_duty)
        if sign == 0 or key != self._segment_cmd:
            self._segment.clear()
            self._segment_cmd = key
            self._segment_t0 = t
        if sign == 0 or not accepted or self.state is None:
            return ""
        if t - self._segment_t0 < self.cfg.settle_s:
            return ""
        self._segment.append((t, self.state.z, self.state.x))
        seg = self._segment
        if len(seg) < 10:
            return ""
        # the median of the last five against the first five's: one wild sighting decides
        # nothing; the move must be beyond three of a sighting's noise too
        z0, z1 = (float(np.median([p[1] for p in part])) for part in (seg[:5], seg[-5:]))
        dz = z1 - z0
        noise = 3 * self.sigma_px * z1 * z1 / (self.g.focal_px * self.g.baseline_m)
        if dz * sign < -max(self.cfg.against_m, noise):
            self._segment.clear()
            return AGAINST
        if key[1] and seg[-1][0] - seg[0][0] >= self.cfg.still_s:
            dx = max(p[2] for p in seg) - min(p[2] for p in seg)
            if abs(dz) < self.cfg.still_m and dx < self.cfg.still_m:
                self._segment.clear()
                return STILL
        return ""


def gains(noise_m: float, accel_mps2: float, dt: float) -> tuple[float, float]:
    """The position and rate gains (alpha, beta) of the steady-state Kalman filter of a constant
    rate on one axis: sightings dt apart (s) with noise_m (m, one sd), the motion's unmodelled
    acceleration accel_mps2 (m/s^2, one sd). Kalata's tracking index lam = accel dt^2 / noise;
    r = (4 + lam - sqrt(8 lam + lam^2)) / 4; alpha = 1 - r^2, beta = 2 (1 - r)^2. Noisy
    sightings (lam small) are smoothed; precise ones followed (alpha toward 1). dt <= 0: the
    sighting is taken as it is (alpha 1, no rate)."""
    if dt <= 0:
        return 1.0, 0.0
    lam = accel_mps2 * dt * dt / max(noise_m, 1e-9)
    r = (4 + lam - math.sqrt(8 * lam + lam * lam)) / 4
    return 1 - r * r, 2 * (1 - r) ** 2
