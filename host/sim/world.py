"""The simulated world's state and physics: the Minoru's geometry, boxes at known depths, and
the robot, a differential drive with a two-sided marker card (rendering is host.sim.renderer).

World frame: the camera at the origin looking along +z (depth), x to the right, y up, its
optical centre height_m above the floor. Heading theta of the robot: 0 = facing away from the
camera (+z), positive turns to its right (+x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from host.camera.geometry import Geometry
from host.servo.marker import RING_RATIO
from host.sim.faults import MotorFaults


@dataclass(frozen=True)
class Box:
    """A box whose front face is at depth z_m, spanning x0..x1 and up to height_m."""

    z_m: float
    x0_m: float
    x1_m: float
    height_m: float


@dataclass(frozen=True)
class Motors:
    """Motor model: no motion below the dead zone, then linear to v_max, first-order lag."""

    v_max_mps: float = 0.35
    dead_zone: int = 120  # permille
    tau_s: float = 0.08
    wheelbase_m: float = 0.14

    def speed(self, duty: float) -> float:
        if abs(duty) <= self.dead_zone:
            return 0.0
        return math.copysign(self.v_max_mps * (abs(duty) - self.dead_zone)
                             / (1000 - self.dead_zone), duty)


@dataclass
class Robot:
    x_m: float = 0.0
    z_m: float = 1.5
    theta: float = 0.0
    v_left: float = 0.0  # wheel speeds, m/s
    v_right: float = 0.0
    marker_height_m: float = 0.20
    marker_radius_m: float = 0.03  # the dark disc; the light ring reaches ring_ratio times it
    ring_ratio: float = RING_RATIO
    body_width_m: float = 0.16
    body_length_m: float = 0.16  # along its heading; the body is this rectangle, centred at x, z
    body_height_m: float = 0.12
    marker_hidden: bool = False  # something between the camera and the card (tests)
    occlusion: float = 0.0  # fraction of the card's width hidden from its left edge

    def half_extent(self) -> tuple[float, float]:
        """Half the body's extent across x and along z with its heading (m): the rectangle
        body_width_m across and body_length_m long, turned by theta."""
        c, s = abs(math.cos(self.theta)), abs(math.sin(self.theta))
        return (c * self.body_width_m / 2 + s * self.body_length_m / 2,
                s * self.body_width_m / 2 + c * self.body_length_m / 2)


@dataclass(frozen=True)
class Person:
    """Someone standing or walking in the scene: a textured upright slab facing the camera."""

    x_m: float
    z_m: float
    width_m: float = 0.45
    height_m: float = 1.75


@dataclass
class World:
    geometry: Geometry = field(default_factory=lambda: Geometry.minoru_default(320, 240))
    size: tuple[int, int] = (320, 240)
    height_m: float = 0.25  # camera above the floor
    wall_z_m: float = 3.2
    boxes: tuple[Box, ...] = (Box(1.2, -0.50, -0.18, 0.38), Box(1.8, 0.22, 0.55, 0.30),
                              Box(2.4, 0.60, 0.95, 0.55))
    robot: Robot = field(default_factory=Robot)
    motors: Motors = field(default_factory=Motors)
    motor_faults: MotorFaults = field(default_factory=MotorFaults)
    seed: int = 0
    target_index: int | None = None  # the box the servo should end at (None: the nearest)
    people: tuple[Person, ...] = ()
    decoys: tuple[Robot, ...] = ()  # other robot-like bodies with the same marker, standing
    traction: tuple[float, float] = (1.0, 1.0)  # each wheel's speed kept on this floor

    def __post_init__(self) -> None:
        self.rng = np.random.default_rng(self.seed + 7919)
        self.t = 0.0
        self.travelled_m = 0.0

    @classmethod
    def for_size(cls, width: int, height: int, **kw: Any) -> World:
        return cls(Geometry.minoru_default(width, height), (width, height), **kw)

    def nearest_box(self) -> Box:
        return min(self.boxes, key=lambda b: b.z_m)

    def project(self, x: float, y: float, z: float) -> tuple[float, float]:
        """Left-image pixel of a world point (y up, relative to the floor)."""
        g = self.geometry
        return g.cx + g.focal_px * x / z, g.cy + g.focal_px * (self.height_m - y) / z

    def marker_truth(self, robot: Robot | None = None) -> tuple[float, float, float]:
        """(left column, row, disparity) of the marker centre (of `robot`, default the
        servo's), exactly."""
        r = robot or self.robot
        u, v = self.project(r.x_m, r.marker_height_m, r.z_m)
        return u, v, self.geometry.focal_px * self.geometry.baseline_m / r.z_m

    def bumped_into(self) -> str:
        """What the robot's body (body_width_m wide) overlaps, besides boxes: "a person" (a
        slab 10 cm deep), "another robot" or "" (a judge's truth; boxes are the trials')."""
        r = self.robot
        for p in self.people:
            if abs(r.z_m - p.z_m) < 0.1 and abs(r.x_m - p.x_m) < (p.width_m + r.body_width_m) / 2:
                return "a person"
        return "another robot" if self.decoy_touched() is not None else ""

    def decoy_touched(self) -> Robot | None:
        """The look-alike robot the robot's body overlaps, or None."""
        r = self.robot
        return next((o for o in self.decoys
                     if abs(r.z_m - o.z_m) < 0.12 and abs(r.x_m - o.x_m) < r.body_width_m), None)

    def step(self, dt: float, duty_left: float, duty_right: float) -> None:
        """Move the robot for dt seconds under the duties its wheels get (permille), through
        the motor faults: gain and offset per wheel, battery sag with distance, wheel slip,
        and the floor's traction. (Called every simulated millisecond: one wheel at a time,
        without building lists, the same operations in the same order.)"""
        r, m, f = self.robot, self.motors, self.motor_faults
        self.t += dt
        a = 1.0 - math.exp(-dt / m.tau_s)
        supply = max(0.5, 1.0 - f.sag_per_m * self.travelled_m)
        # a wheel without duty: speed(0.0) is 0 and nothing slips (the robot holding)
        t_left = (self._wheel(duty_left, supply, f.gain[0], f.offset[0], self.traction[0])
                  if duty_left else 0.0 * f.gain[0] * self.traction[0])
        t_right = (self._wheel(duty_right, supply, f.gain[1], f.offset[1], self.traction[1])
                   if duty_right else 0.0 * f.gain[1] * self.traction[1])
        r.v_left += (t_left - r.v_left) * a
        r.v_right += (t_right - r.v_right) * a
        v = (r.v_left + r.v_right) / 2
        r.theta += (r.v_left - r.v_right) / m.wheelbase_m * dt
        r.x_m += (v * math.sin(r.theta) + f.push_mps) * dt
        r.z_m += v * math.cos(r.theta) * dt
        self.travelled_m += abs(v) * dt

    def _wheel(self, duty: float, supply: float, gain: float, offset: float,
               grip: float) -> float:
        """A wheel's target speed (m/s) under its duty, with its faults (slip drawn here)."""
        v = self.motors.speed(duty * supply - math.copysign(offset, duty) if duty else 0.0) \
            * gain * grip
        slip = self.motor_faults.slip
        if slip and v:
            v *= 1.0 - slip * float(self.rng.random())
        return v
