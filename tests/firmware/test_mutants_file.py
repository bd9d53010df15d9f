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
                     "accel-limit-ignored",
                     # issue 29: every rule its review found unguarded
                     "link-loss-one-tick-early", "guard-only-flags-the-trip",
                     "set-config-refreshes-link", "duplicate-does-not-refresh-link",
                     "last-command-kept-after-link-loss", "no-catch-up-before-a-frame",
                     "nack-refill-doubled", "stop-starts-no-coast",
                     "reverse-to-forward-not-through-zero", "right-motor-never-coasts",
                     "reverse-leg-unramped", "link-timeout-min-1", "link-timeout-max-65534",
                     "record-magic-unchecked", "record-complement-unchecked",
                     "stale-watchdog-mark-kept", "duplicate-ignores-id",
                     "duplicate-compares-first-byte", "hello-keeps-last-command",
                     "rx-bytes-per-pass-unbounded", "rx-ring-16", "board-lock-without-cli",
                     "motor-output-not-atomic", "torn-32-bit-clock-read", "comment-only"):
        assert required in names
    assert all(m.property for m in mutants)
    # the runner's own check: a mutant that changes only a comment is expected to survive
    assert next(m for m in mutants if m.name == "comment-only").expect == "equivalent"
    assert all(m.why.strip() for m in mutants if m.expect != "killed")


def test_a_mutant_whose_text_is_not_found_is_an_error(tmp_path: Path) -> None:
    (tmp_path / "f.c").write_text("int x;\n")
    (tmp_path / "m.toml").write_text('[[mutant]]\nname = "gone"\nproperty = "p"\n'
                                     'file = "f.c"\nfind = "int y;"\nreplace = "int z;"\n')
    try:
        mutate.load(tmp_path / "m.toml", root=tmp_path)
    except ValueError as e:
        assert "occurs 0 times" in str(e)
    else:
        raise AssertionError("a mutant whose text is missing was accepted")
