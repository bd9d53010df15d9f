"""The back-off's "closing on the object's side" (recovery.BackOff, issue 23): seed 17's stops
traced against the world's truth (tools/trace_line_stop.py). In 10 of its 17 false "no safe
way back" stops both straight ways were clear by 2.6-5.8 cm; two misreadings of closing:

- the turned body's gap shrank because the card's turn bound (the median of ten aspects)
  grew, 0.9 -> 1.5 cm, while the centre had come 0.07 cm nearer (trial 226; 364: 0 -> 1.0 cm):
  closing is now the centre's approach;
- after the flip to the other way the body coasted on the first way for 0.26 s (the wheels'
  latency and run-down) and closed 0.9 cm, read as the second way closing: "either way"
  (trial 193): the second way's closing now counts from where its own travel begins, the
  coast bounded by coast_s.
"""

from __future__ import annotations

from host.servo.recovery import BackOff, BackOffConfig

BLOCK = 0.15


def _step(b: BackOff, t: float, z: float, raw: float, turned: float, target: float) -> None:
    b.update(t, z, raw, target, True, True, 0.0, 0.0, 180, 0.0, True, turned, 0)


def test_a_growing_turn_bound_is_not_closing() -> None:
    """Trial 226's back-off (the servo's figures): 3 cm beyond the face it backs off deeper,
    the centre 3.15 -> 3.08 cm from the side over 3 mm of depth while the card's turn bound
    moves 0.9 -> 1.5 cm: not closing, it goes on (b6af144 stopped: "backing off closes on
    the object's side")."""
    b = BackOff(BLOCK, BackOffConfig())
    target = 1.245
    frames = [(5.49, 1.2763, 0.0315, 0.0089), (5.52, 1.2776, 0.0314, 0.0089),
              (5.55, 1.2785, 0.0312, 0.0120), (5.59, 1.2789, 0.0310, 0.0146),
              (5.65, 1.2793, 0.0308, 0.0146), (5.69, 1.2820, 0.0308, 0.0146)]
    for t, z, raw, turned in frames:
        _step(b, t, z, raw, turned, target)
    assert b.outcome == "" and b.deeper is True


def test_the_centre_closing_on_the_side_still_stops() -> None:
    """The same back-off with the centre truly closing (0.7 cm over 1 cm of depth, a heading
    ~35 degrees toward the side), the turn bound steady: it stops, named."""
    b = BackOff(BLOCK, BackOffConfig())
    target = 1.245
    for k in range(8):
        _step(b, 5.49 + 0.033 * k, 1.2763 + 0.0014 * k, 0.0315 - 0.001 * k, 0.0146, target)
    assert b.outcome == "no safe way back: backing off closes on the object's side"


def _flip_and_coast(coast_frames: int, per_frame: float, turned: float) -> BackOff:
    """Trial 193 (the servo's figures): 3 cm in front of the face, turned ~22 degrees, it
    backs off toward the camera closing on the side (1.1 mm a frame over 1.3 mm of depth)
    and flips; then coasts the first way coast_frames frames (3 mm of depth a frame,
    per_frame nearer the side), then goes the second way (deeper), leaving the side."""
    b = BackOff(BLOCK, BackOffConfig())
    target = 1.191
    t, z, raw = 8.58, 1.159, 0.0463
    while not b.flipped and t < 9.5:  # the first way: toward the camera, closing
        _step(b, t, z, raw, turned, target)
        t, z, raw = t + 0.066, z - 0.0013, raw - 0.0011
    assert b.flipped and b.deeper is True and not b.outcome
    for _ in range(coast_frames):  # coasting the first way
        t, z, raw = t + 0.066, z - 0.0030, raw - per_frame
        _step(b, t, z, raw, turned, target)
    for _ in range(6):  # the second way: deeper, away from the side
        t, z, raw = t + 0.066, z + 0.005, raw + 0.002
        _step(b, t, z, raw, turned, target)
    return b


def test_the_coast_after_the_flip_is_not_the_second_way_closing() -> None:
    """Coasting 0.26 s the first way after the flip (4 frames, 1.1 cm nearer the side), then
    deeper, opening the gap: it goes on (b6af144: "backing off either way closes on its
    side")."""
    assert _flip_and_coast(4, 0.0027, 0.027).outcome == ""


def test_a_coast_longer_than_coast_s_is_closing() -> None:
    """Still going the first way 0.9 s after the flip (14 frames: the wheels did not take
    the second way), past coast_s: the closing counts, and it stops, named (with coast_s
    unbounded it went on)."""
    b = _flip_and_coast(14, 0.0015, 0.012)
    assert b.outcome == "no safe way back: backing off either way closes on its side"
