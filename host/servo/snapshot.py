"""What the servo saw and did in one step, handed read-only to observers (the live view).

Observers are called on the loop's thread and must return at once: they keep a reference and
do their work elsewhere. Nothing in a Snapshot may be written to; the arrays are the loop's own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from host.camera.geometry import Geometry
from host.link import protocol_gen as gen
from host.servo.marker import MarkerPair
from host.servo.perception import Target
from host.servo.phase import Phase


@dataclass(frozen=True)
class LinkStats:
    """The serial link's health as the host sees it."""

    rtt_ms: float  # this step's command sent to ACK received, resends included; NaN if none
    resends: int  # commands sent again after silence or a CRC NACK, since the session began
    nacks: int  # NACKs received
    duplicates: int  # resends the robot had already applied (ACK result DUPLICATE)
    reset_cause: str  # the robot's last reset before the session, as its HELLO_REPLY says
    resets: int  # resets the robot reported (BOOT) during the session
    schema_hash: int  # the protocol spec hash the robot's firmware was built from


@dataclass(frozen=True)
class Snapshot:
    """One step: the rectified left image, the disparity the step computed, what was found."""

    t: float  # s, the loop's clock
    phase: Phase  # reference, then the LogRow phases (measure, drive, hold, turn, stop ...);
    # view: `host view`, no robot; ended: the view's last picture after the run
    reason: str  # why the robot is stopped ("" while it may move)
    left: np.ndarray  # rectified left image, uint8 BGR or grey
    disparity: np.ndarray | None  # px, NaN = invalid; rows disparity_y0.. of the image
    disparity_y0: int  # the full map (0) or a band of rows over the marker
    target: Target | None
    marker_pair: MarkerPair | None  # the marker seen in both views (None: not seen)
    row: Any  # the step's LogRow (None in the reference phase)
    link: LinkStats | None
    geometry: Geometry


Observer = Callable[[Snapshot], None]


def link_stats(link: Any, rtt_ms: float) -> LinkStats | None:
    """LinkStats of a RobotLink (None for a link without a session)."""
    hello = getattr(link, "hello", None)
    if hello is None:
        return None
    try:
        cause = gen.ResetCause(hello.reset_cause).name.lower().replace("_", " ")
    except ValueError:
        cause = f"code {hello.reset_cause}"
    return LinkStats(rtt_ms, link.resends, link.nacks, link.duplicates, cause, link.resets,
                     hello.schema_hash)
