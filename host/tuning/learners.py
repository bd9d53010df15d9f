"""Tuning methods over a Space, all paying in distinct objective evaluations.

- paper: the paper's learner exactly. States are window sizes, actions shrink / keep / grow, Q
  starts at zero, the start state is drawn at random, and each of its 20 iterations takes the
  action with the largest Q (ties drawn at random, keep included) and applies the paper's
  equation 6, Q(s, a) = R(s, a) + gamma * max Q(s', .), gamma 0.8.
- guided: the same states, actions and update with heuristics added to make it a reliable
  hill-climber: epsilon-greedy (0.2), ties never go to keep, and among tied moves it repeats
  one that improved and undoes one that did not.
- qlearning: standard Q-learning, Q += alpha * (R + gamma * max Q(s', .) - Q), epsilon decaying
  over the run, in episodes that start from a random state or from the best state found so far.
- grid: every state. random: states drawn without replacement.
- tpe: Optuna's Tree-structured Parzen Estimator (multivariate), the standard optimiser, as a
  baseline (Optuna, a dependency: host tune's default method).

The reward is the improvement of the bad-pixel rate, R(s, a) = bad(s) - bad(s') in percentage
points: positive for a move to a better state, zero for keep. With Q starting at zero, an untried
action looks better than a tried worse one, so the learners explore the neighbours of a state
before they settle.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from host.errors import HostError
from host.tuning.objective import Objective, State
from host.tuning.spaces import Space

METHODS = ("paper", "guided", "qlearning", "grid", "random", "tpe")


class Run:
    """The objective as one run sees it: remembers which states this run evaluated, in order
    (the objective's cache may be shared between runs, as in the benchmark)."""

    def __init__(self, obj: Objective) -> None:
        self.obj = obj
        self.parallel = obj.parallel
        self.visited: dict[State, float] = {}

    def __call__(self, state: State) -> float:
        if state not in self.visited:
            self.visited[state] = self.obj(state)
        return self.visited[state]

    def many(self, states: list[State]) -> list[float]:
        for s, bad in zip(states, self.obj.many(states)):
            self.visited.setdefault(s, bad)
        return [self.visited[s] for s in states]

    def best(self) -> tuple[State, float]:
        state = min(self.visited, key=lambda s: (self.visited[s], s))
        return state, self.visited[state]


@dataclass(frozen=True)
class Move:
    """One step of a Q learner on one parameter: from state s, action a (0 shrink, 1 keep,
    2 grow), the reward it earned and the state it reached."""

    s: int
    a: int
    reward: float
    s_next: int


@dataclass
class TuneResult:
    method: str
    space: Space
    best_state: State
    best_bad: float
    visited: list[tuple[State, float]]  # distinct states in the order this run evaluated them
    history: list[tuple[State, float]]  # one entry per iteration: state visited, its bad %
    q_table: dict[State, np.ndarray] = field(default_factory=dict)
    moves: list[Move] = field(default_factory=list)  # paper and guided: every step, in order

    @property
    def evaluations(self) -> int:
        return len(self.visited)

    def evaluations_to_reach(self, target: float) -> int | None:
        """Distinct evaluations this run needed before one scored <= target (None: never)."""
        for i, (_, bad) in enumerate(self.visited):
            if bad <= target:
                return i + 1
        return None

    def best_so_far(self) -> list[float]:
        out, best = [], float("inf")
        for _, bad in self.history:
            best = min(best, bad)
            out.append(best)
        return out

    def to_json(self) -> dict[str, Any]:
        return {"method": self.method, "space": self.space.name,
                "best_params": self.space.values(self.best_state), "best_bad": self.best_bad,
                "evaluations": self.evaluations, "iterations": len(self.history),
                "history": [{"params": self.space.values(s), "bad": b} for s, b in self.history]}


def paper_update(q: np.ndarray, s: int, a: int, reward: float, s_next: int,
                 gamma: float) -> None:
    """The paper's equation 6: Q(s, a) = R(s, a) + gamma * max over a' of Q(s', a')."""
    q[s, a] = reward + gamma * q[s_next].max()


def q_update(q: dict[State, np.ndarray], s: State, a: int, reward: float, s_next: State,
             alpha: float, gamma: float) -> None:
    """Q-learning: Q(s, a) += alpha * (R + gamma * max Q(s', .) - Q(s, a))."""
    q[s][a] += alpha * (reward + gamma * q[s_next].max() - q[s][a])


def _greedy(values: np.ndarray, epsilon: float, rng: np.random.Generator, keep: int,
            prefer: int | None) -> int:
    """Epsilon-greedy over Q. Ties never go to keep (it earns nothing and teaches nothing while
    a neighbour is untried, so keep wins only when strictly best); among tied moves, prefer
    the one the last reward favours: repeat a move that improved, undo one that did not."""
    if rng.random() < epsilon:
        return int(rng.integers(len(values)))
    best = np.flatnonzero(values == values.max())
    if len(best) == 1:
        return int(best[0])
    best = best[best != keep]
    if prefer is not None and prefer in best:
        return prefer
    return int(rng.choice(best))


def _result(method: str, space: Space, run: Run, history: list[tuple[State, float]],
            q: dict[State, np.ndarray] | None = None, moves: list[Move] | None = None
            ) -> TuneResult:
    best, best_bad = run.best()
    return TuneResult(method, space, best, best_bad, list(run.visited.items()), history, q or {},
                      moves or [])


def _one_dimension(space: Space, method: str) -> int:
    if len(space.dims) != 1:
        raise HostError(f"the {method} learner tunes one parameter; space {space.name} has "
                        f"{len(space.dims)} (use --method qlearning)")
    return space.shape[0]


def _equation_6(method: str, obj: Run, space: Space, iterations: int, rng: np.random.Generator,
                gamma: float, step: int, on_step: Callable[[], None] | None,
                choose: Callable[[np.ndarray, Move | None], int]) -> TuneResult:
    """The paper's loop on one parameter: Q from zeros, a random start state, then at each step
    the action choose() takes from the state's Q row (and the last move), and equation 6."""
    n = _one_dimension(space, "paper's" if method == "paper" else method)
    q = np.zeros((n, 3))  # actions: shrink, keep, grow
    s = int(rng.integers(n))
    bad_s = obj((s,))
    history: list[tuple[State, float]] = []
    moves: list[Move] = []
    for _ in range(iterations):
        a = choose(q[s], moves[-1] if moves else None)
        s2 = min(max(s + (a - 1) * step, 0), n - 1)
        bad2 = obj((s2,))
        moves.append(Move(s, a, bad_s - bad2, s2))
        paper_update(q, s, a, bad_s - bad2, s2, gamma)
        s, bad_s = s2, bad2
        history.append(((s2,), bad2))
        if on_step:
            on_step()
    return _result(method, space, obj, history, {(i,): q[i].copy() for i in range(n)}, moves)


def paper(obj: Run, space: Space, iterations: int, rng: np.random.Generator,
          gamma: float = 0.8, epsilon: float = 0.0, step: int = 1,
          on_step: Callable[[], None] | None = None) -> TuneResult:
    """The paper's learner as published: greedy on Q with random tie-breaks, equation 6."""

    def choose(row: np.ndarray, last: Move | None) -> int:
        if rng.random() < epsilon:
            return int(rng.integers(3))
        return int(rng.choice(np.flatnonzero(row == row.max())))

    return _equation_6("paper", obj, space, iterations, rng, gamma, step, on_step, choose)


def guided(obj: Run, space: Space, iterations: int, rng: np.random.Generator,
           gamma: float = 0.8, epsilon: float = 0.2, step: int = 1,
           on_step: Callable[[], None] | None = None) -> TuneResult:
    """Equation 6 with the hill-climbing heuristics (see the module's docstring)."""

    def choose(row: np.ndarray, last: Move | None) -> int:
        # repeat an improving move, else undo it
        prefer = None if last is None else last.a if last.reward > 0 else 2 - last.a
        return _greedy(row, epsilon, rng, keep=1, prefer=prefer)

    return _equation_6("guided", obj, space, iterations, rng, gamma, step, on_step, choose)


def qlearning(obj: Run, space: Space, iterations: int, rng: np.random.Generator,
              episodes: int = 20, alpha: float = 0.5, gamma: float = 0.9, epsilon: float = 0.3,
              epsilon_final: float = 0.02, restart_best: float = 0.9, step: int = 1,
              on_step: Callable[[], None] | None = None) -> TuneResult:
    actions = space.actions
    opposite = [actions.index((d, -sign)) if d >= 0 else 0 for d, sign in actions]
    q: dict[State, np.ndarray] = defaultdict(lambda: np.zeros(len(actions)))
    final = min(epsilon_final, epsilon)
    decay = (final / epsilon) ** (1 / max(1, iterations - 1)) if epsilon > 0 else 1.0
    per_episode = -(-iterations // episodes)
    history: list[tuple[State, float]] = []
    states = space.states()
    for _ in range(episodes):
        if history and rng.random() < restart_best:
            s = obj.best()[0]
        else:
            s = states[int(rng.integers(len(states)))]
        bad_s = obj(s)
        prefer = None
        for _ in range(per_episode):
            if len(history) == iterations:
                break
            a = _greedy(q[s], epsilon * decay ** len(history), rng, keep=0, prefer=prefer)
            s2 = space.move(s, actions[a], step)
            bad2 = obj(s2)
            reward = bad_s - bad2
            q_update(q, s, a, reward, s2, alpha, gamma)
            prefer = a if reward > 0 else opposite[a]
            s, bad_s = s2, bad2
            history.append((s2, bad2))
            if on_step:
                on_step()
    return _result("qlearning", space, obj, history, dict(q))


def _in_batches(obj: Run, states: list[State], on_step: Callable[[], None] | None
                ) -> list[tuple[State, float]]:
    """Evaluate states in order, a batch at a time (as many as the objective runs at once, so
    progress shows as it goes); one history entry per state."""
    batch = obj.parallel
    history = []
    for i in range(0, len(states), batch):
        part = states[i:i + batch]
        for s, bad in zip(part, obj.many(part)):
            history.append((s, bad))
            if on_step:
                on_step()
    return history


def grid(obj: Run, space: Space, on_step: Callable[[], None] | None = None) -> TuneResult:
    return _result("grid", space, obj, _in_batches(obj, space.states(), on_step))


def random_search(obj: Run, space: Space, iterations: int, rng: np.random.Generator,
                  on_step: Callable[[], None] | None = None) -> TuneResult:
    states = space.states()
    picked = [states[i] for i in rng.permutation(len(states))[:iterations]]
    return _result("random", space, obj, _in_batches(obj, picked, on_step))


def tpe(obj: Run, space: Space, iterations: int, seed: int,
        on_step: Callable[[], None] | None = None) -> TuneResult:
    """Optuna's multivariate TPE sampler over the space's indices (categories for cyclic
    dimensions, integers for ordered ones); a trial that repeats a state costs nothing more."""
    try:
        import optuna
    except ImportError:
        raise HostError("--method tpe needs Optuna: pip install optuna") from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    sampler = optuna.samplers.TPESampler(seed=seed, multivariate=True)
    study = optuna.create_study(sampler=sampler)
    history: list[tuple[State, float]] = []

    def objective(trial: Any) -> float:
        state = tuple(trial.suggest_categorical(d.name, list(range(len(d.values)))) if d.cyclic
                      else trial.suggest_int(d.name, 0, len(d.values) - 1) for d in space.dims)
        bad = obj(state)
        history.append((state, bad))
        if on_step:
            on_step()
        return bad

    study.optimize(objective, n_trials=iterations)
    return _result("tpe", space, obj, history)


def tune(method: str, obj: Objective, space: Space, iterations: int, seed: int,
         on_step: Callable[[], None] | None = None, **hyper: Any) -> TuneResult:
    """Run a method by name; iterations is ignored by grid (it visits every state)."""
    if iterations < 1 and method != "grid":
        raise HostError(f"iterations must be at least 1, got {iterations}")
    rng = np.random.default_rng(seed)
    run = Run(obj)
    if method == "paper":
        return paper(run, space, iterations, rng, on_step=on_step, **hyper)
    if method == "guided":
        return guided(run, space, iterations, rng, on_step=on_step, **hyper)
    if method == "tpe":
        return tpe(run, space, iterations, seed, on_step=on_step)
    if method == "qlearning":
        return qlearning(run, space, iterations, rng, on_step=on_step, **hyper)
    if method == "grid":
        return grid(run, space, on_step=on_step)
    if method == "random":
        return random_search(run, space, iterations, rng, on_step=on_step)
    raise HostError(f"unknown method {method!r} (choose from {', '.join(METHODS)})")
