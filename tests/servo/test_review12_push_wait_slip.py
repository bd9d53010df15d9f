"""Review (issue 23, branch line12, ba8ac3e): the back-off's wait for the re-measure under a
fitted push is judged every frame against the time a back-off toward the camera takes to bring
the body out of the side's depth at speed_mps (6 cm/s) after react_s (recovery.BackOff._out_s),
no longer against the push's whole 3 s horizon at the wait's first frame.

That time assumes the back-off's speed. The faulty world's slip patch (faults.random_hazards:
each wheel keeps 0.3-0.8 of its speed for 0.5-3 s) and its motor faults (gain down to 0.85,
slip up to 15 %, battery sag) make it slower. The wait now stands on until the gap is the push's
share of the 6 cm/s time only; re-measured then, the back-off begins with that margin and no
more, and none of the back-off's own rules sees the closing in time: `closing` needs turn_m
(1 cm) of shrink and more than `turned` (0.3) per metre of depth, so a push under 1 cm/s,
a slow back-off, crosses the side's line before it is 'closing'; the 'at the object's side'
stop acts only once the gap is below 0, the body already on the side.

A kinematic model, the body square to the axis (turned_m 0), the object's face at FACE, its side
at x = 0 (the object at x <= 0), the robot 3 cm in front of the face, pushed toward the side:
the true body must not meet the object's region (across the side's line while any of it is at
or behind the face) before it is out of the face's depth or stopped named."""

from __future__ import annotations

from host.servo.controller import ControlConfig
from host.servo.recovery import BackOff

BLOCK = ControlConfig().block_m
HORIZON = ControlConfig().push_horizon_s
HALF = ControlConfig().half_width_m
FRAME_S = 0.066  # the trial's 15 frames/s
LATENCY_S = 0.12  # the motors' latency at most (faults.random_faults: 60-120 ms)
RUN_DOWN_S = 0.08  # the wheels' run-down after a stop
FACE = 1.30


def _back_off(raw: float, push_mps: float, speed_mps: float, confirm_after_s: float,
              e: float = -0.03) -> tuple[str, float]:
    """The wait and the back-off toward the camera, frame by frame (the robot facing the
    camera: a positive duty brings it nearer), the body's gap across measured exactly, the
    target confirmed after confirm_after_s, the body moving at speed_mps LATENCY_S after a
    moving command (and on for LATENCY_S + RUN_DOWN_S after a stop). Returns the outcome and
    the least true clearance (m) of the body to the object's region (negative: touched)."""
    b, t, z, x = BackOff(BLOCK), 0.0, FACE + e, raw + HALF
    moving_since: float | None = None
    stop_at: float | None = None
    least = 1.0
    dt = 0.002
    next_frame = 0.0
    while t < 10.0:
        if t >= next_frame and stop_at is None:
            next_frame += FRAME_S
            gap = x - HALF
            left, right = b.update(t, z, gap, FACE, t >= confirm_after_s, False, 0.0,
                                   push_mps * HORIZON)
            if b.outcome:
                stop_at = t
            elif (left or right) and moving_since is None:
                assert left > 0 and right > 0  # toward the camera, as the model has it
                moving_since = t
        going = moving_since is not None and t >= moving_since + LATENCY_S and (
            stop_at is None or t < stop_at + LATENCY_S + RUN_DOWN_S)
        if going:
            z -= speed_mps * dt
        x -= push_mps * dt
        if z + HALF >= FACE:  # some of the body at or behind the face: beside the side
            least = min(least, x - HALF)
        else:
            break  # out of the side's depth: clear
        if stop_at is not None and t > stop_at + LATENCY_S + RUN_DOWN_S:
            break  # the run ended named, the robot standing
        t += dt
    return b.outcome, least


def test_nominal_speed_backs_off_clear() -> None:
    """The rule's own assumption (6 cm/s): re-measured just before the wait's stop, the body
    leaves the side's depth clear (a control: passes on the branch too)."""
    outcome, least = _back_off(0.015, 0.006, 0.06, confirm_after_s=1.25)
    assert least > 0.0, (outcome, least)


def test_a_slipping_back_off_does_not_meet_the_side() -> None:
    """A push of 0.6 cm/s fitted, the gap 1.5 cm at the wait's start (a199819: less than the
    1.8 cm the push covers in 3 s, the run ends named at once, standing clear); re-measured
    after 1.25 s (gap 0.75 cm, above the 0.70 cm the branch's rule asks for), the back-off
    runs at 3 cm/s on a slip patch (traction 0.43): it needs 1.8 s to take the body out of the
    face's depth, the push closes 1.1 cm meanwhile. On line12 (ba8ac3e, e11dc27) the body
    crosses the side's line by 1.3 mm while beside it, then 'the body is at the object's side'
    stops it (fails; 0.7 mm at 4 cm/s, clear at 4.5 cm/s and above); a199819 stops named at
    once, standing 1.4 cm clear (passes)."""
    outcome, least = _back_off(0.015, 0.006, 0.03, confirm_after_s=1.25)
    assert least > 0.0, (outcome, least)
