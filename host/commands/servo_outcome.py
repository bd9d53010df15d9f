"""How a servo run ended, as the exit status and one line: held at the target (0), stopped by
the user (the view's STOP) or --duration (0), a replay that ran out first (RECORDING_ENDED), or
not reached (NOT_REACHED): the marker was never seen, or the run ended in a safe stop (marker
lost, frames too late, target vanished)."""

from __future__ import annotations

import math

from host.errors import NotReached, RecordingEnded
from host.servo.loop import Servo

NOT_REACHED = NotReached.status  # the run ended without the robot holding at the target
RECORDING_ENDED = RecordingEnded.status  # the replay ran out before the robot held


def outcome(servo: Servo) -> tuple[int, str]:
    """(exit status, message) for a finished run."""
    rows = servo.rows
    if not rows:
        return NOT_REACHED, "the run ended before the robot phase began"
    seen = [r for r in rows if math.isfinite(r.robot_px)]
    if not seen:
        return NOT_REACHED, (f"the marker was never seen in {len(rows)} frames (check --marker "
                             f"and that the robot's marker faces the cameras)")
    last = rows[-1]
    after = f"after {last.t - rows[0].t:.1f} s"
    target = f"the target's {servo.target_m:.3f} m"
    held, reason = servo.outcome()
    if held == "held":
        return 0, (f"held at {last.depth_m:.3f} m (disparity {last.robot_px:.2f} px) against "
                   f"{target} {after}")
    if servo.requested_stop:
        return 0, f"stopped ({servo.requested_stop}) {after}"
    if last.reason:
        return NOT_REACHED, (f"safe stop {after}: {reason}; last seen at {seen[-1].depth_m:.3f} m "
                             f"(disparity {seen[-1].robot_px:.2f} px) against {target}")
    where = (f"{last.depth_m:.3f} m" if math.isfinite(last.depth_m)
             else f"last seen at {seen[-1].depth_m:.3f} m")
    return 0, f"stopped while in phase {last.phase} at {where}, against {target} {after}"


def replay_outcome(servo: Servo, source: object) -> tuple[int, str]:
    """(exit status, message) for a run whose replay ran out: what outcome() says when the run
    had ended otherwise (held at its last pair, STOP, a safe stop, never seen), else
    RECORDING_ENDED with where the run was; a bag cut off (a killed recording) is said too."""
    status, msg = outcome(servo)
    ended = getattr(source, "ended", None)
    how = ended() if callable(ended) else "the recording ended"
    rows = servo.rows
    if status != 0 or servo.requested_stop or servo.outcome()[0] == "held":
        return status, msg + (f"; {how}" if getattr(source, "truncated", False) else "")
    last = rows[-1]
    return RECORDING_ENDED, (f"{how} in phase {last.phase} after {last.t - rows[0].t:.1f} s, "
                             f"before the robot held at the target's {servo.target_m:.3f} m")
