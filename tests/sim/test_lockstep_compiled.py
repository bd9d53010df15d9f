"""The compiled millisecond (host.emulator.fast_ms, issue 25) against SimSource's loop in
Python: the same robot state to the last bit, the same motor outputs waiting out their latency,
the same bytes on the line at the same times and the same replies, at every frame of a run with
motor faults (slip drawn every millisecond), the board's ramp (its outputs change every
millisecond while it ramps), line faults and every kind of scene event."""

from __future__ import annotations

import dataclasses
import random
from typing import Any

import pytest

from host.emulator import fast_ms
from host.emulator.emulator import Emulator, Faults
from host.emulator.lockstep import LockstepLine
from host.link.client import RobotLink
from host.sim.source import SimSource
from host.sim.world import Box, World
from tests.sim.test_lockstep_native import MOTOR
from tests.sim.test_lockstep_speedup import EVENTS


def _pending(src: SimSource) -> tuple[object, ...]:
    """The motor outputs waiting out their latency, wherever they are kept."""
    out = list(src._pending)
    fast = src._fast
    if fast is not None:
        s = fast.s
        for j in range(s.pend_len):
            i = (s.pend_head + j) % fast_ms.PENDING
            out.append((s.pend_due[i], (s.pend_m[i][0], s.pend_m[i][1])))
    return tuple(out)


def _run(frames: int) -> list[tuple[Any, ...]]:
    world = World.for_size(160, 120, seed=4, motor_faults=MOTOR,
                           boxes=(Box(1.3, -0.3, 0.2, 0.4), Box(2.2, 0.4, 0.9, 0.5)))
    world.robot.z_m = 2.0
    emu = Emulator(Faults(drop=0.03, corrupt=0.02, delay_ms=2.5, seed=9))
    src = SimSource(world, emu, fps=30.0, reference_frames=2, events=EVENTS,
                    latency_ms=MOTOR.latency_ms, seed=4)
    line = LockstepLine(emu, src.run_ms, lambda: src.now_ms, src.run_until_tx)
    states = []
    with RobotLink(line, retries=8, reply_timeout_s=0.1, rng=random.Random(5)) as link:
        link.set_config(400, 250)  # a ramp: the board's outputs change every millisecond
        for k in range(frames):
            frame = src.read()
            assert frame is not None
            duty = 0 if k % 7 == 3 else (250 + 37 * k) % 700 - (400 if k % 5 == 4 else 0)
            link.drive(duty, duty - 90 * (k % 3))
            w = world
            states.append((src.now_ms, w.t, dataclasses.astuple(w.robot), w.travelled_m,
                           w.boxes, w.people, w.traction, src._applied, src._queued,
                           _pending(src), tuple(src.log), emu.now_ms, emu._ticked_ms,
                           tuple(emu._sent), tuple(emu._inbound), tuple(emu._outbound),
                           emu.motors(), link.resends, link.unconfirmed, tuple(link.notes),
                           frame.left.tobytes(), frame.t_left, frame.t_right))
    return states


def test_compiled_millisecond_is_the_loop(monkeypatch: pytest.MonkeyPatch) -> None:
    if fast_ms.library() is None:
        pytest.skip("no gcc: the compiled millisecond is not built")
    ran = []
    compiled = SimSource._run_ms_compiled

    def counted(self: SimSource, *args: object) -> None:
        ran.append(1)
        compiled(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(SimSource, "_run_ms_compiled", counted)
    fast = _run(45)
    assert len(ran) > 100
    monkeypatch.setattr(fast_ms, "library", lambda: None)
    ran.clear()
    loop = _run(45)
    assert not ran
    for k, (a, b) in enumerate(zip(fast, loop, strict=True)):
        assert a == b, f"frame {k}"
    assert any(s[2][3] for s in fast)  # the wheels turned (v_left)
    assert any(len(s[9]) > 5 for s in fast)  # outputs queued while the board ramped
    assert fast[-1][17] > 0  # the line's faults made the link resend
