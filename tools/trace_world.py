"""The trace tools' one hook into a simulated trial: its world kept where the tool reads the truth.

The tools (tools/trace_*.py) run a trial through host.sim.trials.run_trial with some of the
servo's methods wrapped; each wrapper reads the world's truth (the robot's pose, the boxes) from
st["w"], which keep_world sets as every simulation opens."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from host.sim import trials as T


def keep_world(st: dict[str, Any]) -> None:
    """From now on every trial's simulation stores its world in st["w"] while it runs."""
    orig = T.simulation  # type: ignore[attr-defined]

    @contextmanager
    def simulation(*a: Any, **k: Any) -> Iterator[Any]:
        with orig(*a, **k) as sim:
            st["w"] = sim.world
            yield sim

    T.simulation = simulation  # type: ignore[attr-defined]
