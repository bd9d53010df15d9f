"""Params files start from the named matcher's measured defaults and keep the scene's range."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from host.api import StereoMatcher, load_params_file
from host.commands.options import add_matcher_options, params_from_args
from host.params_file import load_params, save_params
from host.stereo.params import MatcherParams
from host.tuning.disparity_range import RangePolicy

SGM = MatcherParams.for_matcher("sgm")


def _file(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "p.toml"
    path.write_text(text)
    return path


def test_a_file_naming_a_matcher_starts_from_its_measured_defaults(tmp_path: Path) -> None:
    # the defect: this file gave the plain dataclass defaults (window 9, border invalid, 5 paths)
    path = _file(tmp_path, '[matcher]\nmatcher = "sgm"\np2_adapt = 0.0\n')
    assert load_params(path)[0] == SGM.replace(p2_adapt=0.0)
    assert load_params(_file(tmp_path, "[matcher]\nblock_size = 7\n"))[0] == MatcherParams(
        block_size=7)


def test_the_command_line_overrides_the_file(tmp_path: Path) -> None:
    path = _file(tmp_path, '[matcher]\nmatcher = "sgm"\np2_adapt = 0.0\n')
    p = argparse.ArgumentParser()
    add_matcher_options(p)
    args = p.parse_args(["--params", str(path), "--paths", "8", "--lr-check", "off"])
    assert params_from_args(args) == SGM.replace(p2_adapt=0.0, paths=8, lr_check=None)


@pytest.mark.parametrize("policy", [None, RangePolicy("coarse", 2.0)])
@pytest.mark.parametrize("params", [SGM.replace(lr_check=None, median=0, num_disparities=48),
                                    SGM, MatcherParams("ncc", 7, lr_check=1.0)])
def test_saved_params_read_back_as_saved(tmp_path: Path, params: MatcherParams,
                                         policy: RangePolicy | None) -> None:
    """Every field, LR off included (its default is on for sgm: the file says "off")."""
    path = tmp_path / "tuned.toml"
    save_params(path, params, {"method": "tpe"},
                disparity_range=policy.to_table() if policy else None)
    got = load_params(path)[0]
    if policy:
        got = got.replace(num_disparities=params.num_disparities)
    assert got == params


def test_lr_check_off_in_a_file(tmp_path: Path) -> None:
    path = _file(tmp_path, '[matcher]\nmatcher = "sgm"\nlr_check = "off"\n')
    assert load_params(path)[0] == SGM.replace(lr_check=None)
    with pytest.raises(Exception, match="lr_check"):
        load_params(_file(tmp_path, '[matcher]\nmatcher = "sgm"\nlr_check = "on"\n'))


def test_a_file_without_a_range_keeps_the_range_policy_in_the_api(tmp_path: Path) -> None:
    """Neither [disparity_range] nor num_disparities: each pair gets its range from the policy
    StereoMatcher.create uses (coarse), not the dataclass's 64; a fixed range stays fixed."""
    path = _file(tmp_path, '[matcher]\nmatcher = "sgm"\n')
    assert load_params_file(path).range_policy == RangePolicy.parse("coarse")
    assert StereoMatcher.load(path).range_policy == RangePolicy.parse("coarse")
    path = _file(tmp_path, '[matcher]\nmatcher = "sgm"\nnum_disparities = 32\n')
    assert load_params_file(path).range_policy is None
    assert load_params_file(path).params.num_disparities == 32


@pytest.mark.parametrize("matcher", ["sgm", "sad", "ncc", "opencv-sgbm"])
def test_the_api_starts_from_the_defaults_the_command_line_gives(matcher: str) -> None:
    """StereoMatcher.create("sgm") is `--matcher sgm`: window 1, 4 paths, LR, fill ... (it gave
    the plain dataclass defaults, block_size 9 over sgm's window 1); what is given overrides."""
    p = argparse.ArgumentParser()
    add_matcher_options(p)
    cli = params_from_args(p.parse_args(["--matcher", matcher]))
    assert StereoMatcher.create(matcher).params == cli
    cli = params_from_args(p.parse_args(["--matcher", matcher, "--block-size", "5",
                                         "--num-disparities", "32"]))
    assert StereoMatcher.create(matcher, block_size=5, num_disparities=32).params == cli
