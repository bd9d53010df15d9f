"""The slow tiers of tests/conftest.py name files and tests that exist (a rename would
otherwise move a test back into the fast tier, or leave a stale entry, unseen)."""

from __future__ import annotations

import re
from types import SimpleNamespace

from tests.conftest import ROOT, SLOW_FILES, SLOW_TESTS, pytest_ignore_collect


def test_every_slow_file_exists() -> None:
    missing = [p for p in SLOW_FILES if not (ROOT / p).exists()]
    assert not missing, missing


def test_every_slow_test_names_a_test_in_its_file() -> None:
    missing = []
    for node in SLOW_TESTS:
        path, name = node.split("::")
        source = ROOT / path
        base = name.split("[")[0]
        if not source.is_file() or not re.search(rf"^def {base}\(", source.read_text(), re.M):
            missing.append(node)
    assert not missing, missing


def test_the_fast_tier_does_not_collect_the_slow_files_and_other_tiers_do() -> None:
    """-m "not slow" leaves the SLOW_FILES uncollected (not imported: every test in them is
    slow, so the fast tier selects the same tests); any other expression collects them."""

    def ignored(path: str, markexpr: str) -> bool:
        config = SimpleNamespace(getoption=lambda name: {"markexpr": markexpr}[name])
        return bool(pytest_ignore_collect(ROOT / path, config))

    for path in ("tests/sim/test_trials.py", "tests/record", "tests/tuning/test_ray_backend.py"):
        assert path in SLOW_FILES and ignored(path, "not slow") and ignored(path, " not  slow ")
        assert not any(ignored(path, m) for m in ("", "slow", "not slow or slow", "not fast"))
    fast_file_with_slow_tests = "tests/sim/test_recover_events.py"
    assert not ignored(fast_file_with_slow_tests, "not slow")
    assert not ignored("tests/test_tiers.py", "not slow")
