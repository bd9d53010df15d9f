"""The simulated clock's faster millisecond loop (SimSource.run_ms: the scene's events looked at
only when one is due, the motor outputs queued only when they change) steps the world exactly
as the loop before it did (looking every millisecond, queueing every output, kept here as the
reference): the same robot state to the last bit, the same scene and the same event log, at
every frame of a run full of events, with motor outputs that change at odd times."""

from __future__ import annotations

import dataclasses
import math

import pytest

from host.sim.faults import Event
from host.sim.source import SimSource, _first_ms
from host.sim.world import Box, World

EVENTS = (
    Event(0.1005, "occlude", fraction=0.4, duration_s=0.2333),
    Event(0.15, "walker", z_m=1.5, x_m=-0.6, speed_mps=0.9, duration_s=0.4001),
    Event(0.2, "lane-box", ahead_m=0.4, width_m=0.3, duration_s=0.3),
    Event(0.31, "move", index=0, z_m=1.1),
    Event(0.333, "flicker", fraction=0.2, hz=100.0, gap_ms=7.0, duration_s=0.25),
    Event(0.41, "freeze", sensor=1, duration_s=0.117),
    Event(0.45, "slip", traction=(0.5, 0.8), duration_s=0.2),
    Event(0.52, "knock", angle_deg=1.5),
    Event(0.6, "appear", box=(0.9, 0.2, 0.5, 0.3)),
    Event(0.61, "drop-burst", duration_s=0.1),
    Event(0.7, "decoy", x_m=0.4, z_m=1.6),
    Event(0.75, "facing", angle_deg=180.0),
    Event(0.8, "vanish", index=1),
    Event(0.85, "occlude", fraction=0.3, duration_s=0.0777),  # ends with nothing else due
)


class Board:
    """Motor outputs that change now and then (and sometimes to what they were), on its own
    millisecond clock."""

    def __init__(self) -> None:
        self.ms = 0

    def motors(self) -> tuple[int, int]:
        k = self.ms // 37 + (self.ms // 101) % 3
        return ((k * 173) % 900 - 300 if k % 4 else 0, (k * 251) % 800 - 250 if k % 5 else 0)

    def advance(self, ms: float) -> None:
        self.ms += int(ms)


class ReferenceSource(SimSource):
    """The loop as it was: events looked at and motor outputs queued every millisecond."""

    def run_ms(self, ms: int) -> None:
        for _ in range(ms):
            self._apply_events()
            self._pending.append((self.now_ms + int(round(self.latency_ms)), self.board.motors()))
            while self._pending and self._pending[0][0] <= self.now_ms:
                self._applied = self._pending.popleft()[1]
            self.world.step(0.001, *self._applied)
            self.board.advance(1)
            self.now_ms += 1


def _source(cls: type[SimSource], latency_ms: float) -> SimSource:
    world = World.for_size(160, 120, seed=4,
                           boxes=(Box(1.3, -0.3, 0.2, 0.4), Box(2.2, 0.4, 0.9, 0.5)))
    world.robot.z_m = 2.0
    return cls(world, Board(), fps=30.0, reference_frames=2, events=EVENTS,
               latency_ms=latency_ms, seed=4)


def _state(s: SimSource) -> tuple:
    w, r = s.world, s.world.robot
    return (s.now_ms, w.t, dataclasses.astuple(r), w.boxes, w.people, w.decoys, w.traction,
            w.travelled_m, s.renderer.pitch_deg, s.renderer.flicker, s.frozen, s.dropped,
            s._applied, tuple(s.log))


@pytest.mark.parametrize("latency_ms", [0.0, 83.4])
def test_same_steps_as_every_millisecond(latency_ms: float) -> None:
    fast, ref = _source(SimSource, latency_ms), _source(ReferenceSource, latency_ms)
    for _ in range(30):
        a, b = fast.read(), ref.read()
        assert _state(fast) == _state(ref)
        assert a is not None and b is not None
        assert (a.left == b.left).all() and (a.right == b.right).all()
        assert (a.t_left, a.t_right) == (b.t_left, b.t_right)
    fast.run_ms(17)  # and run_ms on its own, as the link's waits call it
    ref.run_ms(17)
    assert _state(fast) == _state(ref)
    assert len(fast.log) > len(EVENTS)  # the events and their ends all happened


@pytest.mark.parametrize("t_s", [0.0, 0.001, 0.1005, 0.3, 0.7, 1.0 / 3, 2.9999999, -1.0, 12.345])
def test_first_ms(t_s: float) -> None:
    n = _first_ms(t_s)
    assert n / 1000 >= t_s and (n - 1) / 1000 < t_s
    assert n == min(m for m in range(math.floor(t_s * 1000) - 2, math.ceil(t_s * 1000) + 3)
                    if m / 1000 >= t_s)
