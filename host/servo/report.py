"""The servo run's record: a CSV log and a plot of the trajectory and the commands."""

from __future__ import annotations

import csv
import io
import math
import os
from dataclasses import asdict, fields

from host.camera.geometry import Geometry
from host.files import write_bytes_atomic, write_text_atomic
from host.servo.loop import LogRow
from host.servo.phase import Phase


def write_csv(path: str | os.PathLike[str], rows: list[LogRow]) -> None:
    buf = io.StringIO()
    w = csv.writer(buf)
    names = [f.name for f in fields(LogRow)]
    w.writerow(names)
    for r in rows:
        w.writerow(["" if isinstance(v, float) and math.isnan(v) else
                    (f"{v:.4f}" if isinstance(v, float) else v) for v in asdict(r).values()])
    write_text_atomic(path, buf.getvalue())


def plot_run(path: str | os.PathLike[str], rows: list[LogRow], geometry: Geometry) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = [r.t - rows[0].t for r in rows]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(10, 7), sharex=True,
                                   gridspec_kw={"height_ratios": [1.4, 1]})
    depth = [r.depth_m for r in rows]
    ax1.plot(t, depth, ".", ms=3, label="robot depth from the marker's disparity")
    if any(math.isfinite(r.truth_depth_m) for r in rows):
        ax1.plot(t, [r.truth_depth_m for r in rows], "-", lw=1, label="robot depth (truth)")
    ax1.plot(t, [r.target_m for r in rows], "k--", lw=1,
             label=f"target (nearest object), last {rows[-1].target_m:.3f} m")
    ax1.set_ylabel("depth (m)")
    ax1.legend(loc="best", fontsize=8)
    ax1.grid(alpha=0.3)
    ax1.set_title(f"servo run at {geometry.focal_px:.0f} px focal length: target "
                  f"{rows[-1].target_m:.3f} m")
    ax2.plot(t, [r.left for r in rows], label="left duty")
    ax2.plot(t, [r.right for r in rows], label="right duty")
    for phase, colour in ((Phase.TURN, "tab:orange"), (Phase.HOLD, "tab:green"),
                          (Phase.LOST, "tab:red"), (Phase.STALE, "tab:purple")):
        on = [r.phase == phase for r in rows]
        ax2.fill_between(t, -1000, 1000, where=on, color=colour, alpha=0.12, step="mid",
                         label=phase)
    ax2.set_ylim(-1000, 1000)
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("duty (permille)")
    ax2.legend(loc="best", fontsize=8, ncol=3)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    write_bytes_atomic(path, buf.getvalue())
