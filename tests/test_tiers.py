"""The slow tiers of tests/conftest.py name files and tests that exist (a rename would
otherwise move a test back into the fast tier, or leave a stale entry, unseen)."""

from __future__ import annotations

import re

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
