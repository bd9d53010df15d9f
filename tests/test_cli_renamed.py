"""One name for a matcher parameter on the command line, in params files and in code
(--block-size / block_size ...): the former spellings still read, each with one note line
naming the new one; a params-file key spelt the command-line way is refused naming its key."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from host.api import load_params_file
from host.cli import build_parser
from host.errors import HostError
from host.params_file import save_params
from host.stereo import MatcherParams
from host.stereo.synthetic import synthetic_scene
from host.tuning import make_space
from tests.in_process import host


@pytest.fixture()
def pair(tmp_path: Path) -> list[str]:
    s = synthetic_scene(seed=3, width=96, height=64, max_disp=12)
    for name, image in (("l.png", s.left), ("r.png", s.right)):
        cv2.imwrite(str(tmp_path / name), image)
    return ["disparity", str(tmp_path / "l.png"), str(tmp_path / "r.png")]


def test_the_old_spellings_give_the_same_map_with_one_note_each(
        tmp_path: Path, pair: list[str]) -> None:
    maps = {}
    for how, flags in (("new", ["--block-size", "7", "--num-disparities", "16",
                                "--min-disparity", "2", "--uniqueness-ratio", "15",
                                "--no-colour"]),
                       ("old", ["--window", "7", "--num-disp", "16", "--min-disp", "2",
                                "--uniqueness", "15", "--grey"])):
        npy = tmp_path / f"{how}.npy"
        r = host(*pair, "-o", str(tmp_path / f"{how}.png"), "--npy", str(npy), *flags)
        assert r.returncode == 0, r.stderr
        maps[how] = np.load(npy)
        notes = [line for line in r.stderr.splitlines() if line.startswith("note:")]
        if how == "new":
            assert notes == []
        else:
            assert notes == ["note: --window is now --block-size (the old spelling will go)",
                             "note: --num-disp is now --num-disparities (the old spelling will go)",
                             "note: --min-disp is now --min-disparity (the old spelling will go)",
                             "note: --uniqueness is now --uniqueness-ratio (the old spelling will "
                             "go)",
                             "note: --grey is now --no-colour (the old spelling will go)"]
    np.testing.assert_array_equal(maps["old"], maps["new"])


def test_the_old_spellings_give_the_same_parameters(capsys: pytest.CaptureFixture[str]) -> None:
    from host.commands.options import params_from_args

    def params(*flags: str) -> MatcherParams:
        args = build_parser("host").parse_args(["disparity", "l.png", "r.png", "-o", "o.png",
                                                *flags])
        return params_from_args(args)

    old = params("--grey", "--uniqueness", "15")
    assert old == params("--no-colour", "--uniqueness-ratio", "15")
    assert not old.colour and old.uniqueness_ratio == 15
    assert params("--grey", "--colour").colour  # the later one wins, as with any flag pair
    capsys.readouterr()


def test_the_old_spellings_are_not_in_the_help() -> None:
    for command in ("eval", "disparity", "tune", "servo"):
        text = host(command, "--help").stdout
        assert "--block-size" in text and "--num-disparities" in text
        assert "--uniqueness-ratio" in text and "--no-colour" in text
        assert "--window " not in text and "--num-disp " not in text and "--windows" not in text
        assert "--uniqueness " not in text and "--grey" not in text


def test_tune_reads_the_old_space_and_range_names(capsys: pytest.CaptureFixture[str]) -> None:
    from host.commands.tune import TuneJob

    args = build_parser("host").parse_args(["tune", "--space", "window", "--windows", "7:11",
                                            "--method", "grid"])
    job = TuneJob.from_args(args)
    assert job.space.name == "block-size"
    assert job.space.dims[0].name == "block_size" and job.space.dims[0].values == (7, 9, 11)
    assert capsys.readouterr().err.splitlines() == [
        "note: --space window is now block-size (the old name will go)",
        "note: --windows is now --block-sizes (the old spelling will go)"]


def test_make_space_names_the_new_name_of_the_old_one() -> None:
    with pytest.raises(HostError, match="unknown space 'window' \\(now 'block-size'; choose"):
        make_space("window", MatcherParams())


def test_an_old_params_file_is_read_with_its_space_renamed(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "old.toml"
    save_params(path, MatcherParams(block_size=7), {"method": "grid", "space": "window"})
    f = load_params_file(path)
    assert f.params.block_size == 7 and f.tuning == {"method": "grid", "space": "block-size"}
    assert capsys.readouterr().err == (f"note: {path}: [tuning] space 'window' is now "
                                       f"'block-size' (read as such)\n")


@pytest.mark.parametrize("key, new", [("window", "block_size"), ("num_disp", "num_disparities"),
                                      ("num-disp", "num_disparities"),
                                      ("min_disp", "min_disparity"),
                                      ("uniqueness", "uniqueness_ratio")])
def test_a_matcher_key_spelt_the_command_line_way_is_refused_naming_the_key(
        tmp_path: Path, pair: list[str], key: str, new: str) -> None:
    path = tmp_path / "p.toml"
    path.write_text(f'[matcher]\nmatcher = "sad"\n"{key}" = 7\n')
    out = tmp_path / "o.png"
    r = host(*pair, "-o", str(out), "--params", str(path))
    assert r.returncode == 2 and not out.exists()
    assert r.stderr == (f"host disparity: error: {path}: [matcher] key {key} is {new} in a "
                        f"params file\n")
