"""The native core's millisecond written out in one loop (SimSource._run_ms_native, and the
link's wait for a reply in one call, SimSource.run_until_tx) steps the world, the board and the
line exactly as World.step and Emulator.advance(1) called every millisecond do, the link
waiting a millisecond at a time (kept here as the reference): the same robot state to the last
bit, the same bytes on the line at the same times, the same replies, at every frame of a run
with motor faults (slip drawn every millisecond, push, sag, gains, offsets), line faults and
scene events."""

from __future__ import annotations

import dataclasses
import random

from host.emulator.emulator import Emulator, Faults, Lockstep
from host.emulator.lockstep import LockstepLine
from host.link.client import RobotLink
from host.sim.faults import MotorFaults
from host.sim.source import SimSource
from host.sim.world import Box, World
from tests.sim.test_lockstep_speedup import EVENTS

MOTOR = MotorFaults(gain=(0.93, 1.07), offset=(31.5, 12.25), slip=0.08, sag_per_m=0.02,
                    latency_ms=71.3, push_mps=0.004)


class ReferenceSource(SimSource):
    """The loop through World.step and Emulator.advance(1), a call each a millisecond."""

    def _native(self) -> Lockstep | None:
        return None


def _run(cls: type[SimSource], fast_wait: bool) -> list[tuple]:
    world = World.for_size(160, 120, seed=4, motor_faults=MOTOR,
                           boxes=(Box(1.3, -0.3, 0.2, 0.4), Box(2.2, 0.4, 0.9, 0.5)))
    world.robot.z_m = 2.0
    emu = Emulator(Faults(drop=0.03, corrupt=0.02, delay_ms=2.5, seed=9))
    src = cls(world, emu, fps=30.0, reference_frames=2, events=EVENTS,
              latency_ms=MOTOR.latency_ms, seed=4)
    line = LockstepLine(emu, src.run_ms, lambda: src.now_ms,
                        src.run_until_tx if fast_wait else None)
    states = []
    with RobotLink(line, retries=8, reply_timeout_s=0.1, rng=random.Random(5)) as link:
        for k in range(40):
            frame = src.read()
            assert frame is not None
            duty = 0 if k % 7 == 3 else (250 + 37 * k) % 700 - (400 if k % 5 == 4 else 0)
            link.drive(duty, duty - 90 * (k % 3))
            w = world
            states.append((src.now_ms, w.t, dataclasses.astuple(w.robot), w.travelled_m,
                           w.boxes, w.people, w.traction, src._applied, src._queued,
                           tuple(src.log), emu.now_ms, tuple(emu._sent), emu.motors(),
                           link.resends, link.unconfirmed, tuple(link.notes),
                           frame.left.tobytes(), frame.t_left, frame.t_right))
    return states


def test_native_millisecond_is_the_reference() -> None:
    fast, ref = _run(SimSource, True), _run(ReferenceSource, False)
    assert len(fast) == len(ref)
    for k, (a, b) in enumerate(zip(fast, ref, strict=True)):
        assert a == b, f"frame {k}"
    assert any(s[2][3] for s in fast)  # the wheels turned (v_left)
    assert fast[-1][13] > 0  # the line's faults made the link resend
