"""The tuning figure: the paper's Figure 9 (bad % per iteration with the best-so-far line) and
the Q table as a heat map, in one PNG."""

from __future__ import annotations

import io
import os

import numpy as np

from host.files import write_bytes_atomic
from host.tuning.learners import TuneResult

UNITS = {"block_size": "window (px)", "lr_fill": "LR check with fill (px)"}


def _label(result: TuneResult, state: tuple[int, ...]) -> str:
    return ", ".join(f"{v}" for v in result.space.values(state).values())


def _q_rows(result: TuneResult, max_rows: int) -> tuple[list[tuple[int, ...]], str]:
    """The Q table's rows and the title that says their order: one parameter, every state by
    its value; several, the states of largest |Q| (the most-learned) first."""
    if len(result.space.dims) == 1:
        return sorted(result.q_table), "Q table (rows: every state, smallest first)"
    by_use = sorted(result.q_table, key=lambda s: (-np.abs(result.q_table[s]).sum(), s))
    n = min(max_rows, len(by_use))
    return by_use[:n], f"Q table (rows: the {n} states of largest |Q|, largest first)"


def plot(result: TuneResult, path: str | os.PathLike[str], max_rows: int = 30,
         score: str = "bad pixels (%)") -> None:
    """Write the figure; score names what the learner minimised (for the y axis)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5), width_ratios=[1.3, 1])
    it = np.arange(1, len(result.history) + 1)
    ax1.plot(it, [b for _, b in result.history], "o-", ms=3, lw=1,
             label="score of the visited state")
    ax1.step(it, result.best_so_far(), where="post", lw=2, label="best so far")
    ax1.set(xlabel="iteration (learner step)", ylabel=score,
            title=f"{result.method} on {result.space.name}: best {result.best_bad:.2f}% at "
                  f"{_label(result, result.best_state)} ({result.evaluations} evaluations)")
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
