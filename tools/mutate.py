"""Firmware mutation testing: apply each mutant of firmware/atmega328/mutants.toml to a copy of
the source tree, run the firmware, link and protocol tests there, and print the kill table.

    python tools/mutate.py [--only NAME ...] [--table FILE]

A mutant is killed when the tests fail (or, for one marked expect = "build-fails", when the
firmware does not build). Exit status 0 when every mutant is killed, 1 when one survived, 2 on
a bad mutants file."""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MUTANTS = ROOT / "firmware" / "atmega328" / "mutants.toml"
TESTS = ["tests/firmware", "tests/link", "tests/protocol"]
TIMEOUT_S = 900
# tests of the set-up (a git checkout, a compiler error, the mutants file itself, which a
# mutant's own edit makes stale), not of the firmware's behaviour
BUILD_SYSTEM_TESTS = ["tests/firmware/test_build_errors.py", "tests/firmware/test_mutants_file.py"]


@dataclass
class Mutant:
    name: str
    property: str
    file: str
    find: str
    replace: str
    expect: str = "tests-fail"


def load(path: Path = MUTANTS) -> list[Mutant]:
    """Read and check the mutants; raises ValueError naming the first problem."""
    raw = tomllib.loads(path.read_text())
    out, names = [], set()
    for m in raw.get("mutant", []):
        mutant = Mutant(**m)
        if not re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", mutant.name) or mutant.name in names:
            raise ValueError(f"mutant {mutant.name!r}: name not kebab-case or used twice")
        names.add(mutant.name)
        if mutant.expect not in ("tests-fail", "build-fails"):
            raise ValueError(f"mutant {mutant.name}: expect must be tests-fail or build-fails")
        text = (ROOT / mutant.file).read_text()
        if text.count(mutant.find) != 1:
            raise ValueError(f"mutant {mutant.name}: find text occurs {text.count(mutant.find)}"
                             f" times in {mutant.file}, not once")
        out.append(mutant)
    return out


def _copy_tree(dest: Path) -> None:
    files = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-co", "--exclude-standard"],
                           capture_output=True, text=True, check=True).stdout.split()
    for rel in files:
        src = ROOT / rel
        if src.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / rel)


def run_mutant(m: Mutant) -> tuple[bool, str, float]:
    """(killed, by what, seconds)."""
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory(prefix=f"mutant-{m.name}-") as d:
        tree = Path(d)
        _copy_tree(tree)
        target = tree / m.file
        target.write_text(target.read_text().replace(m.find, m.replace, 1))
        built = subprocess.run(["make", "-s", "-C", str(tree / "firmware" / "atmega328")],
                               capture_output=True, text=True).returncode == 0
        if m.expect == "build-fails":
            return not built, "the firmware does not build", time.monotonic() - t0
        if not built:  # a mutant that does not compile proves nothing about the tests
            return False, "INVALID: the mutant does not build", time.monotonic() - t0
        r = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider",
                            *TESTS, *(f"--deselect={t}" for t in BUILD_SYSTEM_TESTS)],
                           cwd=tree, capture_output=True, text=True, timeout=TIMEOUT_S,
                           env={**os.environ, "PYTHONPATH": str(tree)})
        failed = re.findall(r"^(?:FAILED|ERROR) (\S+)", r.stdout, re.M)
        killed = r.returncode not in (0, 5)
        return killed, (failed[0] if failed else f"pytest exit {r.returncode}"), \
            time.monotonic() - t0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", default=None, help="run only these mutants")
    ap.add_argument("--table", type=Path, help="also write the kill table (markdown) here")
    args = ap.parse_args(argv)
    try:
        mutants = load()
    except (ValueError, TypeError, OSError) as e:
        print(f"mutate: {e}", file=sys.stderr)
        return 2
    if args.only:
        mutants = [m for m in mutants if m.name in args.only]
    rows = ["| mutant | property | result | killed by | s |", "|---|---|---|---|---|"]
    survivors = 0
    for m in mutants:
        killed, by, secs = run_mutant(m)
        survivors += not killed
        rows.append(f"| {m.name} | {m.property} | {'killed' if killed else 'SURVIVED'} | "
                    f"{by} | {secs:.0f} |")
        print(rows[-1], flush=True)
    table = "\n".join(rows)
    print(f"\n{table}\n\n{len(mutants) - survivors} of {len(mutants)} mutants killed")
    if args.table:
        args.table.write_text(table + "\n")
    return 1 if survivors else 0


if __name__ == "__main__":
    sys.exit(main())
