"""Matcher options shared by the commands that compute disparity (eval, disparity, servo)."""

from __future__ import annotations

import argparse

from host.params_file import load_disparity_range, load_params
from host.stereo.params import BORDERS, MATCHERS, MatcherParams


def add_matcher_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("matcher (defaults: --params file, else the built-in defaults)")
    g.add_argument("--params", metavar="FILE", help="tuned parameters file (host tune --out)")
    g.add_argument("--matcher", choices=MATCHERS)
    g.add_argument("--window", type=int, metavar="N", help="block size, odd (px)")
    g.add_argument("--num-disp", type=int, metavar="N",
                   help="number of disparities (default: from the scene's ground truth, else 64)")
    g.add_argument("--min-disp", type=int, metavar="N", help="smallest disparity (px)")
    g.add_argument("--lr-check", type=float, metavar="PX",
                   help="left-right consistency tolerance (px); off when not given")
    g.add_argument("--uniqueness", type=float, metavar="PCT", help="uniqueness ratio (%%)")
    g.add_argument("--border", choices=BORDERS, help="window at the image edge: invalid or clip")
    g.add_argument("--fill", action="store_true", default=None,
                   help="fill invalid pixels from the farther neighbour")
    g.add_argument("--median", type=int, choices=(0, 3, 5), help="median filter size")
    g.add_argument("--no-subpixel", dest="subpixel", action="store_false", default=None)
    g.add_argument("--grey", dest="colour", action="store_false", default=None,
                   help="match on grey even when the images have colour")


_FIELDS = {"matcher": "matcher", "window": "block_size", "num_disp": "num_disparities",
           "min_disp": "min_disparity", "lr_check": "lr_check", "uniqueness": "uniqueness_ratio",
           "border": "border", "fill": "fill", "median": "median", "subpixel": "subpixel",
           "colour": "colour"}


def params_from_args(args: argparse.Namespace) -> MatcherParams:
    """The --params file (or defaults) overridden by the options given on the command line."""
    base = load_params(args.params)[0] if args.params else MatcherParams()
    changes = {f: getattr(args, a) for a, f in _FIELDS.items() if getattr(args, a) is not None}
    return base.replace(**changes).validate()


def num_disp_given(args: argparse.Namespace) -> bool:
    """Whether the disparity range came from the user (option, or a params file that fixes it
    rather than storing a policy)."""
    return args.num_disp is not None or (args.params is not None
                                         and load_disparity_range(args.params) is None)
