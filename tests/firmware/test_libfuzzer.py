"""A short libFuzzer run (ASan + UBSan) of the frame parser and of the firmware core on a checking
mock board (tools/fuzz.py, tests/c/fuzz_*.c), from the committed corpus: any finding fails. The
longer run is `make fuzz`, part of `make bench`. Skips only when clang is not installed."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import fuzz  # noqa: E402

SECONDS = 4


@pytest.mark.parametrize("target", sorted(fuzz.TARGETS))
def test_a_short_fuzz_run_finds_nothing(target, tmp_path) -> None:
    if shutil.which("clang") is None:
        pytest.skip("clang not found: install clang (make system-deps, as root)")
    r = fuzz.run(target, SECONDS, tmp_path)  # a target that does not build raises: a failure
    assert r.ok, f"{target}: {[str(f) for f in r.findings]}\n{r.log[-3000:]}"
    assert r.runs > 1000 and r.cov > 0


def test_every_committed_finding_still_passes(tmp_path) -> None:
    """Each input the fuzzer once failed on is in the corpus, and every run starts from it;
    this runs them alone, so a regression names its file."""
    if shutil.which("clang") is None:
        pytest.skip("clang not found")
    import subprocess

    for target in fuzz.TARGETS:
        corpus = fuzz.ROOT / "tests" / "c" / "corpus" / target
        files = sorted(p for p in corpus.glob("*") if p.is_file())
        if not files:
            continue
        exe = fuzz.build(target, tmp_path)
        for f in files:
            r = subprocess.run([str(exe), str(f)], capture_output=True, text=True, cwd=tmp_path)
            assert r.returncode == 0, f"{f.name}: {r.stderr[-2000:]}"
