"""How a servo run ended, as the exit status and one line: held at the target (0), stopped by
--duration or a replay's end while moving (0), or not reached (NOT_REACHED): the marker was
never seen, or the run ended in a safe stop (marker lost, frames too late)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

from host.errors import NotReached

NOT_REACHED = NotReached.status  # the run ended without the robot holding at the target

_SAFE_STOPS = {"lost": "the marker was lost", "stale": "frames came too late (stale)",
               "hold": "the marker was not seen in the last frame"}


def outcome(rows: Sequence, depth_m: Callable[[float], float],
            stop_reason: str | None = None) -> tuple[int, str]:
    """(exit status, message) for the log rows of a run; depth_m turns disparity into metres;
    stop_reason is why the user stopped the run (the view's STOP), which is no failure."""
    if not rows:
        return NOT_REACHED, "the run ended before the robot phase began"
    target = rows[0].target_px
    if not any(math.isfinite(r.robot_px) for r in rows):
        return NOT_REACHED, (f"the marker was never seen in {len(rows)} frames (check --marker "
                             f"and that the robot's marker faces the cameras)")
    last = rows[-1]
    after = f"after {last.t - rows[0].t:.1f} s"
    seen = [r for r in rows if math.isfinite(r.robot_px)][-1]
    if last.phase in _SAFE_STOPS and not math.isfinite(last.robot_px):
        return NOT_REACHED, (f"safe stop {after}: {_SAFE_STOPS[last.phase]}; last seen at "
                             f"disparity {seen.robot_px:.2f} px ({depth_m(seen.robot_px):.3f} m) "
                             f"against the target's {target:.2f} px")
    where = (f"disparity {last.robot_px:.2f} px ({depth_m(last.robot_px):.3f} m) against the "
             f"target's {target:.2f} px {after}")
    if stop_reason is not None:
        return 0, f"stopped ({stop_reason}) at {where}"
    if last.phase == "hold":
        return 0, f"held at {where}"
    return 0, f"stopped while in phase {last.phase} at {where}"
