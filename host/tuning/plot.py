"""The tuning figure: the paper's Figure 9 (bad % per iteration with the best-so-far line) and
the Q table as a heat map, in one PNG."""

from __future__ import annotations

import io
import os

import numpy as np

from host.files import write_bytes_atomic
from host.tuning.learners import TuneResult


def _label(result: TuneResult, state: tuple[int, ...]) -> str:
    return ", ".join(f"{v}" for v in result.space.values(state).values())


def plot(result: TuneResult, path: str | os.PathLike[str], max_rows: int = 30) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5), width_ratios=[1.3, 1])
    it = np.arange(1, len(result.history) + 1)
    ax1.plot(it, [b for _, b in result.history], "o-", ms=3, lw=1,
             label="bad % at the visited state")
    ax1.step(it, result.best_so_far(), where="post", lw=2, label="best so far")
    ax1.set(xlabel="iteration", ylabel="bad pixels (%)",
            title=f"{result.method} on {result.space.name}: best {result.best_bad:.2f}% at "
                  f"{_label(result, result.best_state)} ({result.evaluations} evaluations)")
    ax1.xaxis.get_major_locator().set_params(integer=True)
    ax1.grid(alpha=0.3)
    ax1.legend()
    if result.q_table:
        states = sorted(result.q_table, key=lambda s: -np.abs(result.q_table[s]).sum())[:max_rows]
        states.sort()
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
        ax2.set_title("Q table (rows: states, most-updated first)")
        fig.colorbar(im, ax=ax2, label="Q (points of bad %)")
    else:
        ax2.axis("off")
        ax2.text(0.5, 0.5, f"{result.method}: no Q table", ha="center", va="center")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    write_bytes_atomic(path, buf.getvalue())
