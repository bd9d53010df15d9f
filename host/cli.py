"""The host command: subcommands for the stereo core, tuning, the link and the servo."""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path
from typing import Any

import host
from host.errors import describe
from host.signals import interrupt_ends_at_once, signals_interrupt

# each command, in --help's order, with its line of help; its arguments and run come from
# host.commands.NAME (add_arguments), imported only when that command runs or the whole parser
# is built: `host --version` and `host --help` load none of the libraries (numba, OpenCV)
COMMANDS = {
    "eval": "score a matcher against ground truth",
    "disparity": "compute a disparity map from a rectified pair",
    "tune": "tune the matcher's parameters (against ground truth, or self-supervised on a "
            "camera's frames)",
    "cameras": "list stereo cameras and the --camera that opens each",
    "capture": "save stereo image pairs from the camera",
    "calibrate": "calibrate and rectify the stereo camera",
    "servo": "servo the robot to the nearest object's depth",
    "emulate": "run the robot's firmware on a pseudo-terminal",
    "view": "look at the stereo camera live in a browser (no robot)",
    "bag": "what a recording holds; repair one a killed run cut off",
}


# one or two examples per command (a command module may define EXAMPLES itself instead)
EXAMPLES = {
    "eval": ["host eval                               # the embedded Motorcycle pair",
             "host eval ../shared/data/middlebury --matcher ncc --block-size 7 --picture out/"],
    "disparity": ["host disparity left.png right.png -o disp.png --num-disparities 64 "
                  "--npy disp.npy"],
    "tune": ["host tune --out tuned.toml --plot tuning.png",
             "host tune ../shared/data/middlebury --space sad --method qlearning --workers 2"],
    "cameras": ["host cameras           # the stereo cameras plugged in, with their --camera",
                "host cameras --sysfs /tmp/fake-sys"],
    "capture": ["host capture --count 25 --interval 2 --out shots/"],
    "calibrate": ["host calibrate shots/ --board 9x6 --square 25 --out calib.yml",
                  "host calibrate shots/ --out calib.yml --ros ros/ --picture check.png"],
    "servo": ["host servo --sim --log run.csv --plot run.png",
              "host servo --port /dev/ttyACM0 --calib calib.yml --params tuned.toml"],
    "view": ["host view --camera minoru --calib calib.yml      # look without a robot",
             "host view --camera replay:shots/ --view 127.0.0.1:8080"],
    "emulate": ["host emulate --drop 0.01     # then: host servo --port /dev/pts/N ...",
                "host emulate --simavr --duration 60"],
}
EPILOGS = {
    "servo": "exit status: 0 held at the target (or stopped by --duration); 2 bad input or a "
             "link failure;\n3 not reached: the marker was never seen, or the run ended in a "
             "safe stop;\n4 a replay (--camera replay:...) ran out before the robot held at "
             "the target;\n128+n ended by signal n (Ctrl-C, SIGTERM, SIGHUP): STOP is sent and "
             "the log and plot are kept.",
}


class _Formatter(argparse.RawDescriptionHelpFormatter):
    """Help with each option's default (when it has one worth showing) and the epilog as
    written (the examples)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if ("%(default)" in text or "default" in text or default in (None, False, [])
                or default is argparse.SUPPRESS or not action.option_strings
                or action.nargs == 0):  # a flag: its default is its absence, not True
            return text
        return text + " (default: %(default)s)"


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error (no usage block) and exit status 2."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser(prog: str = "host", only: str | None = None) -> argparse.ArgumentParser:
    """The whole parser, or with only: every command listed but only that one's module
    imported and its arguments added (none for ""; main picks only from argv)."""
    parser = _Parser(
        prog=prog, description="stereo-servo host: stereo matching, tuning and the robot servo")
    parser.add_argument("--version", action="version", version=f"stereo-servo {host.__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="show the traceback of an error instead of one line")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                parser_class=_Parser)
    for name, line in COMMANDS.items():
        p = sub.add_parser(name, help=line)
        if only in (None, name):
            command = importlib.import_module(f"host.commands.{name}")
            command.add_arguments(p)  # a command module may keep its own EXAMPLES
            _finish(name, p, getattr(command, "EXAMPLES", EXAMPLES.get(name)))
    return parser


def command_named(argv: list[str]) -> str | None:
    """The command argv names: its first word not an option (host's own options take no
    value), if it is a command."""
    word = next((a for a in argv if not a.startswith("-")), None)
    return word if word in COMMANDS else None


def _finish(name: str, p: argparse.ArgumentParser, examples: list[str] | None) -> None:
    """--debug after the command's name too; the epilog: exit statuses and examples."""
    p.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                   help="show the traceback of an error instead of one line")
    text = "\n".join(f"  {line}" for line in examples or [])
    p.epilog = "\n\n".join(t for t in (EPILOGS.get(name), text and "examples:\n" + text) if t)


def main(argv: list[str] | None = None) -> int:
    """Run a subcommand. Bad input (a HostError, an OSError, a library's error on the user's
    data) becomes one line on stderr and exit status 2; SIGINT, SIGTERM and SIGHUP end it like
    Ctrl-C with status 128+n; --debug shows the traceback instead."""
    prog = "stereo-servo" if Path(sys.argv[0]).name == "stereo-servo" else "host"
    argv = sys.argv[1:] if argv is None else argv
    with interrupt_ends_at_once(f"{prog}: interrupted"):  # the command's module loads here
        args = build_parser(prog, only=command_named(argv) or "").parse_args(argv)
    try:
        with signals_interrupt():
            return int(args.run(args))
    except BrokenPipeError:  # the reader (head, less) went away: not an error of ours
        sys.stderr.close()
        return 0
    except BaseException as e:
        said = None if args.debug or isinstance(e, SystemExit) else describe(e)
        if said is None:
            raise
        print(f"{prog} {args.command}: {said[1]}", file=sys.stderr)
        return said[0]


if __name__ == "__main__":
    sys.exit(main())
