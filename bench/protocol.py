"""Benchmark of the protocol: Python encode+decode frames per second, and the C parser's
sanitizer fuzz run over 10^6 iterations (bytes per second, corrupted frames accepted)."""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from host.link import protocol_gen as gen
from host.link.frame import FrameDecoder, encode_frame
from host.link.messages import pack, unpack

ROOT = Path(__file__).resolve().parent.parent


def python_rate(n: int = 50000) -> float:
    msg = gen.SetDrive(left=500, right=-500)
    dec = FrameDecoder()
    t0 = time.perf_counter()
    for i in range(n):
        frames = dec.feed(encode_frame(i & 0xFF, *pack(msg)))
        unpack(frames[0].id, frames[0].payload)
    return n / (time.perf_counter() - t0)


def c_fuzz(iterations: int, sanitize: bool) -> str:
    with tempfile.TemporaryDirectory() as d:
        exe = Path(d) / "fuzz"
        flags = (["-O1", "-g", "-fsanitize=address,undefined", "-fno-sanitize-recover=all"]
                 if sanitize else ["-O2"])
        subprocess.run(["gcc", "-std=gnu11", *flags, f"-I{ROOT / 'protocol/c'}",
                        str(ROOT / "tests/c/fuzz_frame.c"), str(ROOT / "protocol/c/frame.c"),
                        "-o", str(exe)], check=True)
        r = subprocess.run([str(exe), str(iterations), "1"], capture_output=True, text=True)
        if r.returncode:
            raise SystemExit("fuzz run failed:\n" + r.stdout + r.stderr)
        return r.stdout


def main() -> int:
    print(f"python encode+pack+decode+unpack: {python_rate():,.0f} frames/s")
    print("C parser, ASan+UBSan, 10^6 iterations:")
    print("  " + c_fuzz(1_000_000, True).replace("\n", "\n  ").rstrip())
    print("C parser, -O2 without sanitizers, 10^6 iterations:")
    print("  " + c_fuzz(1_000_000, False).splitlines()[0])
    return 0


if __name__ == "__main__":
    sys.exit(main())
