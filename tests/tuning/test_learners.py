"""Tuning methods on landscapes known in advance (no images), and the paper's update rule."""

from __future__ import annotations

import numpy as np
import pytest

from host.errors import HostError
from host.stereo.params import MatcherParams
from host.tuning.learners import paper_update, q_update, tune
from host.tuning.objective import Objective
from host.tuning.spaces import Dimension, Space, make_space


def test_paper_update_rule_on_a_three_state_example() -> None:
    # Q(s, a) = R(s, a) + gamma * max_a' Q(s', a'), by hand:
    q = np.array([[0.0, 0.0, 0.0],
                  [0.0, 0.0, 2.0],
                  [1.0, -3.0, 0.5]])
    paper_update(q, s=0, a=2, reward=1.5, s_next=1, gamma=0.8)
    assert q[0, 2] == pytest.approx(1.5 + 0.8 * 2.0)  # 3.1
    paper_update(q, s=1, a=2, reward=-0.5, s_next=2, gamma=0.8)
    assert q[1, 2] == pytest.approx(-0.5 + 0.8 * 1.0)  # 0.3
    paper_update(q, s=2, a=1, reward=0.0, s_next=2, gamma=0.8)
    assert q[2, 1] == pytest.approx(0.0 + 0.8 * 1.0)  # keep: max over the row as it was
    assert q.tolist() == [[0, 0, pytest.approx(3.1)], [0, 0, pytest.approx(0.3)],
                          [1.0, pytest.approx(0.8), 0.5]]


def test_q_learning_update_rule() -> None:
    from collections import defaultdict

    q = defaultdict(lambda: np.zeros(3))
    q[(1,)] = np.array([0.0, 4.0, -1.0])
    q_update(q, (0,), 2, reward=2.0, s_next=(1,), alpha=0.5, gamma=0.9)
    assert q[(0,)][2] == pytest.approx(0.5 * (2.0 + 0.9 * 4.0))


WINDOW = Space("block-size", (Dimension("block_size", tuple(range(5, 42, 2))),), MatcherParams())
FOUR_D = Space("four", (Dimension("a", tuple(range(12))), Dimension("b", tuple(range(6))),
                        Dimension("c", ("x", "y", "z"), cyclic=True),
                        Dimension("d", tuple(range(5)))), MatcherParams())


def bowl_1d(state) -> float:
    return 10 + 0.3 * (state[0] - 11) ** 2  # optimum at index 11 (window 27)


def bowl_4d(state) -> float:
    a, b, c, d = state
    return 5 + 0.4 * abs(a - 7) + 0.8 * abs(b - 2) + (0.0, 2.5, 1.0)[c] + 0.6 * abs(d - 4)


@pytest.mark.parametrize("method, iterations", [("paper", 30), ("guided", 30),
                                                ("qlearning", 200), ("grid", 0), ("random", 19),
                                                ("tpe", 60)])
def test_each_method_finds_the_optimum_of_a_1d_bowl(method: str, iterations: int) -> None:
    for seed in range(5):
        r = tune(method, Objective(bowl_1d), WINDOW, iterations, seed)
        assert r.best_state == (11,) and r.best_bad == 10.0


@pytest.mark.parametrize("method, iterations", [("qlearning", 600), ("grid", 0)])
def test_multi_parameter_methods_find_the_optimum_of_a_4d_landscape(method, iterations) -> None:
    for seed in range(5):
        r = tune(method, Objective(bowl_4d), FOUR_D, iterations, seed)
        assert r.best_state == (7, 2, 0, 4)
    if method == "qlearning":
        assert r.evaluations < FOUR_D.size * 0.3


def test_the_paper_learner_is_greedy_equation_6_from_zeros() -> None:
    # its moves, replayed from a Q of zeros with equation 6: each action was greedy on the Q
    # of its time, and the replay ends on the learner's own Q table
    starts = set()
    for seed in range(8):
        r = tune("paper", Objective(bowl_1d), WINDOW, 20, seed)
        assert len(r.moves) == len(r.history) == 20
        q = np.zeros((WINDOW.shape[0], 3))
        for m in r.moves:
            assert q[m.s, m.a] == q[m.s].max()  # greedy (ties drawn at random)
            assert m.s_next == min(max(m.s + m.a - 1, 0), WINDOW.shape[0] - 1)
            assert m.reward == pytest.approx(bowl_1d((m.s,)) - bowl_1d((m.s_next,)))
            paper_update(q, m.s, m.a, m.reward, m.s_next, gamma=0.8)
        np.testing.assert_array_equal(q, [r.q_table[(i,)] for i in range(WINDOW.shape[0])])
        assert [(m.s_next,) for m in r.moves] == [s for s, _ in r.history]
        assert all(a.s_next == b.s for a, b in zip(r.moves, r.moves[1:]))
        starts.add(r.moves[0].s)
    assert len(starts) > 3  # a random start state


def test_tpe_is_reproducible_and_counts_repeated_trials_once() -> None:
    pytest.importorskip("optuna", reason="Optuna is not installed")
    a = tune("tpe", Objective(bowl_4d), FOUR_D, 40, seed=1)
    b = tune("tpe", Objective(bowl_4d), FOUR_D, 40, seed=1)
    assert a.history == b.history and len(a.history) == 40
    assert a.evaluations == len({s for s, _ in a.history})


def test_runs_are_reproducible_with_a_seed() -> None:
    a = tune("qlearning", Objective(bowl_4d), FOUR_D, 300, seed=3)
    b = tune("qlearning", Objective(bowl_4d), FOUR_D, 300, seed=3)
    c = tune("qlearning", Objective(bowl_4d), FOUR_D, 300, seed=4)
    assert a.history == b.history and a.visited == b.visited
    assert a.history != c.history


def test_evaluations_count_distinct_states_only() -> None:
    calls = []
    obj = Objective(lambda s: calls.append(s) or bowl_1d(s))
    r = tune("paper", obj, WINDOW, 40, seed=0)
    assert r.evaluations == len(set(s for s, _ in r.visited)) == len(calls)
    assert len(r.history) == 40 > r.evaluations


def test_the_paper_learner_refuses_a_multi_parameter_space() -> None:
    with pytest.raises(HostError, match="tunes one parameter"):
        tune("paper", Objective(bowl_4d), FOUR_D, 10, 0)


def test_zero_iterations_and_unknown_method_are_errors() -> None:
    with pytest.raises(HostError, match="at least 1"):
        tune("qlearning", Objective(bowl_1d), WINDOW, 0, 0)
    with pytest.raises(HostError, match="unknown method"):
        tune("annealing", Objective(bowl_1d), WINDOW, 10, 0)


def test_spaces_map_states_to_valid_matcher_parameters() -> None:
    for name in ("block-size", "sad", "opencv-bm", "opencv-sgbm"):
        space = make_space(name, MatcherParams(num_disparities=64))
        for s in space.states()[:: max(1, space.size // 50)]:
            p = space.params(s).validate(width=450)
            if name == "opencv-sgbm":
                assert p.p2 >= p.p1 > 0
