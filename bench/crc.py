"""Which CRC for the link: corrupted frames that each CRC lets through, measured on the
protocol's own frame lengths (SET_DRIVE and STATUS) with numba.

Corruption models, each applied to 10^7 copies of a valid frame (seeded, reproducible):
  bytes  2..6 distinct bytes of SEQ ID PAYLOAD CRC replaced by other random values
  burst  a run of 2..8 consecutive bytes of SEQ ID PAYLOAD CRC replaced by random values
  bits   2..6 distinct bits of SEQ ID PAYLOAD CRC flipped
LEN is left alone (a changed LEN reframes the stream and is mostly caught by the length check
against the ID; this measures the CRC). A corrupted frame counts as accepted when its CRC, over
the corrupted LEN SEQ ID PAYLOAD, equals the corrupted CRC field.

    python bench/crc.py [--trials N]
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np
from numba import njit

from host.link import protocol_gen as gen
from host.link.frame import encode_frame
from host.link.messages import pack

# name: (width, polynomial in normal form, init, reflected, final xor)
CRCS = {
    "CRC-16/CCITT-FALSE (0x1021)": (16, 0x1021, 0xFFFF, False, 0),
    "CRC-16 Koopman 0xAC9A (normal 0x5935)": (16, 0x5935, 0xFFFF, False, 0),
    "CRC-32C (Castagnoli)": (32, 0x1EDC6F41, 0xFFFFFFFF, True, 0xFFFFFFFF),
}


def table(width: int, poly: int, reflected: bool) -> np.ndarray:
    t = np.zeros(256, dtype=np.uint64)
    mask = (1 << width) - 1
    if reflected:
        rpoly = int(f"{poly:0{width}b}"[::-1], 2)
        for i in range(256):
            c = i
            for _ in range(8):
                c = (c >> 1) ^ rpoly if c & 1 else c >> 1
            t[i] = c
    else:
        for i in range(256):
            c = i << (width - 8)
            for _ in range(8):
                c = ((c << 1) ^ poly) & mask if c & (1 << (width - 1)) else (c << 1) & mask
            t[i] = c
    return t


@njit(cache=True)
def crc(data, n, t, width, init, reflected, xorout):
    c = np.uint64(init)
    for i in range(n):
        b = np.uint64(data[i])
        if reflected:
            c = (c >> np.uint64(8)) ^ t[(c ^ b) & np.uint64(0xFF)]
        else:
            c = ((c << np.uint64(8)) & np.uint64((1 << width) - 1)) ^ \
                t[((c >> np.uint64(width - 8)) ^ b) & np.uint64(0xFF)]
    return c ^ np.uint64(xorout)


@njit(cache=True)
def _next(s):
    s ^= (s << np.uint64(13)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    s ^= s >> np.uint64(7)
    s ^= (s << np.uint64(17)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    return s


@njit(cache=True)
def trial_run(body, t, width, init, reflected, xorout, model, trials, seed):
    """body: LEN SEQ ID PAYLOAD; the CRC is appended little-endian. Returns accepted count."""
    nb = width // 8
    n = body.shape[0]
    frame = np.zeros(n + nb, dtype=np.uint8)
    good = crc(body, n, t, width, init, reflected, xorout)
    s = np.uint64(seed)
    accepted = 0
    span = n + nb - 1  # corruptible bytes: all after LEN
    for _ in range(trials):
        for i in range(n):
            frame[i] = body[i]
        for k in range(nb):
            frame[n + k] = (good >> np.uint64(8 * k)) & np.uint64(0xFF)
        s = _next(s)
        if model == 0:  # 2..6 distinct bytes replaced by other values
            count = 2 + int(s % np.uint64(5))
            done = 0
            used = np.zeros(span, dtype=np.uint8)
            while done < count:
                s = _next(s)
                pos = int(s % np.uint64(span))
                if used[pos]:
                    continue
                used[pos] = 1
                s = _next(s)
                frame[1 + pos] ^= np.uint8(1 + s % np.uint64(255))
                done += 1
        elif model == 1:  # a burst of 2..8 consecutive bytes replaced by random values
            length = min(2 + int(s % np.uint64(7)), span)
            s = _next(s)
            start = int(s % np.uint64(span - length + 1))
            changed = False
            for k in range(length):
                s = _next(s)
                v = np.uint8(s % np.uint64(256))
                changed |= v != frame[1 + start + k]
                frame[1 + start + k] = v
            if not changed:
                continue
        else:  # 2..6 distinct bit flips
            count = 2 + int(s % np.uint64(5))
            done = 0
            used = np.zeros(span * 8, dtype=np.uint8)
            while done < count:
                s = _next(s)
                bit = int(s % np.uint64(span * 8))
                if used[bit]:
                    continue
                used[bit] = 1
                frame[1 + bit // 8] ^= np.uint8(1 << (bit % 8))
                done += 1
        c = crc(frame, n, t, width, init, reflected, xorout)
        got = np.uint64(0)
        for k in range(nb):
            got |= np.uint64(frame[n + k]) << np.uint64(8 * k)
        if c == got:
            accepted += 1
    return accepted


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=10_000_000)
    args = ap.parse_args(argv)
    frames = {"SET_DRIVE": encode_frame(7, *pack(gen.SetDrive(left=500, right=-500))),
              "STATUS": encode_frame(7, *pack(gen.Status(123456, 500, -500, 4, 1, 1000, 3, 2,
                                                         250, 400, 0, 0, 0)))}
    print(f"# {args.trials} corruptions per cell; {os.cpu_count()} CPUs, load "
          f"{os.getloadavg()[0]:.2f}; numba, one thread")
    print("| CRC | model | " + " | ".join(f"{k} ({len(v)} B)" for k, v in frames.items())
          + " |")
    print("|---|---|" + "---|" * len(frames))
    t0 = time.perf_counter()
    for name, (width, poly, init, refl, xorout) in CRCS.items():
        t = table(width, poly, refl)
        for model, label in enumerate(("bytes 2..6", "burst 2..8", "bits 2..6")):
            cells = []
            for f in frames.values():
                body = np.frombuffer(f[1:-gen.CRC_LEN], dtype=np.uint8).copy()
                n = trial_run(body, t, width, init, refl, xorout, model, args.trials,
                              0x9E3779B97F4A7C15 ^ (model * 7919 + len(body)))
                cells.append(f"{n} ({n / args.trials:.1e})")
            print(f"| {name} | {label} | " + " | ".join(cells) + " |", flush=True)
    print(f"# {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
