"""Golden vectors: the host's decoder and the firmware's C parser give the same answers."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from host.link.frame import FrameDecoder, crc
from host.link.messages import describe

ROOT = Path(__file__).resolve().parents[2]
VECTORS = json.loads((ROOT / "protocol" / "vectors.json").read_text())["vectors"]


def expected_lines(v: dict) -> list[str]:
    lines = [f"frame {f['seq']} {f['id']} {f['payload']} {f['text']}" for f in v["frames"]]
    return lines + [f"counters {v['good_frames']} {v['crc_errors']} {v['framing_errors']}"]


@pytest.mark.parametrize("vector", VECTORS, ids=[v["name"] for v in VECTORS])
def test_python_decoder_matches_vector(vector: dict) -> None:
    dec = FrameDecoder()
    frames = dec.feed(bytes.fromhex(vector["input"]))
    got = [f"frame {f.seq} {f.id} {f.payload.hex()} {describe(f.id, f.payload)}" for f in frames]
    got.append(f"counters {dec.good_frames} {dec.crc_errors} {dec.framing_errors}")
    assert got == expected_lines(vector)


def test_python_decoder_byte_at_a_time_matches_whole() -> None:
    for v in VECTORS:
        dec = FrameDecoder()
        frames = [f for b in bytes.fromhex(v["input"]) for f in dec.feed(bytes([b]))]
        assert len(frames) == len(v["frames"]), v["name"]


def test_c_parser_matches_every_vector(native_build) -> None:
    exe = native_build("vector_driver", [ROOT / "tests/c/vector_driver.c",
                                         ROOT / "protocol/c/frame.c"])
    stdin = "".join(v["input"] + "\n" for v in VECTORS)
    out = subprocess.run([str(exe)], input=stdin, capture_output=True, text=True, check=True)
    lines = out.stdout.splitlines()
    want = [line for v in VECTORS for line in expected_lines(v)]
    assert lines == want


def test_vectors_cover_the_required_cases() -> None:
    names = " | ".join(v["name"] for v in VECTORS)
    for case in ("bad CRC", "truncated", "oversize length", "unknown id", "garbage between",
                 "back to back"):
        assert case in names
    from host.link import protocol_gen as gen
    for cls in gen.MESSAGES.values():
        assert f"message {cls.NAME}" in names


def test_crc_is_crc32c_in_python_and_in_c(native_build, tmp_path: Path) -> None:
    assert crc(b"123456789") == 0xE3069283  # CRC-32C check value
    src = tmp_path / "crc.c"
    src.write_text('#include <stdio.h>\n#include "crc.h"\n'
                   'int main(void){uint32_t c=0xFFFFFFFF;const char*s="123456789";'
                   'while(*s)c=crc_update(c,(uint8_t)*s++);printf("%08X\\n",c^0xFFFFFFFF);'
                   'return 0;}\n')
    exe = native_build("crc", [src])
    assert subprocess.run([str(exe)], capture_output=True, text=True).stdout.strip() == "E3069283"
