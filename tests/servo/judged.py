"""A closed-loop run stepped under the trials' judge: the tests' one way to say "never unsafe"."""

from __future__ import annotations

import math

from host.sim.run import SimRun
from host.sim.trials import _unsafe


class Judged:
    """Steps a simulation and judges each step as the trials do (trials._unsafe): the body
    touching the object, or driving on no valid measure for longer than the stale limit."""

    def __init__(self, sim: SimRun) -> None:
        self.sim = sim
        self.last_valid = sim.source.t  # the last frame time with a valid measure

    def step(self) -> str:
        """One step of the run; why it is unsafe now, or ""."""
        sim = self.sim
        sim.step()
        row = sim.servo.rows[-1]
        if math.isfinite(row.depth_m) and not row.reason:
            self.last_valid = row.t
        return _unsafe(sim, self.last_valid, sim.servo.stale_s)
