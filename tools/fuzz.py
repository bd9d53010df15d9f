"""Build and run the libFuzzer targets (clang, ASan + UBSan) of the frame parser and the firmware
core: tests/c/fuzz_parser.c and tests/c/fuzz_core.c, from the committed corpus under tests/c/corpus
(the parser's also seeded with protocol/vectors.json).

    python tools/fuzz.py [--seconds S] [--only parser|core] [--out DIR] [--coverage]

Prints each target's figures (runs, edges covered, features, corpus) and exits 1 on a finding
(the input is kept under build/fuzz/<target>/ as crash-*, to become a corpus file and a test),
2 when clang is missing or a target does not build."""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FW = ROOT / "firmware" / "atmega328"
PROTOCOL = ROOT / "protocol" / "c"
TARGETS = {
    "parser": [ROOT / "tests/c/fuzz_parser.c", PROTOCOL / "frame.c"],
    "core": [ROOT / "tests/c/fuzz_core.c", FW / "core/robot.c", FW / "core/drive.c",
             FW / "core/link_loss.c", FW / "emu/single_thread.c", PROTOCOL / "frame.c"],
}
FLAGS = ["-g", "-O1", "-std=gnu11", "-Wall", "-Wextra", "-Werror",
         "-fsanitize=fuzzer,address,undefined", "-fno-sanitize-recover=all"]


class FuzzError(Exception):
    """clang is missing, or a target does not build."""


@dataclass
class Result:
    target: str
    ok: bool
    runs: int
    cov: int
    ft: int
    corpus: int
    seconds: float
    findings: list[Path]
    log: str


def build(target: str, out_dir: Path) -> Path:
    clang = shutil.which("clang")
    if clang is None:
        raise FuzzError("clang not found: install clang (make system-deps, as root)")
    exe = out_dir / f"fuzz-{target}"
    r = subprocess.run([clang, *FLAGS, f"-I{PROTOCOL}", *map(str, TARGETS[target]), "-o",
                        str(exe)], capture_output=True, text=True)
    if r.returncode:
        raise FuzzError(f"fuzz target {target} does not build: {r.stderr.strip()[-1500:]}")
    return exe


def _seed_parser(corpus: Path) -> None:
    vectors = json.loads((ROOT / "protocol" / "vectors.json").read_text())["vectors"]
    for v in vectors:
        (corpus / f"vector-{v['name']}").write_bytes(bytes.fromhex(v["input"]))


def run(target: str, seconds: float, out_dir: Path) -> Result:
    """Fuzz one target for seconds from the committed corpus; new inputs go to a scratch corpus
    under out_dir, findings to out_dir/<target>/crash-*."""
    work = out_dir / target
    shutil.rmtree(work, ignore_errors=True)
    scratch = work / "corpus"
    scratch.mkdir(parents=True)
    committed = ROOT / "tests" / "c" / "corpus" / target
    if target == "parser":
        _seed_parser(scratch)
    exe = build(target, out_dir)
    cmd = [str(exe), f"-max_total_time={seconds:g}", "-print_final_stats=1", "-timeout=10",
           f"-artifact_prefix={work}/", str(scratch), *([str(committed)] if committed.exists()
                                                         else [])]
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=work)
    log = r.stderr
    last = [line for line in log.splitlines() if re.match(r"#\d+\s+(DONE|INITED|pulse|NEW|REDUCE)",
                                                          line)]
    stats = dict(re.findall(r"(\w+): (\d+)", last[-1])) if last else {}
    runs = re.search(r"stat::number_of_executed_units: (\d+)", log)
    secs = re.search(r"Done \d+ runs in (\d+) second", log)
    findings = sorted(work.glob("crash-*")) + sorted(work.glob("leak-*")) + sorted(
        work.glob("timeout-*"))
    return Result(target, r.returncode == 0 and not findings, int(runs.group(1)) if runs else 0,
                  int(stats.get("cov", 0)), int(stats.get("ft", 0)),
                  int(re.search(r"corp: (\d+)", last[-1]).group(1)) if last and "corp:" in
                  last[-1] else 0, float(secs.group(1)) if secs else 0.0, findings, log)


def coverage(target: str, corpus: list[Path], out_dir: Path) -> str:
    """llvm-cov's report (lines, branches) of the target's sources over the inputs in corpus,
    run once each by a build with source-based coverage."""
    clang, cov, prof = (shutil.which(t) for t in ("clang", "llvm-cov", "llvm-profdata"))
    if not (clang and cov and prof):
        raise FuzzError("clang, llvm-cov and llvm-profdata are needed for coverage")
    exe = out_dir / f"cover-{target}"
    sources = [str(p) for p in TARGETS[target][1:]]
    r = subprocess.run([clang, "-O0", "-std=gnu11", "-fsanitize=fuzzer",
                        "-fprofile-instr-generate", "-fcoverage-mapping", f"-I{PROTOCOL}",
                        str(TARGETS[target][0]), *sources, "-o", str(exe)],
                       capture_output=True, text=True)
    if r.returncode:
        raise FuzzError(f"coverage build of {target} failed: {r.stderr[-800:]}")
    raw = out_dir / f"{target}.profraw"
    subprocess.run([str(exe), "-runs=0", *map(str, corpus)], capture_output=True, text=True,
                   env={"LLVM_PROFILE_FILE": str(raw)})
    data = out_dir / f"{target}.profdata"
    subprocess.run([prof, "merge", "-sparse", str(raw), "-o", str(data)], check=True)
    return subprocess.run([cov, "report", str(exe), f"-instr-profile={data}", *sources],
                          capture_output=True, text=True, check=True).stdout


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="per target (default 60)")
    ap.add_argument("--only", choices=sorted(TARGETS), help="one target")
    ap.add_argument("--out", type=Path, default=None, help="work folder (default a temporary one)")
    ap.add_argument("--coverage", action="store_true",
                    help="then report line and branch coverage of the sources over the corpus")
    args = ap.parse_args(argv)
    out = args.out or Path(tempfile.mkdtemp(prefix="stereo-servo-fuzz-"))
    out.mkdir(parents=True, exist_ok=True)
    bad = 0
    for target in [args.only] if args.only else list(TARGETS):
        try:
            r = run(target, args.seconds, out)
        except FuzzError as e:
            print(f"fuzz: {e}", file=sys.stderr)
            return 2
        bad += not r.ok
        print(f"{target}: {r.runs} runs in {r.seconds:.0f} s, {r.cov} edges, {r.ft} features, "
              f"corpus {r.corpus}; {'no finding' if r.ok else 'FINDING'}", flush=True)
        for f in r.findings:
            print(f"  finding: {f}")
        if not r.ok and not r.findings:
            print(r.log[-3000:])
        if args.coverage:
            committed = ROOT / "tests" / "c" / "corpus" / target
            dirs = [out / target / "corpus", *([committed] if committed.exists() else [])]
            print(coverage(target, dirs, out), flush=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
