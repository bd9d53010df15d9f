"""The summary of a trial campaign as a safety engineer reads it: the hold rate with its Wilson
95 % interval, the unsafe count with its one-sided 95 % upper bound, outcomes by fault kind, error
and time percentiles; and a picture of the same."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy.stats import beta

OUTCOMES = ("held", "missed", "stopped", "not settled", "unsafe")
Z95 = 1.959963984540054  # two-sided 95 % normal quantile


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of a proportion k/n (95 % by default); (nan, nan) for n = 0."""
    if n == 0:
        return math.nan, math.nan
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return max(0.0, centre - half), min(1.0, centre + half)


def upper_bound(k: int, n: int, confidence: float = 0.95) -> float:
    """One-sided exact (Clopper-Pearson) upper bound of a rate seen k times in n: with none
    seen, 1 - (1 - confidence)^(1/n) (about 3/n)."""
    if n == 0:
        return math.nan
    if k >= n:
        return 1.0
    return float(beta.ppf(confidence, k + 1, n - k))


def _pct(values: Sequence[float], q: float) -> float:
    return float(np.percentile(values, q)) if len(values) else math.nan


def summary(trials: Sequence[Any]) -> dict[str, Any]:
    """Figures of finished trials (objects with outcome, reason, error_m, time_to_hold_s and
    events); the same set of trials gives the same summary whatever order they came in."""
    trials = sorted(trials, key=lambda t: t.index)
    n = len(trials)
    count = {o: sum(t.outcome == o for t in trials) for o in OUTCOMES}
    reached = [t for t in trials if t.outcome in ("held", "missed")]
    errs = [abs(t.error_m) * 100 for t in reached]
    times = [t.time_to_hold_s for t in reached]
    reasons: dict[str, int] = {}
    for t in trials:
        if t.outcome not in ("held", "missed"):
            key = f"{t.outcome}: {t.reason}"
            reasons[key] = reasons.get(key, 0) + 1
    by_fault: dict[str, dict[str, int]] = {}
    for t in trials:
        for kind in sorted(set(t.events)) or ["none"]:
            row = by_fault.setdefault(kind, {"trials": 0, **{o: 0 for o in OUTCOMES}})
            row["trials"] += 1
            row[t.outcome] += 1
    lo, hi = wilson(count["held"], n)
    return {"trials": n, **{o.replace(" ", "_"): count[o] for o in OUTCOMES},
            "hold_rate": count["held"] / n if n else math.nan,
            "hold_rate_wilson95": [lo, hi],
            "unsafe_rate_upper95": upper_bound(count["unsafe"], n),
            "error_cm_p50": _pct(errs, 50), "error_cm_p95": _pct(errs, 95),
            "error_cm_p99": _pct(errs, 99), "error_cm_max": max(errs) if errs else math.nan,
            "time_s_p50": _pct(times, 50), "time_s_p95": _pct(times, 95),
            "time_s_max": max(times) if times else math.nan,
            "by_fault": dict(sorted(by_fault.items())), "reasons": dict(sorted(reasons.items()))}


def lines(s: dict[str, Any]) -> list[str]:
    """The summary in words, one figure a line."""
    lo, hi = s["hold_rate_wilson95"]
    out = [f"held {s['held']}/{s['trials']} ({s['hold_rate']:.1%}, Wilson 95 % {lo:.1%}-"
           f"{hi:.1%}), missed {s['missed']}, safe stops {s['stopped']}, not settled "
           f"{s['not_settled']}, unsafe {s['unsafe']} (rate below {s['unsafe_rate_upper95']:.2%} "
           f"at 95 %)",
           f"|error| p50 {s['error_cm_p50']:.2f} cm, p95 {s['error_cm_p95']:.2f} cm, p99 "
           f"{s['error_cm_p99']:.2f} cm, max {s['error_cm_max']:.2f} cm; time to hold p50 "
           f"{s['time_s_p50']:.1f} s, p95 {s['time_s_p95']:.1f} s, max {s['time_s_max']:.1f} s"]
    for kind, row in s["by_fault"].items():
        bad = ", ".join(f"{row[o]} {o}" for o in OUTCOMES[1:] if row[o])
        out.append(f"  {kind:<16} {row['held']:4d}/{row['trials']:<4d} held"
                   + (f"; {bad}" if bad else ""))
    out += [f"  {v:4d} x {k}" for k, v in s["reasons"].items()]
    return out


def plot(path: Path, s: dict[str, Any], trials: Sequence[Any]) -> None:
    """Outcomes with the hold rate's interval, |error| and time-to-hold distributions, and the
    outcomes by fault kind, in one PNG (written atomically)."""
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from host.files import write_bytes_atomic

    colours = {"held": "tab:green", "missed": "tab:olive", "stopped": "tab:blue",
               "not settled": "tab:orange", "unsafe": "tab:red"}
    fig, ax = plt.subplots(2, 2, figsize=(11, 8))
    counts = [s[o.replace(" ", "_")] for o in OUTCOMES]
    ax[0, 0].bar(OUTCOMES, counts, color=[colours[o] for o in OUTCOMES])
    lo, hi = s["hold_rate_wilson95"]
    ax[0, 0].set_title(f"{s['trials']} trials: held {s['hold_rate']:.1%} (95 % {lo:.1%}-{hi:.1%}),"
                       f" unsafe < {s['unsafe_rate_upper95']:.2%}", fontsize=10)
    errs = [abs(t.error_m) * 100 for t in trials if t.outcome in ("held", "missed")]
    times = [t.time_to_hold_s for t in trials if t.outcome in ("held", "missed")]
    if errs:
        ax[0, 1].hist(errs, bins=30, color="tab:green")
    ax[0, 1].set_xlabel("|depth error| at hold (cm)")
    if times:
        ax[1, 0].hist(times, bins=30, color="tab:gray")
    ax[1, 0].set_xlabel("time to hold (s)")
    kinds = list(s["by_fault"])
    bottom = np.zeros(len(kinds))
    for o in OUTCOMES:
        vals = np.array([s["by_fault"][k][o] for k in kinds], float)
        ax[1, 1].barh(kinds, vals, left=bottom, color=colours[o], label=o)
        bottom += vals
    ax[1, 1].set_title("outcomes by fault kind drawn", fontsize=10)
    ax[1, 1].legend(fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    write_bytes_atomic(path, buf.getvalue())
