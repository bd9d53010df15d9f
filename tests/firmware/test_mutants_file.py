"""firmware/atmega328/mutants.toml stays applicable: every mutant's text occurs exactly once in
its file, names are unique kebab-case, and the list covers the issue's safety properties."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import mutate  # noqa: E402


def test_every_mutant_applies_to_the_current_sources() -> None:
    mutants = mutate.load()  # raises ValueError naming a stale or ambiguous mutant
    names = {m.name for m in mutants}
    for required in ("link-loss-off", "crc-check-off", "watchdog-off", "duplicate-check-off",
                     "ramp-off", "pwm-disconnected", "pwm-prescaler-8", "enable-pins-not-outputs",
                     "init3-wdt-disable-removed", "mcusr-not-cleared", "rx-overflow-check-removed",
                     "accel-limit-ignored"):
        assert required in names
    assert all(m.property for m in mutants)
