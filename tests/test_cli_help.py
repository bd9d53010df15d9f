"""host --help: every option and positional of every command has a help line, defaults are
shown, each command ends with examples; the disparity picture has a colour bar and a legend."""

from __future__ import annotations

import argparse
import shlex

import cv2
import numpy as np
import pytest

from host.cli import build_parser
from host.stereo.picture import colourise, legend_layout, picture


def _commands() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


@pytest.mark.parametrize("name", sorted(_commands()))
def test_every_command_documents_each_option_and_ends_with_examples(name: str) -> None:
    p = _commands()[name]
    undocumented = [a.option_strings or a.dest for a in p._actions if not a.help]
    assert undocumented == []
    text = p.format_help()
    examples = text.split("examples:\n")[-1].splitlines()
    assert "examples:\n" in text and 1 <= len(examples) <= 2
    assert all(line.strip().startswith(f"host {name}") for line in examples)
    for line in examples:  # each example is a command line the parser accepts
        build_parser().parse_args(shlex.split(line.split("#")[0])[1:])


def test_defaults_are_shown() -> None:
    text = _commands()["servo"].format_help()
    assert "(default: 600)" in text and "(default: turn)" in text
    assert "(default: None)" not in text and "(default: False)" not in text


def test_one_option_name_has_one_unit() -> None:
    """--silent-after was seconds in emulate and ms in servo."""
    for name in ("servo", "emulate"):
        action = next(a for a in _commands()[name]._actions if a.dest == "silent_after")
        assert action.metavar == "MS" and "ms" in action.help


@pytest.mark.parametrize("name", sorted(_commands()))
def test_a_flag_shows_no_default(name: str) -> None:
    """--no-lock's default was shown as 'True': a flag's default is its absence."""
    text = " ".join(_commands()[name].format_help().split())
    assert "(default: True)" not in text and "(default: False)" not in text


def test_picture_has_a_colour_bar_in_px_and_a_black_invalid_swatch() -> None:
    disp = np.tile(np.linspace(0, 40, 300, dtype=np.float32), (100, 1))
    disp[:10] = np.nan
    pic = picture(disp, 40.0)
    assert (pic[:100, :300] == colourise(disp, 40.0)).all()
    lay = legend_layout(300)
    panel = pic[100:]
    x, y, w, h = lay.swatch
    assert (panel[y + 2:y + h - 2, x + 2:x + w - 2] == 0).all()
    bx, by, bw, bh = lay.bar
    bar = panel[by + bh // 2, bx:bx + bw].astype(int)
    for d in (5.0, 20.0, 35.0):  # the bar at d px has the colour of a map pixel at d px
        col = int(np.argmin(np.abs(disp[50] - d)))
        at = int(round(d / 40.0 * (bw - 1)))
        assert np.abs(bar[at] - pic[50, col].astype(int)).max() <= 12
    assert cv2.imencode(".png", pic)[0]
