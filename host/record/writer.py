"""The recording's file and its worker: a rosbag2 in MCAP storage (profile ros2, schemas
ros2msg, messages CDR), written by the mcap library from a worker thread fed by a bounded queue.

The loop's thread only queues (a closure and its references, no copy, no encoding); the worker
runs at a lower priority; a full queue drops the item and counts it, and /diagnostics says how
many ("recorder" status) once a second and at the end, as the file's rosbag2 metadata does.
Chunks are written whole as they fill (unbuffered file), so a run killed at any moment leaves
every chunk but the last one it was filling readable.
"""

from __future__ import annotations

import os
import queue
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from mcap.writer import CompressionType, Writer

from host.errors import HostError
from host.record import messages as m

COMPRESSIONS = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4,
                "none": CompressionType.NONE}
CHUNK_BYTES = 4 << 20  # a chunk is written when it holds this much (a few 640x480 frames)
QUEUE_ITEMS = 32  # about a second of frames at 30 fps: a few tens of MB at 640x480
STATS_EVERY_S = 1.0

Message = tuple[str, Any, int]  # topic, message, log time (ns)
Build = Callable[[], Iterable[Message]]


class _Direct:
    """A file whose every write reaches the operating system at once (no buffer in this
    process to lose when it is killed)."""

    def __init__(self, path: Path) -> None:
        self._raw = open(path, "wb", buffering=0)  # noqa: SIM115 (closed in close())

    def write(self, data: bytes | memoryview) -> int:
        view = memoryview(data)
        while view.nbytes:
            view = view[self._raw.write(view):]
        return len(data)

    def tell(self) -> int:
        return self._raw.tell()

    def flush(self) -> None:
        pass

    def close(self) -> None:
        self._raw.close()


class BagFile:
    """The MCAP file: one channel per topic of messages.TOPICS, its schema the ROS 2 message
    definition; not thread-safe (the worker owns it)."""

    def __init__(self, path: Path, compression: str = "zstd",
                 chunk_bytes: int = CHUNK_BYTES) -> None:
        self.path = path
        self._file = _Direct(path)
        self._mcap = Writer(self._file,  # type: ignore[arg-type]  # a binary file, not an IO
                            chunk_size=chunk_bytes,
                            compression=COMPRESSIONS[compression])
        self._mcap.start(profile="ros2", library="stereo-servo host record")
        self.counts: Counter[str] = Counter()
        self.first_ns: int | None = None
        self.last_ns = 0
        schemas = {t: self._mcap.register_schema(t, "ros2msg", m.msgdef(t).encode())
                   for t in sorted(set(m.TOPICS.values()))}
        self._channels = {topic: self._mcap.register_channel(topic, "cdr", schemas[t])
                          for topic, t in m.TOPICS.items()}

    def write(self, topic: str, msg: Any, ns: int) -> None:
        self._mcap.add_message(self._channels[topic], log_time=ns, data=m.serialize(msg),
                               publish_time=ns, sequence=self.counts[topic])
        self.counts[topic] += 1
        self.first_ns = ns if self.first_ns is None else min(self.first_ns, ns)
        self.last_ns = max(self.last_ns, ns)

    def close(self, custom: dict[str, str]) -> None:
        """The rosbag2 metadata record (as rosbag2's own MCAP storage writes it), the summary
        and the footer."""
        self._mcap.add_metadata("rosbag2", {"serialized_metadata": self._rosbag2_yaml(custom)})
        self._mcap.finish()
        self._file.close()

    def abandon(self) -> None:
        self._file.close()

    def _rosbag2_yaml(self, custom: dict[str, str]) -> str:
        first = self.first_ns or 0
        topics = "".join(
            f"    - topic_metadata:\n        name: {topic}\n        type: {t}\n"
            f"        serialization_format: cdr\n        offered_qos_profiles: ''\n"
            f"      message_count: {self.counts[topic]}\n"
            for topic, t in m.TOPICS.items() if self.counts[topic])
        data = "".join(f"    {k}: '{v}'\n" for k, v in custom.items())
        return (f"rosbag2_bagfile_information:\n  version: 8\n  storage_identifier: mcap\n"
                f"  duration:\n    nanoseconds: {self.last_ns - first}\n"
                f"  starting_time:\n    nanoseconds_since_epoch: {first}\n"
                f"  message_count: {sum(self.counts.values())}\n"
                f"  topics_with_message_count:\n{topics}"
                f"  compression_format: ''\n  compression_mode: ''\n"
                f"  relative_file_paths:\n    - {self.path.name}\n"
                f"  custom_data:\n{data}")


