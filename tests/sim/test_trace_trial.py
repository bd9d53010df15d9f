"""One trial of a campaign traced alone: `--trials N --trial-index I --log run.csv` writes the
servo's log of the very run the campaign judged (how a stopped or unsafe trial is traced)."""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys

import pytest

from host.sim.trials import run_trial, traced_trial
from host.stereo.params import MatcherParams


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    return a == b


@pytest.mark.slow  # two closed-loop trials
def test_a_traced_trial_is_the_campaigns_trial_with_its_rows() -> None:
    job = (3, 1, (320, 240), MatcherParams(), False)
    record = run_trial(job)
    traced, rows = traced_trial(job)
    assert all(_same(x, y) for x, y in zip(vars(record).values(), vars(traced).values()))
    assert len(rows) > 20
    assert rows[-1].t - rows[0].t == pytest.approx(traced.sim_s, abs=1.0)


@pytest.mark.slow  # a closed-loop trial through the CLI
def test_the_cli_writes_the_log_of_the_one_trial_it_ran(tmp_path) -> None:
    log, out = tmp_path / "run.csv", tmp_path / "t.json"
    run = subprocess.run([sys.executable, "-m", "host", "servo", "--sim", "--trials", "4",
                          "--seed", "3", "--trial-index", "2", "--workers", "1", "--json",
                          str(out), "--log", str(log)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    trial = json.loads(out.read_text())["trials"][0]
    with log.open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) > 20
    t = [float(r["t"]) for r in rows]
    assert t[-1] - t[0] == pytest.approx(trial["sim_s"], abs=1.0)
    assert f"log: {log}" in run.stdout
