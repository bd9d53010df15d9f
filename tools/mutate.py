"""Firmware mutation testing that cannot count a false kill: an unmutated control runs the tests
first and must pass; each mutant then runs the same tests from the same environment, and counts
as killed only by a test that fails an assertion about behaviour, three times running.

    python tools/mutate.py [--only NAME ...] [--tests PATH ...] [--table FILE] [--quick]

The mutants are firmware/atmega328/mutants.toml. Each copy of the tree (control and mutants)
gets a link to this checkout's .venv, so a test that runs .venv/bin/host finds it in the copy as
it does here. What counts (pytest's JUnit report, the failure's exception type):
  - a kill: a test's call fails with AssertionError, pytest's Failed (pytest.raises that did not
    raise, pytest.fail) or LinkError (the robot misbehaved on the wire), and fails again both
    times it is rerun alone (otherwise it is a flake: deselected, and the run goes on);
  - not a kill: an error in a fixture (a harness or firmware that does not build), a collection
    error, any other exception (FileNotFoundError, BuildFailed, CalledProcessError, ...): the test
    is deselected and the run goes on, and the report says so.
A mutant whose find text is not in its file exactly once is an error (exit 2), as is a control
that fails. expect = "equivalent" (with why = the argument) must survive, and so must expect =
"survives" (a race no test can hit yet: reported as a known survivor, not as equivalent); a mutant
that does not build is INVALID. --quick runs a mutant's killed_by tests first and the whole set
only when they do not kill it (a kill is a kill whatever else runs; a survivor has faced every
test the control passed). Exit 0 when every mutant met its expectation, 1 when one did not, 2 on
an error."""

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
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MUTANTS = ROOT / "firmware" / "atmega328" / "mutants.toml"
TESTS = ["tests/firmware", "tests/link", "tests/protocol", "tests/c"]
TIMEOUT_S = 1800
RERUNS = 2  # a kill must fail this many reruns alone as well
# tests of the set-up, not of the firmware's behaviour: a compiler error, the mutants file (which
# a mutant's own edit makes stale), the generated files being current (a mutant of a generated
# file is judged by what the firmware then does, not by the file differing from its spec)
NOT_BEHAVIOUR = ["tests/firmware/test_build_errors.py", "tests/firmware/test_mutants_file.py",
                 "tests/protocol/test_generated.py::test_generated_files_are_current"]
KILLING_EXCEPTIONS = {"AssertionError", "Failed", "LinkError"}


@dataclass
class Mutant:
    name: str
    property: str
    file: str
    find: str
    replace: str
    expect: str = "killed"
    why: str = ""
    killed_by: list[str] = field(default_factory=list)


def load(path: Path = MUTANTS, root: Path = ROOT) -> list[Mutant]:
    """Read and check the mutants; raises ValueError naming the first problem."""
    raw = tomllib.loads(path.read_text())
    out, names = [], set()
    for m in raw.get("mutant", []):
        mutant = Mutant(**m)
        if not re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", mutant.name) or mutant.name in names:
            raise ValueError(f"mutant {mutant.name!r}: name not kebab-case or used twice")
        names.add(mutant.name)
        if mutant.expect not in ("killed", "equivalent", "survives"):
            raise ValueError(f"mutant {mutant.name}: expect must be killed, equivalent or "
                             "survives")
        if mutant.expect != "killed" and not mutant.why.strip():
            raise ValueError(f"mutant {mutant.name}: a mutant expected to survive needs its "
                             "argument (why)")
        if mutant.find == mutant.replace:
            raise ValueError(f"mutant {mutant.name}: replace is the find text")
        text = (root / mutant.file).read_text()
        if text.count(mutant.find) != 1:
            raise ValueError(f"mutant {mutant.name}: find text occurs {text.count(mutant.find)}"
                             f" times in {mutant.file}, not once")
        out.append(mutant)
    return out


def snapshot(dest: Path) -> None:
    """The checkout's files (tracked and untracked, not ignored) as they are now: the control
    and every mutant are copies of this one snapshot, so an edit made while the run goes on
    reaches none of them."""
    files = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-co", "--exclude-standard"],
                           capture_output=True, text=True, check=True).stdout.split("\n")
    for rel in filter(None, files):
        src = ROOT / rel
        if src.is_file() and not src.is_symlink():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / rel)


BASE: Path | None = None  # the snapshot (main sets it)


def copy_tree(dest: Path) -> None:
    """A copy of the snapshot in dest/tree, a link to this checkout's .venv in it, and next to
    it a link to this checkout's ../shared (the PlatformIO snapshot, the data), as here."""
    assert BASE is not None
    shutil.copytree(BASE, dest / "tree", symlinks=True)
    (dest / "tree" / ".venv").symlink_to((ROOT / ".venv").resolve())
    if (ROOT.parent / "shared").exists():
        (dest / "shared").symlink_to((ROOT.parent / "shared").resolve())


@dataclass
class Outcome:
    test: str
    kind: str    # passed, skipped, kill, other-failure, error
    detail: str  # exception type, or the error's first line


