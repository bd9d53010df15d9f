"""host tune on real images: the window learner ends near the grid optimum; files and JSON."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from host.cli import main
from host.params_file import load_params
from host.stereo import MatcherParams
from host.stereo.synthetic import synthetic_scene
from host.tuning.backends import make_backend
from host.tuning.disparity_range import RangePolicy
from host.tuning.ground_truth import GroundTruthScore
from host.tuning.learners import tune
from host.tuning.objective import Objective, SceneTable
from host.tuning.spaces import make_space, odd_range

from ..in_process import host


def gt_objective(scenes, space, workers: int = 1) -> Objective:
    ranges = [RangePolicy().resolve(s.left, s.right, gt=s.gt) for s in scenes]
    return Objective.of(SceneTable(make_backend(GroundTruthScore(scenes, ranges), workers),
                                   space.params))


@pytest.fixture(scope="module")
def scene():
    return synthetic_scene(seed=11, width=200, height=150, max_disp=24, noise=2.0)


def test_guided_window_tuning_ends_within_half_a_point_of_the_grid_best(scene) -> None:
    space = make_space("block-size", MatcherParams(num_disparities=32), odd_range("3:27"))
    obj = gt_objective([scene], space)
    best_grid = tune("grid", obj, space, 0, 0).best_bad
    for seed in range(3):
        r = tune("guided", obj, space, 20, seed)
        assert r.best_bad <= best_grid + 0.5, (seed, r.best_bad, best_grid)


def test_tune_writes_params_plot_and_json(tmp_path: Path, capsys) -> None:
    out, fig = tmp_path / "p.toml", tmp_path / "fig.png"
    assert main(["tune", "--method", "paper", "--iterations", "6", "--block-sizes", "7:15",
                 "--out", str(out), "--plot", str(fig), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    for key in ("method", "space", "best_params", "best_bad", "evaluations", "iterations",
                "history"):
        assert key in result
    assert result["method"] == "paper" and result["iterations"] == 6 == len(result["history"])
    assert set(result["history"][0]) == {"params", "bad"}
    params, tuning = load_params(out)
    assert params.block_size == result["best_params"]["block_size"]
    assert tuning["method"] == "paper" and tuning["scenes"] == ["motorcycle"]
    assert abs(tuning["bad"] - result["best_bad"]) < 1e-3
    img = cv2.imread(str(fig))
    assert img is not None and img.shape[1] > 800
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_plain_tune_runs_in_the_measured_conditions(tmp_path: Path, capsys) -> None:
    """The defaults are what docs/tuning.md measured: TPE, clipped borders, the
    ground-truth range from the nonocc percentiles."""
    out = tmp_path / "p.toml"
    assert main(["tune", "--block-sizes", "9:13", "--out", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    params, tuning = load_params(out)
    assert result["method"] == tuning["method"] == "tpe"
    assert params.border == "clip"
    assert main(["tune", "--block-sizes", "9:13", "--border", "invalid", "--out", str(out)]) == 0
    assert load_params(out)[0].border == "invalid"  # what the user names wins


def test_tuned_params_round_trip_into_eval(tmp_path: Path, capsys) -> None:
    out = tmp_path / "p.toml"
    assert main(["tune", "--method", "grid", "--block-sizes", "9:13", "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["eval", "--params", str(out), "--json"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["matcher"]["block_size"] == load_params(out)[0].block_size


def _run(*argv: str) -> tuple[int, str]:
    """host tune in this process: (exit status, stderr)."""
    r = host("tune", *argv)
    return r.returncode, r.stderr


@pytest.mark.parametrize("argv, message", [
    (["--space", "nope"], "invalid choice"),
    (["--method", "nope"], "invalid choice"),
    (["--iterations", "0"], "at least 1"),
    (["--space", "sad", "--method", "paper"], "tunes one parameter"),
    (["--block-sizes", "4:10"], "odd bounds"),
    (["--alpha", "0.5", "--method", "paper"], "belong to --method qlearning"),
    (["--method", "grid", "--gamma", "0.5"], "takes no learning parameters"),
])
def test_bad_input_is_a_one_line_error(argv: list[str], message: str) -> None:
    code, err = _run(*argv)
    assert code == 2 and message in err and err.count("\n") == 1


def test_a_scene_without_ground_truth_is_refused(tmp_path: Path) -> None:
    for name in ("im0.png", "im1.png"):
        cv2.imwrite(str(tmp_path / name), np.zeros((40, 80), np.uint8))
    code, err = _run(str(tmp_path))
    assert code == 2 and "no ground truth" in err


def test_an_interrupted_run_leaves_no_params_file(tmp_path: Path) -> None:
    out = tmp_path / "p.toml"
    out.write_text("[matcher]\nblock_size = 7\n")
    code, _ = _run("--iterations", "0", "--out", str(out))
    assert code == 2 and out.read_text() == "[matcher]\nblock_size = 7\n"


def test_parallel_workers_give_the_same_result_as_one_process(scene) -> None:
    space = make_space("block-size", MatcherParams(num_disparities=32), odd_range("5:11"))
    one = gt_objective([scene], space)
    two = gt_objective([scene], space, workers=2)
    try:
        a, b = tune("grid", one, space, 0, 0), tune("grid", two, space, 0, 0)
    finally:
        two.close()
    assert a.history == b.history and b.evaluations == space.size


def test_learning_parameters_reach_the_learner(capsys) -> None:
    argv = ["tune", "--method", "qlearning", "--iterations", "12", "--block-sizes", "7:13",
            "--json", "--seed", "2"]
    assert main(argv + ["--epsilon", "0.0", "--episodes", "1"]) == 0
    greedy = json.loads(capsys.readouterr().out)["history"]
    assert main(argv + ["--epsilon", "1.0", "--episodes", "1"]) == 0
    random_walk = json.loads(capsys.readouterr().out)["history"]
    assert greedy != random_walk


def test_the_job_runs_without_writing_and_the_report_writes(tmp_path: Path, capsys) -> None:
    """host tune in its three steps: the checked job, a run that writes and prints nothing, and
    the report that writes the parameters and prints the line."""
    from host.cli import build_parser
    from host.commands.tune import TuneJob, report, run_job

    out = tmp_path / "p.toml"
    args = build_parser("host").parse_args(["tune", "--method", "grid", "--block-sizes", "7:11",
                                            "--out", str(out)])
    job = TuneJob.from_args(args)
    assert (job.method, job.iterations, [s.name for s in job.tuned_on]) == \
        ("grid", 0, ["motorcycle"])
    done = run_job(job)
    assert not out.exists() and capsys.readouterr() == ("", "")
    assert done.result.evaluations == 3 and done.best.block_size in (7, 9, 11)
    report(job, done)
    assert load_params(out)[0] == done.best
    assert capsys.readouterr().out.startswith("grid on block-size over motorcycle: best ")
