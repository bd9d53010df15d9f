"""Fault models of the simulated world, as hardware shows them; every one seedable.

Motors: gain and duty offset per wheel, wheel slip, battery sag with distance, a sideways push,
actuation latency. Cameras: exposure gain and bias and white balance per sensor, left/right
capture skew, motion blur, frame drops, sensor noise, lens distortion. Scene: objects that move,
appear and vanish, the marker partly occluded. Link: the emulator's Faults.

Hazards (the named events of issue 23, drawn by random_faults from a stream of their own, so the
faults above stay what they were for a seed): the robot placed facing the camera or side-on, a
box put down in its lane, a knocked camera, a frozen sensor, mains flicker on rolling shutters,
the marker half hidden behind the object, a person walking through the view, wheel slip on a
smooth floor, a burst of dropped frames, a second robot-like marker in the scene.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from host.emulator.emulator import Faults as LinkFaults


@dataclass(frozen=True)
class MotorFaults:
    gain: tuple[float, float] = (1.0, 1.0)  # speed factor of the left and right wheel
    offset: tuple[float, float] = (0.0, 0.0)  # permille of duty lost to extra friction
    slip: float = 0.0  # each ms a wheel loses up to this fraction of its speed
    sag_per_m: float = 0.0  # supply (so duty) lost per metre driven, fraction
    latency_ms: float = 0.0  # from the firmware's output to the wheels
    push_mps: float = 0.0  # sideways push on the robot (+x), m/s


@dataclass(frozen=True)
class CameraFaults:
    gain: tuple[float, float] = (1.0, 1.0)  # exposure x gain of the left and right sensor
    bias: tuple[float, float] = (0.0, 0.0)  # black level, grey levels
    white: tuple[tuple[float, float, float], ...] = ()  # BGR gains per sensor; () = grey images
    skew_ms: float = 0.0  # the right sensor captures this much after the left
    exposure_ms: float = 0.0  # motion blur over the exposure; 0 = none
    drop: float = 0.0  # probability that a frame never arrives
    noise: float = 2.0  # sensor noise, grey levels (sigma)
    distortion: tuple[float, float] = (0.0, 0.0)  # radial k1 of the left and right lens
    # (with distortion the simulated camera is calibrated on rendered chessboards first)


@dataclass(frozen=True)
class Event:
    """Something that happens in the world at t_s (simulated seconds). Its kind names it:

    move        box `index` moves to depth z_m
    appear      `box` appears
    vanish      box `index` is taken away
    occlude     a post hides `fraction` of the marker card's width until t_s + duration_s
    facing      the robot is placed with heading angle_deg (0 away from the camera, 180 facing
                it, 90 side-on: its card edge-on)
    lane-box    a box width_m wide appears ahead_m ahead of the robot's centre, across its
                lane (ahead: the way it moves, or faces when standing); taken away after
                duration_s (0: it stays)
    knock       the camera rig is pitched by angle_deg more (positive: tilted down) and stays so
    freeze      sensor `sensor` (0 left, 1 right) repeats its last image for duration_s; its
                timestamps advance with the other's (stamps=True) or repeat too (False)
    flicker     the light varies by +-fraction at hz, read row by row by rolling shutters whose
                two captures are gap_ms apart, for duration_s (0: to the end)
    behind      the robot is placed behind box `index` at depth z_m (or where it is, if
                farther), so the box's edge hides `fraction` of its card's ring
    walker      a person (0.45 m wide) walks across the view at depth z_m from x_m at
                speed_mps (signed, +x to the right) for duration_s
    slip        a smooth floor: each wheel keeps `traction` of its speed for duration_s
    drop-burst  no frame arrives for duration_s
    decoy       a second robot-like body with the same marker stands at (x_m, z_m)
    """

    t_s: float
    kind: str
    index: int = 0
    z_m: float = 0.0
    box: tuple[float, float, float, float] | None = None  # z, x0, x1, height
    fraction: float = 0.0
    duration_s: float = 0.0
    angle_deg: float = 0.0
    ahead_m: float = 0.0
    width_m: float = 0.0
    sensor: int = 0
    stamps: bool = True
    hz: float = 100.0
    gap_ms: float = 0.0
    x_m: float = 0.0
    speed_mps: float = 0.0
    traction: tuple[float, float] = (1.0, 1.0)

    def describe(self) -> str:
        """The event's name with its size, for a trial's fault description."""
        if self.kind == "facing":
            return f"facing {self.angle_deg:.0f} deg"
        if self.kind == "lane-box":
            return f"lane-box {self.ahead_m * 100:.0f} cm ahead, {self.width_m * 100:.0f} cm wide"
        if self.kind == "knock":
            return f"knock {self.angle_deg:+.1f} deg"
        if self.kind == "freeze":
            stamps = "stamps advance" if self.stamps else "stamps frozen"
            return f"freeze {('left', 'right')[self.sensor]} {self.duration_s:.1f} s {stamps}"
        if self.kind == "flicker":
            return f"flicker {self.fraction:.0%} {self.hz:.0f} Hz gap {self.gap_ms:.0f} ms"
        if self.kind == "behind":
            return f"behind {self.fraction:.0%} hidden"
        if self.kind in ("walker", "decoy"):
            return f"{self.kind} at {self.z_m:.2f} m"
        if self.kind == "slip":
            return f"slip {self.traction[0]:.2f}/{self.traction[1]:.2f} {self.duration_s:.1f} s"
        if self.kind == "drop-burst":
            return f"drop-burst {self.duration_s:.2f} s"
        return self.kind

HAZARDS = ("facing", "lane-box", "knock", "freeze", "flicker", "behind", "walker", "slip",
           "drop-burst", "decoy")


@dataclass(frozen=True)
class WorldFaults:
    motor: MotorFaults = field(default_factory=MotorFaults)
    camera: CameraFaults = field(default_factory=CameraFaults)
    events: tuple[Event, ...] = ()
    link: LinkFaults = field(default_factory=LinkFaults)


def _pair(rng: np.random.Generator, lo: float, hi: float) -> tuple[float, float]:
    return float(rng.uniform(lo, hi)), float(rng.uniform(lo, hi))


def random_hazards(rng: np.random.Generator, target_z: float, target_index: int = 0,
                   rate: float = 0.05) -> list[Event]:
    """The named events of issue 23, each drawn with probability `rate` (the robot hidden
    behind the object, which no servo can hold through, with rate / 5), each of random size."""
    events: list[Event] = []

    def sign() -> float:
        return float(rng.choice([-1.0, 1.0]))

    if rng.random() < rate:  # placed facing the camera, or side-on
        angle = float(rng.choice([180.0, 60.0, 90.0])) * sign() + float(rng.uniform(-5, 5))
        events.append(Event(0.0, "facing", angle_deg=angle))
    if rng.random() < rate:  # a box put down in its lane, taken away a few seconds later
        events.append(Event(float(rng.uniform(1.5, 6)), "lane-box",
                            ahead_m=float(rng.uniform(0.29, 0.6)),
                            width_m=float(rng.choice([0.3, 0.6])),
                            duration_s=float(rng.uniform(2, 6))))
    if rng.random() < rate:  # a cable tug or a knock pitches the rig
        events.append(Event(float(rng.uniform(1, 8)), "knock",
                            angle_deg=sign() * float(rng.uniform(1, 2))))
    if rng.random() < rate:  # one sensor stops delivering new images
        events.append(Event(float(rng.uniform(1, 8)), "freeze", sensor=int(rng.integers(2)),
                            stamps=bool(rng.random() < 0.5),
                            duration_s=float(rng.uniform(1, 3))))
    if rng.random() < rate:  # mains lighting on rolling shutters
        events.append(Event(float(rng.uniform(1, 8)), "flicker", fraction=0.2, hz=100.0,
                            gap_ms=float(rng.uniform(5, 15)),
                            duration_s=float(rng.uniform(2, 8))))
    if rng.random() < rate / 5:  # the card half behind the object's edge
        events.append(Event(0.0, "behind", target_index,
                            z_m=target_z + float(rng.uniform(0.3, 0.9)),
                            fraction=float(rng.uniform(0.4, 0.6))))
    if rng.random() < rate:  # someone walks through the view
        z, speed = float(rng.uniform(0.6, 2.8)), sign() * float(rng.uniform(0.8, 1.4))
        reach = 0.4 * z + 0.3  # just outside the view (half its width at z, and the body's)
        events.append(Event(float(rng.uniform(1, 8)), "walker", z_m=z,
                            x_m=-reach if speed > 0 else reach, speed_mps=speed,
                            duration_s=2 * reach / abs(speed)))
    if rng.random() < rate:  # a smooth patch of floor
        events.append(Event(float(rng.uniform(1, 8)), "slip",
                            traction=(float(rng.uniform(0.3, 0.8)), float(rng.uniform(0.3, 0.8))),
                            duration_s=float(rng.uniform(0.5, 3))))
    if rng.random() < rate:  # the USB bus loses a run of frames
        events.append(Event(float(rng.uniform(1, 8)), "drop-burst",
                            duration_s=float(rng.uniform(0.2, 1.0))))
    if rng.random() < rate:  # a second robot stands beside the lane, behind the target and
        # in front of the boxes on the right (the one at 1.8 m hides x / z of 0.12-0.31)
        z = float(rng.uniform(target_z + 0.15, 1.75))
        events.append(Event(0.0, "decoy", z_m=z, x_m=float(rng.uniform(0.17, 0.28)) * z))
    return events


def random_faults(rng: np.random.Generator, target_z: float, target_index: int = 0,
                  link: bool = True, vanish: float = 0.01, silent: float = 0.01,
                  hazards: float = 0.05) -> WorldFaults:
    """A faulty world as a trial meets it: every fault on, each of random size, and each of
    issue 23's hazards (random_hazards) with probability `hazards` (0: none). The hazards come
    from a stream spawned off rng, which leaves rng's own draws (the other faults, and what its
    caller draws next) as they were without them."""
    hazard_rng = rng.spawn(1)[0]
    motor = MotorFaults(gain=_pair(rng, 0.85, 1.15), offset=_pair(rng, 0.0, 40.0),
                        slip=float(rng.uniform(0.0, 0.15)), sag_per_m=float(rng.uniform(0, 0.05)),
                        latency_ms=float(rng.uniform(60, 120)),
                        push_mps=float(rng.uniform(-0.01, 0.01)))
    camera = CameraFaults(gain=_pair(rng, 0.8, 1.2), bias=_pair(rng, -15, 15),
                          white=tuple(_white(rng) for _ in range(2)),
                          skew_ms=float(rng.uniform(0, 33)), exposure_ms=float(rng.uniform(5, 30)),
                          drop=float(rng.uniform(0, 0.05)), noise=float(rng.uniform(1.5, 3.5)),
                          )
    events: list[Event] = []
    if rng.random() < 0.3:  # the target is pushed nearer or farther
        events.append(Event(float(rng.uniform(1, 8)), "move", target_index,
                            z_m=target_z + float(rng.choice([-1, 1]) * rng.uniform(0.08, 0.25))))
    if rng.random() < 0.2:  # a box appears behind the target
        z = float(rng.uniform(target_z + 0.4, 2.9))
        events.append(Event(float(rng.uniform(1, 8)), "appear", box=(z, 0.35, 0.6, 0.3)))
    if rng.random() < 0.3:  # someone walks between the camera and the card
        events.append(Event(float(rng.uniform(1, 8)), "occlude",
                            fraction=float(rng.uniform(0.15, 0.45)),
                            duration_s=float(rng.uniform(0.3, 1.5))))
    if rng.random() < vanish:
        events.append(Event(float(rng.uniform(2, 8)), "vanish", target_index))
    if hazards:
        events += random_hazards(hazard_rng, target_z, target_index, hazards)
    link_faults = LinkFaults()
    if link:
        link_faults = LinkFaults(drop=float(rng.uniform(0, 0.003)),
                                 corrupt=float(rng.uniform(0, 0.003)),
                                 delay_ms=float(rng.uniform(0, 15)),
                                 silent_after_ms=(float(rng.uniform(3000, 8000))
                                                  if rng.random() < silent else None),
                                 seed=int(rng.integers(1 << 30)))
    return WorldFaults(motor, camera, tuple(events), link_faults)


def _white(rng: np.random.Generator) -> tuple[float, float, float]:
    """One sensor's white balance: a BGR gain each, 0.85-1.15."""
    b, g, r = (float(x) for x in rng.uniform(0.85, 1.15, 3))
    return b, g, r
