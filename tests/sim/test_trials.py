"""The trials runner: what counts as unsafe and as not settled, the summary's figures, and
campaigns that give the same bytes on a busy machine, after an interrupt and a resume, and on
Ray."""

from __future__ import annotations

import io
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import pytest

from host.servo.loop import LogRow
from host.servo.phase import Phase
from host.sim.campaign import run_trials
from host.sim.trial_stats import summary, upper_bound, wilson
from host.sim.trials import Judge, Trial, _unsafe
from host.sim.world import World
from host.stereo.params import MatcherParams
from tests.netns import loopback_only

PARAMS = MatcherParams(block_size=9, num_disparities=48, border="clip")


def sim_with(z: float, x: float = 0.0, duty: tuple[int, int] = (300, 300), t: float = 5.0):
    world = World()
    world.robot.z_m, world.robot.x_m = z, x
    return SimpleNamespace(world=world, emulator=SimpleNamespace(motors=lambda: duty),
                           source=SimpleNamespace(t=t), servo=SimpleNamespace(stale_s=0.3))


def test_unsafe_outcomes_are_named() -> None:
    assert _unsafe(sim_with(1.5), last_valid=4.99, stale_s=0.3) == ""
    assert _unsafe(sim_with(1.2, x=-0.3), 4.99, 0.3) == "hit the object"
    assert _unsafe(sim_with(0.25), 4.99, 0.3) == "hit the camera"
    assert "left the view" in _unsafe(sim_with(1.5, x=0.6), 4.99, 0.3)
    assert "without a valid observation" in _unsafe(sim_with(1.5), 4.0, 0.3)
    # stopped motors are never unsafe for want of observations
    assert _unsafe(sim_with(1.5, duty=(0, 0)), 0.0, 0.3) == ""


def row(depth: float, truth: float, duty: int = 300, reason: str = "") -> LogRow:
    nan = math.nan
    return LogRow(5.0, Phase.DRIVE, reason, 1.2, depth, nan, 20.0, 20.0, nan, duty, duty, 30.0, 1.0,
                  0.0, truth)


def test_driving_on_a_depth_far_from_the_truth_is_unsafe() -> None:
    """The issue's false marker: 3.18 m read for a robot at 1.26 m, driven on."""
    judge = Judge(sim_with(1.26))
    assert judge(row(1.30, 1.26)) == ""  # within 10 cm + 5 %
    assert "drove on a marker depth of 3.18 m with the robot at 1.26 m" in judge(row(3.18, 1.26))
    # a reading the servo did not drive on (stopped, or flagged unusable) is not held against it
    assert Judge(sim_with(1.26, duty=(0, 0)))(row(3.18, 1.26, duty=0)) == ""
    assert "marker depth" not in Judge(sim_with(1.26))(row(3.18, 1.26, reason="stale"))


def test_a_probe_move_is_judged_by_its_travel_not_by_the_sighting_it_tests() -> None:
    """The probe tests a sighting it does not trust yet (maybe another robot's card, which it
    then leaves out): that sighting's depth is not held against it, its travel is."""
    sim = sim_with(1.79)
    judge = Judge(sim)
    probe = row(1.43, 1.79)
    probe.phase = Phase.PROBE
    assert judge(probe) == ""  # the decoy at 1.43 m tested, the robot at 1.79 m
    sim.world.robot.z_m = 1.79 - 0.10
    assert judge(probe) == ""  # 10 cm: within the bound
    sim.world.robot.z_m = 1.79 - 0.20
    assert "the probe move went 20 cm" in judge(probe)
    assert "drove on a marker depth" in Judge(sim_with(1.79))(row(1.43, 1.79))  # not a probe
    # a probe is no exemption from the stale limit: driving 0.5 s past the last sighting
    blind = Judge(sim_with(1.79, t=5.5))
    unseen = row(math.nan, 1.79)
    unseen.phase = Phase.PROBE
    assert "without a valid observation" in blind(unseen)


def test_a_run_that_does_not_settle_is_its_own_outcome(monkeypatch) -> None:
    """Not a safe stop: on today's main a trial out of time counted as "stopped"."""
    import host.sim.trials as trials

    monkeypatch.setattr(trials, "MAX_S", 0.5)  # far too short to reach the target
    t = trials.run_trial((1, 0, (320, 240), PARAMS, True))
    assert (t.outcome, t.reason) == ("not settled", "did not settle in 0.5 s")
    assert summary([t])["not_settled"] == 1 and summary([t])["stopped"] == 0


def test_summary_counts_outcomes_intervals_and_fault_kinds() -> None:
    def trial(i: int, outcome: str, err: float, t: float, reason: str = "",
              events=()) -> Trial:
        return Trial(i, 1.0, 1.2, "", list(events), outcome, reason, err, 0.01, 0.0, t, 10.0,
                     0.0)

    trials = [trial(i, "held", 0.001 * i, float(i), events=["move"] * (i < 2))
              for i in range(8)]
    trials += [trial(8, "stopped", math.nan, math.nan, "target vanished", ["vanish"]),
               trial(9, "unsafe", 0.5, math.nan, "hit the object", ["move"])]
    s = summary(trials[::-1])  # the order they finished in does not matter
    assert (s["trials"], s["held"], s["stopped"], s["unsafe"]) == (10, 8, 1, 1)
    assert s["hold_rate"] == pytest.approx(0.8)
    assert s["hold_rate_wilson95"] == pytest.approx([0.4902, 0.9433], abs=1e-4)
    assert s["unsafe_rate_upper95"] == pytest.approx(upper_bound(1, 10))
    assert s["error_cm_max"] == pytest.approx(0.7)
    assert s["error_cm_p50"] == pytest.approx(0.35)
    assert s["reasons"] == {"stopped: target vanished": 1, "unsafe: hit the object": 1}
    assert s["by_fault"]["move"] == {"trials": 3, "held": 2, "missed": 0, "stopped": 0,
                                     "not settled": 0, "unsafe": 1}
    assert s["by_fault"]["none"]["trials"] == 6 and s["by_fault"]["vanish"]["stopped"] == 1