def _nodeid(case: ET.Element) -> str:
    cls, name = case.get("classname", ""), case.get("name", "")
    parts = cls.split(".")
    # classname is the module path with dots, plus a class name for tests in a class
    for i in range(len(parts), 0, -1):
        path = "/".join(parts[:i]) + ".py"
        if (ROOT / path).exists():
            return "::".join([path, *parts[i:], name])
    return f"{cls}::{name}"


def _exception(failure: ET.Element) -> str:
    """The exception type of a failed test: pytest ends its report with "path:line: Type"."""
    for line in reversed((failure.text or "").strip().splitlines()):
        m = re.match(r"^\S+:\d+: ([\w.]+)$", line.strip())
        if m:
            return m.group(1).rsplit(".", 1)[-1]
    message = failure.get("message", "")
    if message.startswith("assert "):
        return "AssertionError"
    head = message.split(":", 1)[0].strip()
    return head.rsplit(".", 1)[-1] if re.fullmatch(r"[\w.]+", head) else head[:40]


def pytest_run(tree: Path, tests: list[str], deselect: list[str]) -> tuple[list[Outcome], str]:
    """Run pytest in tree, stopping at the first failure; the outcome of each test that ran."""
    report = tree / "junit.xml"
    report.unlink(missing_ok=True)
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider",
           f"--junitxml={report}", *tests,
           *(f"--deselect={t}" for t in [*NOT_BEHAVIOUR, *deselect])]
    env = {**os.environ, "PYTHONPATH": str(tree)}
    try:
        r = subprocess.run(cmd, cwd=tree, capture_output=True, text=True, timeout=TIMEOUT_S,
                           env=env)
    except subprocess.TimeoutExpired:
        return [Outcome("(pytest)", "error", f"timed out after {TIMEOUT_S} s")], ""
    if not report.exists():
        return [Outcome("(pytest)", "error", f"exit {r.returncode}: {r.stdout[-300:]}")], r.stdout
    out = []
    for case in ET.parse(report).iter("testcase"):
        test = _nodeid(case)
        failure, error, skipped = case.find("failure"), case.find("error"), case.find("skipped")
        if failure is not None:
            exc = _exception(failure)
            out.append(Outcome(test, "kill" if exc in KILLING_EXCEPTIONS else "other-failure",
                               exc))
        elif error is not None:
            out.append(Outcome(test, "error", error.get("message", "")[:120]))
        elif skipped is not None:
            out.append(Outcome(test, "skipped", skipped.get("message", "")[:120]))
        else:
            out.append(Outcome(test, "passed", ""))
    if r.returncode not in (0, 1, 5) and not any(o.kind != "passed" for o in out):
        out.append(Outcome("(pytest)", "error", f"exit {r.returncode}: {r.stdout[-300:]}"))
    return out, r.stdout


def _fails_alone(tree: Path, test: str) -> bool:
    outcomes, _ = pytest_run(tree, [test], [])
    return any(o.kind == "kill" for o in outcomes)


def find_kill(tree: Path, tests: list[str], notes: list[str],
              flaky: list[str] = ()) -> Outcome | None:
    """The first test that kills what is in tree, or None when every test passes there."""
    deselect: list[str] = list(flaky)
    while True:
        outcomes, _ = pytest_run(tree, tests, deselect)
        bad = next((o for o in outcomes if o.kind not in ("passed", "skipped")), None)
        if bad is None:
            return None
        if bad.kind == "kill":
            if all(_fails_alone(tree, bad.test) for _ in range(RERUNS)):
                return bad
            notes.append(f"flaky: {bad.test} ({bad.detail}) passed when rerun")
        else:
            notes.append(f"not a kill: {bad.test}: {bad.kind} {bad.detail}")
        if bad.test == "(pytest)":
            return None
        deselect.append(bad.test)


def control(tests: list[str]) -> tuple[list[Outcome], list[str], float]:
    """The unmutated tree, copied as each mutant is: every test must pass. A test that fails
    and then passes twice alone is flaky here: it is named in the report and deselected for
    the mutants too (they run what the control passed); one that fails alone is an error.
    Returns the outcomes, the flaky tests and the seconds taken."""
    t0 = time.monotonic()
    flaky: list[str] = []
    with tempfile.TemporaryDirectory(prefix="mutant-control-") as d:
        copy_tree(Path(d))
        tree = Path(d) / "tree"
        while True:
            outcomes, stdout = pytest_run(tree, tests, flaky)
            bad = next((o for o in outcomes if o.kind in ("kill", "other-failure", "error")),
                       None)
            if bad is None:
                return outcomes, flaky, time.monotonic() - t0
            if bad.test == "(pytest)" or len(flaky) >= 3:
                raise RuntimeError(f"the unmutated control fails {bad.test}: {bad.kind} "
                                   f"{bad.detail}\n{stdout[-2000:]}")
            for _ in range(2):
                rerun, _ = pytest_run(tree, [bad.test], [])
                if not rerun or any(x.kind not in ("passed", "skipped") for x in rerun):
                    raise RuntimeError(f"the unmutated control fails {bad.test}: {bad.kind} "
                                       f"{bad.detail}\n{stdout[-2000:]}")
            flaky.append(bad.test)


