"""The tuning figure: the paper's Figure 9 (bad % per iteration with the best-so-far line) and
the Q table as a heat map, in one PNG."""

from __future__ import annotations

import io
import os

import numpy as np

from host.files import write_bytes_atomic
from host.tuning.learners import TuneResult

STARTS = ("paper", "guided", "qlearning")  # learners that walk from a start state
UNITS = {"block_size": "block size (px)", "lr_fill": "LR check with fill (px)"}


def _value(v: object) -> str:
    if v is None:  # lr_fill's None is the check switched off
        return "off"
    return f"{v:g}" if isinstance(v, float) else str(v)


def _label(result: TuneResult, state: tuple[int, ...]) -> str:
    return ", ".join(_value(v) for v in result.space.values(state).values())


def _named(result: TuneResult, state: tuple[int, ...]) -> str:
    return ", ".join(f"{k} {_value(v)}" for k, v in result.space.values(state).items())


def _q_rows(result: TuneResult, max_rows: int) -> tuple[list[tuple[int, ...]], str]:
    """The Q table's rows and the title that says their order: one parameter, every state by
    its value; several, the states of largest |Q| (the most-learned) first."""
    if len(result.space.dims) == 1:
        return sorted(result.q_table), "Q table (rows: every state, smallest first)"
    by_use = sorted(result.q_table, key=lambda s: (-np.abs(result.q_table[s]).sum(), s))
    n = min(max_rows, len(by_use))
    return by_use[:n], f"Q table (rows: the {n} states of largest |Q|, largest first)"


def series(result: TuneResult) -> tuple[np.ndarray, np.ndarray]:
    """(iteration, score) of the first panel. A Q-learner evaluates its start state before its
    first step: that is iteration 0; grid, random and tpe evaluate theirs as iteration 1."""
    history = [b for _, b in result.history]
    if result.method in STARTS:
        return np.arange(len(history) + 1), np.array([result.visited[0][1], *history])
    return np.arange(1, len(history) + 1), np.array(history)


def figure_title(result: TuneResult, scenes: tuple[str, ...] = ()) -> str:
    """What was tuned on what, and the best state with its parameters named."""
    over = f" over {', '.join(scenes)}" if scenes else ""
    return (f"{result.method} on {result.space.name}{over}\nbest {result.best_bad:.2f}% at "
            f"{_named(result, result.best_state)} ({result.evaluations} evaluations)")


def plot(result: TuneResult, path: str | os.PathLike[str], max_rows: int = 30,
         score: str = "bad pixels (%)", scenes: tuple[str, ...] = ()) -> None:
    """Write the figure; score names what the learner minimised (for the y axis), scenes what
    it was tuned on (for the title). Iteration 0 is the start state (the first evaluated)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5), width_ratios=[1.3, 1])
    it, scores = series(result)
    ax1.plot(it, scores, "o-", ms=3, lw=1, label="score of the visited state")
    ax1.plot(it[:1], scores[:1], "s", ms=7, color="C2",
             label=f"start: {_named(result, result.visited[0][0])}")
    ax1.step(it, np.minimum.accumulate(scores), where="post", lw=2, label="best so far")
    ax1.set(xlabel="iteration (learner step; 0 = start state)" if result.method in STARTS
            else "iteration", ylabel=score, title=figure_title(result, scenes))
    ax1.xaxis.get_major_locator().set_params(integer=True)
    ax1.grid(alpha=0.3)
    ax1.legend()
    if result.q_table:
        states, title = _q_rows(result, max_rows)
        table = np.array([result.q_table[s] for s in states])
        if len(result.space.dims) == 1:
            cols = ["shrink", "keep", "grow"]
        else:
            cols = ["keep"] + [f"{d.name}{'+' if sign > 0 else '-'}"
                               for d in result.space.dims for sign in (-1, 1)]
        lim = max(float(np.abs(table).max()), 1e-9)
        im = ax2.imshow(table, cmap="RdBu", vmin=-lim, vmax=lim, aspect="auto")
        ax2.set_xticks(range(len(cols)), cols, rotation=60, ha="right", fontsize=8)
        ax2.set_yticks(range(len(states)), [_label(result, s) for s in states], fontsize=7)
        ax2.set_ylabel(", ".join(UNITS.get(d.name, d.name) for d in result.space.dims))
        ax2.set_xlabel("action")
        ax2.set_title(title)
        fig.colorbar(im, ax=ax2, label=f"Q (points of {score})")
    else:
        ax2.axis("off")
        ax2.text(0.5, 0.5, f"{result.method}: no Q table", ha="center", va="center")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    write_bytes_atomic(path, buf.getvalue())
