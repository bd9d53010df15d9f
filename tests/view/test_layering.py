"""The live view sits on top: nothing below the commands imports host.view, and the servo
loop runs without it loaded."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

HOST = Path(__file__).resolve().parents[2] / "host"


def test_only_commands_import_the_view():
    pattern = re.compile(r"^\s*(from|import)\s+host\.view\b", re.M)
    importers = {p.relative_to(HOST).parts[0] for p in HOST.rglob("*.py")
                 if pattern.search(p.read_text(encoding="utf-8"))}
    assert importers <= {"commands", "view"}, importers


def test_servo_loop_does_not_load_the_view():
    code = "import sys, host.servo.loop, host.servo.snapshot; print('host.view' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "False", out.stderr