def run_mutant(m: Mutant, tests: list[str], quick: bool,
               flaky: list[str] = ()) -> tuple[str, str, list[str], float]:
    """(result, killed by, notes, seconds); result: killed, survived or invalid."""
    t0 = time.monotonic()
    notes: list[str] = []
    with tempfile.TemporaryDirectory(prefix=f"mutant-{m.name}-") as d:
        copy_tree(Path(d))
        tree = Path(d) / "tree"
        target = tree / m.file
        target.write_text(target.read_text().replace(m.find, m.replace, 1))
        for extra in ([], ["TEST_HANG=1"]):
            b = subprocess.run(["make", "-s", "-C", str(tree / "firmware" / "atmega328"), *extra],
                               capture_output=True, text=True)
            if b.returncode:  # a mutant that does not compile proves nothing about the tests
                return "invalid", "the mutant does not build", [b.stderr[-300:]], \
                    time.monotonic() - t0
        kill = None
        if quick and m.killed_by:
            kill = find_kill(tree, m.killed_by, notes, flaky)
        if kill is None:
            kill = find_kill(tree, tests, notes, flaky)
    secs = time.monotonic() - t0
    if kill is None:
        return "survived", "", notes, secs
    return "killed", f"{kill.test} ({kill.detail})", notes, secs


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", default=None, help="run only these mutants")
    ap.add_argument("--tests", nargs="*", default=None, help=f"test paths (default {TESTS})")
    ap.add_argument("--quick", action="store_true",
                    help="try each mutant's killed_by tests first")
    ap.add_argument("--table", type=Path, help="also write the report (markdown) here")
    args = ap.parse_args(argv)
    try:
        mutants = load()
    except (ValueError, TypeError, OSError) as e:
        print(f"mutate: {e}", file=sys.stderr)
        return 2
    if args.only:
        unknown = set(args.only) - {m.name for m in mutants}
        if unknown:
            print(f"mutate: no mutant named {sorted(unknown)[0]}", file=sys.stderr)
            return 2
        mutants = [m for m in mutants if m.name in args.only]
    tests = args.tests or TESTS
    with tempfile.TemporaryDirectory(prefix="mutant-base-") as base:
        global BASE
        BASE = Path(base)
        snapshot(BASE)
        try:
            mutants = load(root=BASE) if not args.only else [
                m for m in load(root=BASE) if m.name in args.only]
        except ValueError as e:
            print(f"mutate: {e}", file=sys.stderr)
            return 2
        return _run(mutants, tests, args)


def _run(mutants: list[Mutant], tests: list[str], args: argparse.Namespace) -> int:
    try:
        outcomes, flaky, secs = control(tests)
    except RuntimeError as e:
        print(f"mutate: {e}", file=sys.stderr)
        return 2
    passed = sum(o.kind == "passed" for o in outcomes)
    skipped = [o for o in outcomes if o.kind == "skipped"]
    head = (f"control (unmutated copy, same tests {' '.join(tests)}): {passed} passed, "
            f"{len(skipped)} skipped, {secs:.0f} s")
    for t in flaky:
        head += f"\n  flaky in the control (failed once, passed twice alone; not run): {t}"
    for o in skipped:
        head += f"\n  skipped {o.test}: {o.detail}"
    print(head, flush=True)
    rows = ["| mutant | property | result | killed by | s |", "|---|---|---|---|---|"]
    bad = 0
    for m in mutants:
        result, by, notes, secs = run_mutant(m, tests, args.quick, flaky)
        if m.expect == "equivalent":
            ok = result == "survived"
            shown = "equivalent (survived)" if ok else f"NOT EQUIVALENT: {result}"
            by = by or m.why.strip().split("\n")[0][:100]
        elif m.expect == "survives":  # argued in the file: not equivalent, no test hits it yet
            ok = result == "survived"
            shown = ("SURVIVED (known, not equivalent)" if ok
                     else f"{result}, not the known survivor")
            by = by or " ".join(m.why.split())[:100]
        else:
            ok = result == "killed"
            shown = {"killed": "killed", "survived": "SURVIVED", "invalid": "INVALID"}[result]
        bad += not ok
        rows.append(f"| {m.name} | {m.property} | {shown} | {by} | {secs:.0f} |")
        print(rows[-1], flush=True)
        for n in notes:
            print(f"    {n}", flush=True)
    killed = sum(" | killed | " in r for r in rows)
    table = "\n".join(rows)
    summary = (f"{len(mutants)} mutants: {killed} killed, "
               f"{sum('equivalent (survived)' in r for r in rows)} equivalent, "
               f"{sum('(known, not equivalent)' in r for r in rows)} known survivors "
               f"(not equivalent), {bad} not as expected")
    print(f"\n{head}\n\n{table}\n\n{summary}")
    if args.table:
        args.table.write_text(f"{head}\n\n{table}\n\n{summary}\n")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
