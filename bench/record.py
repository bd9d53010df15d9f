"""Benchmark of --record: a simulated servo run at 640x480 (or --size) held to real time at
30 fps for 60 s (or --seconds), recording every frame (both views raw, each disparity map, the
marker, target, phase, drive, link and the robot's STATUS once a second), as `host servo --sim
--record` does; then the loop's top rate with and without recording, as fast as it goes, in
interleaved rounds. The same real-time run without recording is the control: on a loaded
machine it shows how much of a shortfall is the load's.

Reported: the real-time run's loop rate (goal: >= 30 Hz, every pair recorded, nothing
dropped; pairs come at their capture times, and wait for a slow loop as a camera's do), pairs
more than 0.1 s late to their pace, items the recorder dropped, the process's CPU; the file's
size per minute as written (chunks compressed with --compression) and uncompressed (the
chunks' own uncompressed sizes, what --record-compression none writes); the load (uptime).
Exit status 1 when the real-time run fell below 30 Hz or dropped anything."""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from host.camera.paced import PacedSource
from host.record import record_servo
from host.sim.run import Setup, simulation
from host.stereo import MatcherParams
from host.stereo.matcher import warm_up

FPS = 30.0


def _uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def sizes(path: Path) -> tuple[int, int]:
    """(bytes on disk, bytes with the chunks uncompressed), from the file's chunk index."""
    from mcap.reader import make_reader

    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    on_disk = path.stat().st_size
    packed = sum(c.compressed_size for c in summary.chunk_indexes)
    unpacked = sum(c.uncompressed_size for c in summary.chunk_indexes)
    return on_disk, on_disk - packed + unpacked


def run(size: tuple[int, int], params: MatcherParams, seconds: float, record: Path | None,
        compression: str, paced: bool) -> dict:
    args = argparse.Namespace(record=record, record_compression=compression)
    setup = Setup(size, 2.2, params=params, fps=FPS)
    with simulation(setup, reference=False) as sim:
        servo = sim.servo
        if paced:
            servo.source = PacedSource(servo.source, 1.0, catch_up=True)  # as a camera
        pacer = servo.source
        with record_servo(args, servo, sim.source.clock) as rec:
            servo.reference()
            steps = 0
            load0 = os.getloadavg()[0]
            t0, cpu0, loop0 = time.perf_counter(), time.process_time(), time.thread_time()
            t_sim0 = sim.source.t
            while sim.source.t - t_sim0 < seconds:
                servo.step(sim.world.robot.z_m)
                steps += 1
            wall = time.perf_counter() - t0
            loop_cpu = time.thread_time() - loop0
            cpu = time.process_time() - cpu0
            t_close = time.perf_counter()
        close_s = time.perf_counter() - t_close
    out = {"loop_hz": steps / wall, "steps": steps, "wall_s": wall, "cpu_share": cpu / wall,
           "loop_cpu_ms": loop_cpu / steps * 1000, "cpu_ms": cpu / steps * 1000,
           "load": load0, "late": getattr(pacer, "late", 0), "close_s": close_s,
           "sim_s": seconds, "phases": sorted({r.phase for r in servo.rows})}
    if rec is not None:
        out.update(dropped=sum(rec.dropped.values()), queued=dict(rec.queued),
                   written=sum(rec._bag.counts.values()))
        out["size"], out["uncompressed"] = sizes(record)  # type: ignore[arg-type]
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--size", default="640x480")
    ap.add_argument("--seconds", type=float, default=60.0, help="the real-time run (sim s)")
    ap.add_argument("--compression", choices=("zstd", "lz4", "none"), default="zstd")
    ap.add_argument("--fast-seconds", type=float, default=5.0,
                    help="each as-fast-as-it-goes run (sim s)")
    ap.add_argument("--rounds", type=int, default=2)
    args = ap.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    params = MatcherParams(matcher="sad", block_size=9, num_disparities=64, border="clip")
    warm_up(params)
    print(f"{size[0]}x{size[1]} at {FPS:g} fps, matcher {params.matcher} window "
          f"{params.block_size}, {params.num_disparities} disparities; chunks {args.compression}; "
          f"{os.cpu_count()} cores shared with other users")
    print(f"uptime at start: {_uptime()}", flush=True)
    failed = False
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "realtime.mcap"
        m = run(size, params, args.seconds, path, args.compression, paced=True)
        per_min = 60.0 / args.seconds
        print(f"real time, {args.seconds:g} s recorded: loop {m['loop_hz']:.1f} Hz "
              f"({m['steps']} steps in {m['wall_s']:.1f} s), {m['late']} pairs late to their "
              f"pace, recorder dropped {m['dropped']} of "
              f"{m['dropped'] + sum(m['queued'].values())} items, "
              f"{m['written']} messages; CPU a step: loop thread {m['loop_cpu_ms']:.1f} ms, "
              f"process {m['cpu_ms']:.1f} ms ({m['cpu_share'] * 100:.0f}% of one core); "
              f"closing took {m['close_s']:.1f} s; load {m['load']:.2f}; phases {m['phases']}")
        print(f"size: {m['size'] * per_min / 1e6:.0f} MB a minute as written "
              f"({args.compression}), {m['uncompressed'] * per_min / 1e6:.0f} MB a minute "
              f"uncompressed", flush=True)
        failed = m["loop_hz"] < 0.98 * FPS or m["dropped"] > 0
        path.unlink()
        c = run(size, params, args.seconds, None, args.compression, paced=True)
        print(f"real time, {args.seconds:g} s not recorded (the control): loop "
              f"{c['loop_hz']:.1f} Hz, {c['late']} pairs late; CPU a step: loop thread "
              f"{c['loop_cpu_ms']:.1f} ms, process {c['cpu_ms']:.1f} ms; load {c['load']:.2f}",
              flush=True)
        rates: dict[str, list[float]] = {"no record": [], "record": []}
        cpu: dict[str, list[tuple[float, float]]] = {"no record": [], "record": []}
        for r in range(args.rounds):
            for name in (list(rates) if r % 2 == 0 else list(rates)[::-1]):
                rec = Path(tmp) / f"fast{r}.mcap" if name == "record" else None
                f = run(size, params, args.fast_seconds, rec, args.compression, paced=False)
                rates[name].append(f["loop_hz"])
                cpu[name].append((f["loop_cpu_ms"], f["cpu_ms"]))
                offered = f["dropped"] + sum(f["queued"].values()) if rec else 0
                extra = f", recorder dropped {f['dropped']} of {offered}" if rec else ""
                print(f"  as fast as it goes, round {r + 1} {name:>9}: loop {f['loop_hz']:5.1f} "
                      f"Hz; CPU a step: loop thread {f['loop_cpu_ms']:5.1f} ms, process "
                      f"{f['cpu_ms']:5.1f} ms{extra}; load {f['load']:.2f}",
                      flush=True)
                if rec:
                    rec.unlink()
    for name, hz in rates.items():
        loop_ms = statistics.median(c[0] for c in cpu[name])
        proc_ms = statistics.median(c[1] for c in cpu[name])
        # on two free cores the loop's thread bounds the rate, or the process's CPU over both
        free = 1000 / max(loop_ms, proc_ms / 2)
        print(f"{name:>9}: top loop rate median {statistics.median(hz):5.1f} Hz "
              f"({', '.join(f'{h:.1f}' for h in hz)}); CPU a step: loop thread {loop_ms:.1f} "
              f"ms, process {proc_ms:.1f} ms: about {free:.0f} Hz on 2 free cores")
    print(f"uptime at end: {_uptime()}")
    if failed:
        print("FAILED: the real-time run fell below 30 Hz or dropped items", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