def test_the_bounds_are_the_textbook_ones() -> None:
    assert upper_bound(0, 100) == pytest.approx(1 - 0.05 ** (1 / 100))  # about 3 %
    assert upper_bound(0, 1000) == pytest.approx(0.002991, abs=1e-6)
    lo, hi = wilson(98, 100)
    assert (lo, hi) == pytest.approx((0.92999, 0.99450), abs=1e-4)


def test_a_trial_index_beyond_the_trials_is_refused() -> None:
    from host.errors import HostError

    with pytest.raises(HostError, match="--trial-index 5 is not among the 5 trials"):
        run_trials(5, 1, (320, 240), MatcherParams(), indices=[5])


def test_trial_setups_do_not_depend_on_which_others_run() -> None:
    """--trial-index I reproduces trial I of a full run: its world comes from (seed, I) only."""
    from host.sim.trials import trial_setup

    a = trial_setup(1, 51, (320, 240), MatcherParams())
    trial_setup(1, 50, (320, 240), MatcherParams())
    assert trial_setup(1, 51, (320, 240), MatcherParams()) == a


def test_the_same_seed_gives_the_same_trial_json_beside_two_busy_processes(tmp_path) -> None:
    """Everything runs on the simulated clock: a starved host changes no byte."""
    def once(path: Path) -> bytes:
        run_trials(4, 3, (320, 240), PARAMS, path, workers=1, indices=[2], out=io.StringIO())
        return path.read_bytes()

    quiet = once(tmp_path / "quiet.json")
    burn = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(2)]
    try:
        busy = once(tmp_path / "busy.json")
    finally:
        for p in burn:
            p.kill()
            p.wait()
    assert json.loads(quiet)["trials"][0]["sim_s"] > 3  # a run, not an early failure
    assert busy == quiet


def _host(*args: str) -> list[str]:
    return [sys.executable, "-m", "host", "servo", "--sim", *args]


def test_an_interrupted_campaign_resumed_gives_the_straight_runs_summary(tmp_path) -> None:
    plan = ["--trials", "3", "--seed", "4", "--nominal", "--workers", "2"]
    straight = subprocess.run(_host(*plan, "--json", str(tmp_path / "s.json")),
                              capture_output=True, text=True, timeout=600)
    assert straight.returncode == 0, straight.stderr
    part, rows = tmp_path / "p.json", tmp_path / "p.csv"
    proc = subprocess.Popen(_host(*plan, "--json", str(part), "--csv", str(rows)),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 600
    while (not rows.exists() or rows.read_text().count("\n") < 2) \
            and time.monotonic() < deadline:
        time.sleep(0.1)  # the header and the first trial's row
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    kept = json.loads(part.read_text())
    assert not kept["complete"] and 1 <= len(kept["trials"]) < 3
    again = subprocess.run(_host(*plan, "--json", str(part), "--csv", str(rows), "--resume"),
                           capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr
    assert f"({len(kept['trials'])} done before" in again.stdout
    a, b = json.loads((tmp_path / "s.json").read_text()), json.loads(part.read_text())
    assert b["complete"] and a["summary"] == b["summary"] and a["trials"] == b["trials"]
    assert rows.read_text().count("\n") == 4  # the header and one row a trial


def test_resume_refuses_another_campaigns_file(tmp_path) -> None:
    path = tmp_path / "t.json"
    path.write_text(json.dumps({"world": "faulty", "seed": 9, "size": [320, 240], "n": 3,
                                "indices": None, "params": "", "trials": []}))
    r = subprocess.run(_host("--trials", "3", "--seed", "4", "--json", str(path), "--resume"),
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "is another campaign (seed 9, here 4)" in r.stderr
    assert r.stderr.count("\n") == 1


def test_a_trial_on_ray_is_the_trial_run_alone(tmp_path) -> None:
    """--trial-index reproduces a trial whichever backend ran it: Ray (a local cluster in a
    loopback-only namespace) and one process give the same bytes (also the calibration of the
    trial's lenses, whose last bits depend on BLAS's thread count)."""
    pytest.importorskip("ray", reason="Ray is not installed (pip install 'stereo-servo[ray]')")
    prefix = loopback_only()
    plan = ["--trials", "40", "--seed", "5", "--trial-index", "37"]  # faulty: lenses too
    env = os.environ | {"RAY_USAGE_STATS_ENABLED": "0"}
    alone = subprocess.run(_host(*plan, "--workers", "1", "--json", str(tmp_path / "a.json")),
                           capture_output=True, text=True, env=env, timeout=600)
    assert alone.returncode == 0, alone.stderr
    on_ray = subprocess.run(
        prefix + ["ip link set lo up && exec \"$@\"", "sh",
                  *_host(*plan, "--ray", "--json", str(tmp_path / "r.json"))],
        capture_output=True, text=True, env=env, timeout=600)
    assert on_ray.returncode == 0, on_ray.stderr[-2000:]
    assert (tmp_path / "r.json").read_bytes() == (tmp_path / "a.json").read_bytes()
