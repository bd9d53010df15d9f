"""Options shared by the commands: the matcher's (eval, disparity, tune, servo), and the
range-checked number types every numeric option uses, so a bad value is refused at parse time
with a message naming the option ("argument --fps: must be > 0, got 0")."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from typing import Any

from host import renamed
from host.params_file import load_disparity_range, load_matcher_table, load_params
from host.stereo.params import BORDERS, MATCHERS, SGM_PATHS, MatcherParams


def _bounds(lo: float | None, hi: float | None, lo_open: bool, hi_open: bool) -> str:
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        parts.append(f"{'<' if hi_open else '<='} {hi:g}")
    return " and ".join(parts)


def _ranged(kind: type, lo: float | None, hi: float | None, lo_open: bool,
            hi_open: bool) -> Callable[[str], float]:
    def parse(text: str) -> float:
        try:
            value: float = kind(text)
        except ValueError:
            word = "an integer" if kind is int else "a number"
            raise argparse.ArgumentTypeError(f"expected {word}, got {text!r}") from None
        if kind is float and not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
        if ((lo is not None and (value < lo or (lo_open and value == lo)))
                or (hi is not None and (value > hi or (hi_open and value == hi)))):
            raise argparse.ArgumentTypeError(
                f"must be {_bounds(lo, hi, lo_open, hi_open)}, got {text}")
        return value

    parse.__name__ = kind.__name__  # argparse names the type in its own messages
    return parse


def int_range(lo: int | None = None, hi: int | None = None) -> Callable[[str], int]:
    """An argparse type: an integer in [lo, hi] (either bound may be None)."""
    return _ranged(int, lo, hi, False, False)  # type: ignore[return-value]


def float_range(lo: float | None = None, hi: float | None = None, *, lo_open: bool = False,
                hi_open: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite number between lo and hi, each bound closed unless *_open."""
    return _ranged(float, lo, hi, lo_open, hi_open)


POSITIVE = float_range(0, lo_open=True)  # > 0
NON_NEGATIVE = float_range(0)  # >= 0
FRACTION = float_range(0, 1)  # [0, 1]
COUNT = int_range(1)  # >= 1
SEED = int_range(0)  # >= 0


def _tolerance_or_off(text: str) -> float:
    """--lr-check's type: a tolerance in px (>= 0), or "off"."""
    if text == "off":
        return -1.0
    try:
        return NON_NEGATIVE(text)
    except argparse.ArgumentTypeError as e:
        raise argparse.ArgumentTypeError(f"{e} (or off)") from None


_tolerance_or_off.__name__ = "float"


def option(name: str) -> str:
    """The command-line spelling of a MatcherParams field or params-file key: --block-size."""
    return "--" + name.replace("_", "-")


class _OldSpelling(argparse.Action):
    """An option's former spelling, kept so that old scripts run: stored as the new option
    (whose dest it shares), with a one-line note on stderr naming the new spelling."""

    def __init__(self, option_strings: list[str], dest: str, new: str, **kw: Any) -> None:
        super().__init__(option_strings, dest, help=argparse.SUPPRESS,
                         default=argparse.SUPPRESS, **kw)
        self.new = new

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: Any, option_string: str | None = None) -> None:
        print(f"note: {option_string} is now {self.new} (the old spelling will go)",
              file=sys.stderr)
        setattr(namespace, self.dest, self.const if self.nargs == 0 else values)


def add_old_spelling(g: argparse._ActionsContainer, old: str, new: argparse.Action) -> None:
    """old (e.g. --window, --grey) read as the option new (--block-size, --no-colour: a flag
    stores what new stores), with a note (_OldSpelling)."""
    if new.nargs == 0:
        g.add_argument(old, dest=new.dest, nargs=0, const=new.const, action=_OldSpelling,
                       new=new.option_strings[0])
    else:
        g.add_argument(old, dest=new.dest, type=new.type or str, action=_OldSpelling,
                       new=new.option_strings[0])


def add_matcher_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("matcher (defaults: the --matcher's measured ones; a --params file "
                             "overrides them, the options override the file)")
    g.add_argument("--params", metavar="FILE", help="tuned parameters file (host tune --out)")
    g.add_argument("--matcher", choices=MATCHERS,
                   help="matching cost, or an OpenCV matcher; each starts from its measured "
                        "best settings (sgm: block size 1, clip, LR 0, uniqueness 30, fill, "
                        "4 paths, median 5, whole pixels)")
    new = [g.add_argument(option("block_size"), type=int_range(1), metavar="N",
                          help="side of the matching window, odd (px)"),
           g.add_argument(option("num_disparities"), type=COUNT, metavar="N",
                          help="number of disparities (default: from the scene's ground truth, "
                               "else 64)"),
           g.add_argument(option("min_disparity"), type=int, metavar="N",
                          help="smallest disparity (px)")]
    g.add_argument("--lr-check", type=_tolerance_or_off, metavar="PX",
                   help="left-right consistency tolerance (px), or off (the matcher's default "
                        "when not given)")
    new.append(g.add_argument(option("uniqueness_ratio"), type=float_range(0, 100),
                              metavar="PCT", help="uniqueness ratio (%%)"))
    g.add_argument("--border", choices=BORDERS, help="window at the image edge: invalid or clip")
    g.add_argument("--fill", action="store_true", default=None,
                   help="fill invalid pixels from the farther neighbour")
    g.add_argument("--no-fill", dest="fill", action="store_false", default=None,
                   help="leave invalid pixels without a disparity")
    g.add_argument("--paths", type=int, choices=SGM_PATHS,
                   help="aggregation paths of the own SGM")
    g.add_argument("--median", type=int, choices=(0, 3, 5), help="median filter size")
    g.add_argument("--subpixel", dest="subpixel", action="store_true", default=None,
                   help="sub-pixel disparities (a fit through the costs beside the winner)")
    g.add_argument("--no-subpixel", dest="subpixel", action="store_false", default=None,
                   help="whole-pixel disparities (the own SGM's default)")
    g.add_argument("--colour", action="store_true", default=None,
                   help="match on the colour planes when the images have colour")
    new.append(g.add_argument("--no-colour", dest="colour", action="store_false", default=None,
                              help="match on grey even when the images have colour"))
    by_option = {a.option_strings[0]: a for a in new}
    for old, name in (renamed.PARAMETERS | renamed.FLAGS).items():
        add_old_spelling(g, option(old), by_option[option(name)])


_FIELDS = ("matcher", "block_size", "num_disparities", "min_disparity", "lr_check",
           "uniqueness_ratio", "border", "fill", "median", "subpixel", "colour", "paths")


def params_from_args(args: argparse.Namespace) -> MatcherParams:
    """The --params file (its keys over its matcher's measured defaults), else the --matcher's
    measured defaults (MatcherParams.for_matcher), overridden by the options given."""
    if args.params:
        base = load_params(args.params)[0]
    else:
        base = MatcherParams.for_matcher(args.matcher or MatcherParams.matcher)
    changes = {f: getattr(args, f) for f in _FIELDS if getattr(args, f) is not None}
    if changes.get("lr_check") == -1.0:
        changes["lr_check"] = None
    return base.replace(**changes).validate()


def num_disparities_given(args: argparse.Namespace) -> bool:
    """Whether the disparity range came from the user: the option, or a params file whose
    [matcher] table fixes it (num_disparities) rather than storing a [disparity_range] policy.
    A params file with neither keeps the scene's own range policy."""
    if args.num_disparities is not None:
        return True
    if args.params is None or load_disparity_range(args.params) is not None:
        return False
    return "num_disparities" in load_matcher_table(args.params)
