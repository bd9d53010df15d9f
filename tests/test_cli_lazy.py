"""host --version and host --help load none of the libraries (each command's module is imported
only when it runs), and the parser built for one command is the whole parser's for it."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import pytest

from host.cli import COMMANDS, build_parser, command_named

ROOT = Path(__file__).resolve().parent.parent

# a fresh interpreter runs the console script's entry with argv, then names what it imported
# of the heavy libraries and of our modules that compile or load them
SCRIPT = r"""
import sys
argv, sys.argv = sys.argv[1:], ["host"]
sys.argv += argv
import stereo_servo
try:
    stereo_servo.main()
except SystemExit:
    pass
heavy = ("numba", "cv2", "scipy", "matplotlib", "optuna", "host.stereo", "host.commands.",
         "host.servo", "host.sim", "host.tuning", "host.camera")
print("IMPORTED:", *sorted(m for m in sys.modules if m.startswith(heavy)))
"""


@pytest.mark.parametrize("argv", [["--version"], ["--help"], [], ["nope"]],
                         ids=["version", "help", "no-command", "unknown-command"])
def test_host_without_a_command_to_run_imports_no_library(argv: list[str]) -> None:
    run = subprocess.run([sys.executable, "-c", SCRIPT, *argv], cwd=ROOT, capture_output=True,
                         text=True, timeout=120)
    imported = run.stdout.split("IMPORTED:")[-1].split()
    assert "IMPORTED:" in run.stdout and imported == [], run.stderr[-1000:]


def _sub(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_command_parsed_alone_has_the_whole_parsers_help_and_defaults(name: str) -> None:
    whole, alone = _sub(build_parser())[name], _sub(build_parser(only=name))[name]
    assert alone.format_help() == whole.format_help()
    assert [(a.dest, a.default) for a in alone._actions] == \
        [(a.dest, a.default) for a in whole._actions]
    assert alone.get_default("run") is whole.get_default("run") is not None


def test_host_help_lists_every_command_with_its_line_without_loading_one() -> None:
    assert build_parser(only="").format_help() == build_parser().format_help()


def test_the_command_is_the_first_word_that_is_not_an_option() -> None:
    assert command_named(["--debug", "servo", "--sim", "eval"]) == "servo"
    assert command_named(["--version"]) is None and command_named(["nope", "servo"]) is None
