"""The tuning figure: the start state is always drawn, the title names the scenes and the
parameters, and the LR check switched off reads "off"."""

from __future__ import annotations

from host.stereo import MatcherParams
from host.tuning.learners import TuneResult
from host.tuning.plot import _label, figure_title, series
from host.tuning.spaces import make_space


def _result(method: str, space_name: str = "block-size") -> TuneResult:
    space = make_space(space_name, MatcherParams())
    start, a, b = space.states()[:3]
    # the start state is the best, and the learner never came back to it
    return TuneResult(method, space, start, 8.36, [(start, 8.36), (a, 9.1), (b, 9.7)],
                      [(a, 9.1), (b, 9.7)])


def test_a_q_learners_start_state_is_iteration_zero_even_when_never_revisited() -> None:
    it, scores = series(_result("paper"))
    assert list(it) == [0, 1, 2] and list(scores) == [8.36, 9.1, 9.7]
    assert min(scores) == 8.36  # the best shown is the best found


def test_grid_like_methods_start_at_their_first_evaluation() -> None:
    r = _result("grid")
    r.history.insert(0, r.visited[0])
    it, scores = series(r)
    assert list(it) == [1, 2, 3] and scores[0] == 8.36


def test_the_title_names_scenes_and_parameters_and_lr_off_is_off() -> None:
    r = _result("qlearning", "sad")
    text = figure_title(r, ("cones", "teddy"))
    assert "over cones, teddy" in text
    assert "block_size 5, lr_fill off, matcher sad" in text, text
    assert "None" not in text and "None" not in _label(r, r.visited[1][0])
