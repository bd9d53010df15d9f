"""One servo run from its first robot frame to its end, and the stop rules, shared by the CLI
servo (camera or replay), `host servo --sim` and the trials: one loop, one set of rules."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from host.camera.source import CameraError
from host.servo.loop import LogRow, Servo
from host.servo.phase import Phase

HELD, STOPPED, DURATION, NOT_SETTLED, LOST, ENDED, UNSAFE = (
    "held", "stopped", "duration", "not settled", "lost", "camera ended", "unsafe")


@dataclass(frozen=True)
class Rules:
    """When a run ends (times in s on the run's clock, counted from the run's start unless
    said otherwise). The first that applies ends it, in this order: the watch's verdict, the
    servo's own stop (or STOP requested), the marker lost for lost_s, held for settle_s (from
    hold_from_s on, absolute), duration_s, limit_s."""

    settle_s: float = 1.0  # holding this long ends the run (0: run on)
    duration_s: float | None = None  # the run ends after this long, whatever it does
    limit_s: float | None = None  # not settled by then: NOT_SETTLED
    lost_s: float | None = None  # the marker lost this long: LOST
    hold_from_s: float = -math.inf  # holding counts only from this clock time on
    camera_end_ok: bool = False  # a camera that ends (a replay) ends the run; else it raises


@dataclass(frozen=True)
class End:
    """How a run ended: one of the names above, and why in words."""

    how: str
    reason: str = ""


def run_servo(servo: Servo, rules: Rules, clock: Callable[[], float],
              truth: Callable[[], float] = lambda: math.nan,
              watch: Callable[[LogRow], str] | None = None,
              each: Callable[[LogRow], None] | None = None) -> End:
    """Steps the servo (after its reference phase) until a rule ends the run. truth(): the
    robot's true depth for the log (simulation); watch(row): a reason the run is unsafe, or "";
    each(row): called after every step (notes, a status line). Errors of the link or the camera
    leave as exceptions; the caller's link context sends STOP."""
    t0 = clock()
    # a wait still on near it ends the run named (Servo._too_late); a run without a limit has
    # no deadline, not the one a run before it on this servo had
    servo.deadline = None if rules.limit_s is None else t0 + rules.limit_s
    lost_since: float | None = None
    while True:
        try:
            row = servo.step(truth())
        except CameraError:
            if not rules.camera_end_ok:
                raise
            return End(ENDED, "the camera ended")
        if each is not None:
            each(row)
        why = watch(row) if watch is not None else ""
        if why:
            return End(UNSAFE, why)
        # only on the step that sent STOP: a stop requested from another thread (the view's
        # STOP) while a step was deciding takes effect at the next step, which sends it
        if row.phase == Phase.STOP:
            return End(STOPPED, servo.stop_reason or row.reason)
        lost_since = (lost_since if lost_since is not None else row.t) \
            if row.phase == Phase.LOST else None
        if rules.lost_s is not None and lost_since is not None \
                and row.t - lost_since > rules.lost_s:
            return End(LOST, f"marker lost for {rules.lost_s:g} s")
        now = clock()
        if rules.settle_s and servo.held_for(rules.settle_s) and now > rules.hold_from_s:
            return End(HELD)
        if rules.duration_s is not None and now - t0 >= rules.duration_s:
            return End(DURATION, f"{rules.duration_s:g} s passed")
        if rules.limit_s is not None and now - t0 > rules.limit_s:
            return End(NOT_SETTLED, f"did not settle in {rules.limit_s:g} s")
