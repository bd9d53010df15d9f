"""The generated files are current, and the schema hash follows wire facts, not docs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import protogen  # noqa: E402

from host.link import protocol_gen as gen  # noqa: E402


def test_generated_files_are_current() -> None:
    r = subprocess.run([sys.executable, str(protogen.ROOT / "tools" / "protogen.py"), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_generated_files_say_do_not_edit() -> None:
    for rel in protogen.OUTPUTS:
        assert "DO NOT EDIT" in (protogen.ROOT / rel).read_text()[:300], rel


def test_schema_hash_changes_with_the_wire_and_not_with_docs(tmp_path: Path) -> None:
    text = protogen.SPEC.read_text()
    base = protogen.load_spec().schema_hash
    assert base == gen.SCHEMA_HASH
    doc_edit = tmp_path / "doc.toml"
    doc_edit.write_text(text.replace('doc = "Stop both motors', 'doc = "Halt both motors'))
    assert protogen.load_spec(doc_edit).schema_hash == base
    wire_edit = tmp_path / "wire.toml"
    wire_edit.write_text(text.replace("min = -1000, max = 1000", "min = -999, max = 999", 1))
    assert protogen.load_spec(wire_edit).schema_hash != base


def test_spec_errors_are_caught(tmp_path: Path) -> None:
    import pytest

    bad = tmp_path / "bad.toml"
    bad.write_text(protogen.SPEC.read_text().replace("id = 0x03", "id = 0x02"))
    with pytest.raises(ValueError, match="used twice"):
        protogen.load_spec(bad)
