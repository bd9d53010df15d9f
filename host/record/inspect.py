"""What a recording holds, read from the start as it was written (so a file cut off by a
killed run reads too), and its repair: every complete message copied into a closed file with
a summary, which the readers that need one (rosbags, mcap's make_reader) open."""

from __future__ import annotations

import os
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from host.errors import HostError


@dataclass
class BagInfo:
    topics: dict[str, str] = field(default_factory=dict)  # topic -> message type
    counts: Counter[str] = field(default_factory=Counter)
    first_ns: int | None = None
    last_ns: int = 0
    closed: bool = False  # ends in a footer (False: cut off, as a killed run leaves it)
    recorder: str = ""  # the last "recorder" diagnostic's message, if any


def _messages(path: Path, info: BagInfo) -> Iterator[tuple[Any, Any, Any]]:
    """(schema, channel, message) of every complete message; info.closed tells how it ended."""
    from mcap.exceptions import InvalidMagic, McapError
    from mcap.reader import NonSeekingReader

    with path.open("rb") as f:
        try:
            yield from NonSeekingReader(f).iter_messages(log_time_order=False)
            info.closed = True
        except InvalidMagic:
            raise HostError(f"{path}: not an MCAP file") from None
        except (McapError, EOFError, ValueError):
            info.closed = False


def scan(path: Path, on_message: Any = None) -> BagInfo:
    """The topics, counts and times of path (on_message(schema, channel, message) for each)."""
    if not path.is_file():
        raise HostError(f"{path}: no such recording")
    info = BagInfo()
    store = None
    for schema, channel, message in _messages(path, info):
        info.topics[channel.topic] = schema.name if schema else "(no schema)"
        info.counts[channel.topic] += 1
        t = message.log_time
        info.first_ns = t if info.first_ns is None else min(info.first_ns, t)
        info.last_ns = max(info.last_ns, t)
        if schema is not None and schema.name == "diagnostic_msgs/msg/DiagnosticArray":
            if store is None:
                from rosbags.typesys import Stores, get_typestore

                store = get_typestore(Stores.ROS2_HUMBLE)
            msg: Any = store.deserialize_cdr(message.data, schema.name)
            for status in msg.status:
                if status.name == "recorder":
                    info.recorder = status.message
        if on_message is not None:
            on_message(schema, channel, message)
    return info


def repair(src: Path, dst: Path) -> BagInfo:
    """Copy every complete message of src into dst, closed with a summary; dst appears only
    once whole (written beside it, then renamed)."""
    from mcap.writer import CompressionType, Writer

    part = dst.with_name(dst.name + ".part")
    schemas: dict[int, int] = {}
    channels: dict[int, int] = {}
    try:
        with part.open("wb") as f:
            writer = Writer(f, chunk_size=4 << 20, compression=CompressionType.ZSTD)
            writer.start(profile="ros2", library="stereo-servo host bag --repair")

            def copy(schema: Any, channel: Any, message: Any) -> None:
                if schema is not None and schema.id not in schemas:
                    schemas[schema.id] = writer.register_schema(schema.name, schema.encoding,
                                                                schema.data)
                if channel.id not in channels:
                    channels[channel.id] = writer.register_channel(
                        channel.topic, channel.message_encoding,
                        schemas.get(channel.schema_id, 0), dict(channel.metadata))
                writer.add_message(channels[channel.id], message.log_time, message.data,
                                   message.publish_time, message.sequence)

            info = scan(src, copy)
            writer.finish()
        os.replace(part, dst)
    except BaseException:
        part.unlink(missing_ok=True)
        raise
    return info
