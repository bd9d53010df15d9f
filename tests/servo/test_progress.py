"""A run that neither closes in on its target nor holds there stops itself with a named reason
(host.servo.progress), before an outer time limit would call it "not settled"."""

from __future__ import annotations

import math

from host.camera.source import StereoFrame
from host.servo.progress import NO_PROGRESS, Progress, ProgressConfig
from host.servo_run import NOT_SETTLED, STOPPED, Rules, run_servo
from tests.servo.simulation import simulation

DT = 1 / 30


def _run(progress: Progress, frames: list[tuple[str, float | None]], target: float = 1.2,
         waiting: bool = False) -> tuple[float, str]:
    """Feeds frames (phase, error) at 30 Hz; (time, reason) of the first stop, else (nan, "")."""
    for i, (phase, e) in enumerate(frames):
        why = progress.update(i * DT, phase, e, target, waiting)
        if why:
            return i * DT, why
    return math.nan, ""


def test_closing_in_is_progress_and_oscillating_is_not() -> None:
    cfg = ProgressConfig(stall_s=5.0)
    n = int(20 / DT)
    closing = [("drive", 1.0 - 0.9 * i / n) for i in range(n)]
    assert _run(Progress(cfg), closing) == (math.nan, "")
    # about the target, +-3 cm for ever: the best |error| never improves by step_m
    swinging = [("creep", 0.03 * math.sin(i * DT * 2)) for i in range(n)]
    t, why = _run(Progress(cfg), swinging)
    assert why.startswith(NO_PROGRESS) and 4.9 < t < 6.0


def test_a_steady_hold_is_progress_and_a_hold_broken_every_few_frames_is_not() -> None:
    cfg = ProgressConfig(stall_s=5.0)
    steady = [("creep", 0.05)] + [("hold", 0.001)] * int(20 / DT)
    assert _run(Progress(cfg), steady) == (math.nan, "")
    # held three frames, marker unseen three: never a hold of hold_s
    broken = [("creep", 0.05)] + [("hold", 0.001) if i % 6 < 3 else ("wait", None)
                                  for i in range(int(20 / DT))]
    t, why = _run(Progress(cfg), broken)
    assert why.startswith(NO_PROGRESS) and t < 6.0


def test_bounded_waits_and_a_new_target_restart_the_count() -> None:
    cfg = ProgressConfig(stall_s=5.0)
    p = Progress(cfg)
    stuck = [("drive", 0.3)] * int(4 / DT)
    assert _run(p, stuck) == (math.nan, "")
    t0 = 4.0
    for i in range(int(10 / DT)):  # a wait of recovery.py's: not counted
        assert not p.update(t0 + i * DT, "obstacle", None, 1.2, waiting=True)
    t0 += 10
    for i in range(int(4 / DT)):  # the target moved: a new goal, counted afresh
        assert not p.update(t0 + i * DT, "drive", 0.3, 1.5)
    assert p.update(t0 + 5.1, "drive", 0.3, 1.5).startswith(NO_PROGRESS)


def test_a_target_that_keeps_moving_while_nothing_is_measured_restarts_no_count() -> None:
    """Seed 11's trial 322: the card lost at the end of the acquisition, the robot stood in
    "wait" for 41 s while the re-measure took its own body, drifting out of the region left
    out, for the target: the target's depth changed by 2-16 cm every 2-15 s, each change a new
    goal that restarted the count, and the run ended "not settled" at 45 s. A new goal restarts
    the count once; again only after an error has been measured against it."""
    cfg = ProgressConfig(stall_s=5.0)
    p = Progress(cfg)
    t, targets = 0.0, [1.2, 1.1, 0.95, 0.92, 0.94, 1.1, 0.95, 0.92]
    why = ""
    for k in range(int(20 / DT)):
        t = k * DT
        why = p.update(t, "wait", None, targets[int(t / 2.5) % len(targets)])
        if why:
            break
    assert why.startswith(NO_PROGRESS) and 4.9 < t < 5.2
    # measured against, a new goal restarts the count, as it did
    p = Progress(cfg)
    for k in range(int(4 / DT)):
        assert not p.update(k * DT, "drive", 0.3, 1.2)
    assert not p.update(4.0, "wait", None, 1.5)
    assert not p.update(8.9, "wait", None, 1.5)
    assert p.update(9.1, "wait", None, 1.5).startswith(NO_PROGRESS)


def test_the_servo_names_a_hold_it_cannot_keep_instead_of_running_out_of_time() -> None:
    """Closed loop (the constructed case of dev seed 102's trial 74): at the target the marker
    is unseen three frames in six (a card at the edge of what the search finds), so the servo
    holds only between gaps and never for the settle time. Before the progress check the run
    went on to its limit (NOT_SETTLED, 44 s here as the trials' 45 s); now the servo stops it
    with a named reason."""
    with simulation(1.6, seed=3) as sim:
        read, count = sim.source.read, [0]

        def gappy() -> StereoFrame:
            f = read()
            w = sim.world
            if abs(w.robot.z_m - w.nearest_box().z_m) > 0.05:
                return f
            count[0] += 1
            if count[0] % 6 >= 3:
                return f
            u, v, d = w.marker_truth()
            r = int(3 * w.geometry.focal_px * w.robot.marker_radius_m / w.robot.z_m) + 2
            left, right = f.left.copy(), f.right.copy()
            left[max(0, int(v) - r):int(v) + r, max(0, int(u) - r):int(u) + r] = 128
            ur = u - d
            right[max(0, int(v) - r):int(v) + r, max(0, int(ur) - r):int(ur) + r] = 128
            return StereoFrame(left, right, f.t_left, f.t_right)

        sim.source.read = gappy
        end = run_servo(sim.servo, Rules(settle_s=1.0, limit_s=44.0), sim.source.clock)
    assert count[0] > 30, "the robot never reached the target: the case was not built"
    assert end.how == STOPPED and end.reason.startswith(NO_PROGRESS), end
    assert end.how != NOT_SETTLED


def test_an_approach_after_a_recovery_is_measured_against_its_own_least() -> None:
    """Seed 18 #62: held (error ~0), pushed, backed off 15 cm in a recovery, came back on a
    new heading, and was creeping in 1.2 cm from its target when "no progress in 20 s" ended
    the run: its least error was still the hold's. After a recovery the first error measured
    is the new approach's least (no progress by itself), and closing in from it is progress."""
    cfg = ProgressConfig(stall_s=5.0)
    p = Progress(cfg)
    frames: list[tuple[str, float | None]] = [("creep", 0.004)] * int(0.5 / DT)
    frames += [("recover", None)] * int(0.5 / DT)
    frames += [("drive", -0.15 * i * DT / 2) for i in range(int(2 / DT))]  # backed off 15 cm
    n = int(12 / DT)
    frames += [("drive", -0.15 + 0.14 * i / n) for i in range(n)]  # and in again, slowly
    assert _run(p, frames) == (math.nan, "")
    # the recovery alone, with no closing in after it, restarts nothing
    p = Progress(cfg)
    frames = [("creep", 0.004)] * int(0.5 / DT) + [("recover", None)] * int(0.5 / DT)
    frames += [("drive", -0.15)] * int(8 / DT)
    t, why = _run(p, frames)
    assert why.startswith(NO_PROGRESS) and 4.9 < t < 5.2
