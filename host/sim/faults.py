"""Fault models of the simulated world, as hardware shows them; every one seedable.

Motors: gain and duty offset per wheel, wheel slip, battery sag with distance, a sideways push,
actuation latency. Cameras: exposure gain and bias and white balance per sensor, left/right
capture skew, motion blur, frame drops, sensor noise, lens distortion. Scene: objects that move,
appear and vanish, the marker partly occluded. Link: the emulator's Faults.
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
    """At t_s: "move" box `index` to depth z_m, "appear" `box`, or "vanish" box `index`;
    "occlude" hides `fraction` of the marker card's width until t_s + duration_s."""

    t_s: float
    kind: str
    index: int = 0
    z_m: float = 0.0
    box: tuple[float, float, float, float] | None = None  # z, x0, x1, height
    fraction: float = 0.0
    duration_s: float = 0.0


@dataclass(frozen=True)
class WorldFaults:
    motor: MotorFaults = field(default_factory=MotorFaults)
    camera: CameraFaults = field(default_factory=CameraFaults)
    events: tuple[Event, ...] = ()
    link: LinkFaults = field(default_factory=LinkFaults)


def _pair(rng: np.random.Generator, lo: float, hi: float) -> tuple[float, float]:
    return float(rng.uniform(lo, hi)), float(rng.uniform(lo, hi))


def random_faults(rng: np.random.Generator, target_z: float, target_index: int = 0,
                  link: bool = True, vanish: float = 0.01, silent: float = 0.01) -> WorldFaults:
    """A faulty world as a trial meets it: every fault on, each of random size."""
    motor = MotorFaults(gain=_pair(rng, 0.85, 1.15), offset=_pair(rng, 0.0, 40.0),
                        slip=float(rng.uniform(0.0, 0.15)), sag_per_m=float(rng.uniform(0, 0.05)),
                        latency_ms=float(rng.uniform(60, 120)),
                        push_mps=float(rng.uniform(-0.01, 0.01)))
    camera = CameraFaults(gain=_pair(rng, 0.8, 1.2), bias=_pair(rng, -15, 15),
                          white=tuple(tuple(float(g) for g in rng.uniform(0.85, 1.15, 3))
                                      for _ in range(2)),
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
    link_faults = LinkFaults()
    if link:
        link_faults = LinkFaults(drop=float(rng.uniform(0, 0.003)),
                                 corrupt=float(rng.uniform(0, 0.003)),
                                 delay_ms=float(rng.uniform(0, 15)),
                                 silent_after_ms=(float(rng.uniform(3000, 8000))
                                                  if rng.random() < silent else None),
                                 seed=int(rng.integers(1 << 30)))
    return WorldFaults(motor, camera, tuple(events), link_faults)
