"""The host command: subcommands for the stereo core, tuning, the link and the servo."""

from __future__ import annotations

import argparse
import sys

from host.commands import calibrate, capture, disparity, emulate, servo, tune, view
from host.commands import eval as eval_cmd
from host.errors import HostError

COMMANDS = [eval_cmd, disparity, tune, capture, calibrate, servo, emulate, view]


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error (no usage block) and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="host", description="stereo-servo host: stereo matching, tuning and the robot servo")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                parser_class=_Parser)
    for command in COMMANDS:
        command.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run a subcommand; a HostError becomes one line on stderr and exit status 2."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.run(args))
    except HostError as e:
        print(f"host {args.command}: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"host {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader (head, less) went away: not an error of ours
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