WORKER_NICE = 10  # the worker yields the CPU to the loop: a busy machine drops, not stalls


def _lower_priority() -> None:
    """This thread at a lower scheduling priority (Linux: threads have their own nice value),
    so that on a loaded machine the recorder falls behind and drops (counted) before it slows
    the loop. Where that is not possible it runs as it is."""
    try:
        tid = threading.get_native_id()
        os.setpriority(os.PRIO_PROCESS, tid, os.getpriority(os.PRIO_PROCESS, tid) + WORKER_NICE)
    except (AttributeError, OSError):
        pass


class Recorder:
    """Records from any thread without waiting: put(kind, build) queues build (run later on
    the worker, returning (topic, message, ns) triples); stamps come from ns(t), t on the
    run's clock mapped to the wall clock's epoch at start."""

    def __init__(self, path: Path, clock: Callable[[], float] = time.monotonic,
                 compression: str = "zstd", queue_items: int = QUEUE_ITEMS,
                 chunk_bytes: int = CHUNK_BYTES) -> None:
        self.path = path
        self.offset_ns = time.time_ns() - int(round(clock() * 1e9))  # whole ns: t keeps its digits
        self.queued: Counter[str] = Counter()
        self.dropped: Counter[str] = Counter()
        self.written: Counter[str] = Counter()
        self.error: BaseException | None = None
        self._queue: queue.Queue[tuple[str, Build] | None] = queue.Queue(queue_items)
        self._bag = BagFile(path, compression, chunk_bytes)
        self._stats_t = time.monotonic()
        self._last_ns = 0
        self._closed = False
        self._worker = threading.Thread(target=self._run, name="recorder", daemon=True)
        self._worker.start()

    def ns(self, t: float) -> int:
        """A time on the run's clock (s) as ROS time (ns since the epoch)."""
        return int(round(t * 1e9)) + self.offset_ns

    def put(self, kind: str, build: Build) -> None:
        """Queue build, or drop it and count the drop when the queue is full."""
        if self._closed:
            return
        try:
            self._queue.put_nowait((kind, build))
            self.queued[kind] += 1
        except queue.Full:
            self.dropped[kind] += 1

    def summary(self) -> str:
        """One line: what was written and dropped."""
        total = sum(self._bag.counts.values())
        drops = sum(self.dropped.values())
        dropped = (f"; dropped {drops} items the worker could not keep up with ("
                   + ", ".join(f"{k} {n}" for k, n in sorted(self.dropped.items())) + ")"
                   if drops else "; nothing dropped")
        return f"recorded {total} messages to {self.path}{dropped}"

    def _stats(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for kind in sorted(set(self.queued) | set(self.dropped)):
            out[f"{kind} queued"] = self.queued[kind]
            out[f"{kind} dropped"] = self.dropped[kind]
        out["queue length"] = self._queue.qsize()
        return out

    def _write_stats(self, final: bool = False) -> None:
        drops = sum(self.dropped.values())
        level = m.WARN if drops else m.OK
        text = (f"{drops} items dropped (the recorder fell behind)" if drops
                else "nothing dropped") + (" (final)" if final else "")
        ns = max(self._last_ns, 1)
        self._bag.write("/diagnostics", m.diagnostics(ns, [m.status(
            "recorder", level, text, self._stats())]), ns)

    def _run(self) -> None:
        _lower_priority()
        while True:
            item = self._queue.get()
            if item is None:
                return
            kind, build = item
            if self.error is not None:
                continue
            try:
                for topic, msg, ns in build():
                    self._bag.write(topic, msg, ns)
                    self._last_ns = max(self._last_ns, ns)
                self.written[kind] += 1
                if time.monotonic() - self._stats_t >= STATS_EVERY_S:
                    self._stats_t = time.monotonic()
                    self._write_stats()
            except Exception as e:  # noqa: BLE001 (said at close, one line)
                self.error = e

    def close(self) -> None:
        """Write what is queued, the final counts, the summary and the footer."""
        if self._closed:
            return
        self._closed = True
        self._queue.put(None)
        self._worker.join()
        if self.error is not None:
            self._bag.abandon()
            raise HostError(f"--record {self.path}: {self.error}")
        self._write_stats(final=True)
        custom = {f"dropped {k}": str(v) for k, v in sorted(self.dropped.items())}
        self._bag.close(custom)

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
