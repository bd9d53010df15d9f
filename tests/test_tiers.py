"""The slow tiers of tests/conftest.py name files and tests that exist (a rename would
otherwise move a test back into the fast tier, or leave a stale entry, unseen)."""

from __future__ import annotations

import re
import subprocess
import sys

from tests.conftest import ROOT, SLOW_FILES, SLOW_TESTS


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


def test_the_fast_tier_runs_the_same_tests_without_collecting_the_slow_files() -> None:
    """-m "not slow" leaves the SLOW_FILES uncollected (not imported); it selects the tests a
    collection that imports them and deselects their tests selects."""

    def collected(markexpr: str) -> tuple[list[str], int]:
        r = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p",
                            "no:cacheprovider", "-m", markexpr, "tests/tuning", "tests/view"],
                           cwd=ROOT, capture_output=True, text=True, timeout=300)
        total = re.search(r"^\d+/(\d+) tests collected", r.stdout, re.M)
        assert total, r.stdout[-1000:]
        return sorted(x for x in r.stdout.splitlines() if "::" in x), int(total.group(1))

    (fast, fast_total), (same, total) = collected("not slow"), collected("not slow or not slow")
    slow_files = [p for p in SLOW_FILES if p.startswith(("tests/tuning/", "tests/view/"))]
    assert slow_files and fast and fast == same
    assert fast_total < total  # the slow files' tests were never collected
