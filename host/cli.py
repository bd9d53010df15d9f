"""The host command: subcommands for the stereo core, tuning, the link and the servo."""

from __future__ import annotations

import argparse
import sys

from host.commands import calibrate, capture, disparity, emulate, servo, tune
from host.commands import eval as eval_cmd
from host.errors import describe
from host.signals import signals_interrupt

COMMANDS = [eval_cmd, disparity, tune, capture, calibrate, servo, emulate]


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error (no usage block) and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="host", description="stereo-servo host: stereo matching, tuning and the robot servo")
    parser.add_argument("--debug", action="store_true",
                        help="show the traceback of an error instead of one line")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                parser_class=_Parser)
    for command in COMMANDS:
        command.add_parser(sub)
    for p in sub.choices.values():  # --debug also after the command's name
        p.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                       help="show the traceback of an error instead of one line")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run a subcommand. Bad input (a HostError, an OSError, a library's error on the user's
    data) becomes one line on stderr and exit status 2; SIGINT, SIGTERM and SIGHUP end it like
    Ctrl-C with status 128+n; --debug shows the traceback instead."""
    args = build_parser().parse_args(argv)
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
        print(f"host {args.command}: {said[1]}", file=sys.stderr)
        return said[0]


if __name__ == "__main__":
    sys.exit(main())
