"""The robot's body against the scene's fixed objects, in the floor plane: one check of a motion.

Positions are (depth z, lateral x) in metres, the camera frame seen from above (fixed_cells).
A heading is the way the robot faces: 0 away from the camera (+z), positive toward +x, so a
forward move goes along (sin h, cos h) in (x, z). The body is the circle a turn in place sweeps
(turn_radius_m): it holds the robot's footprint at any heading, so a heading known only roughly
costs no margin beside the robot, only along the way it goes.

A motion is a straight run of travel_m along a heading (a drive, a reversed leg, a probe, a
drift while standing), the heading known to within spread (rad), or a spin in place (heading
None). A cell is in its way when the moving circle reaches it on any of those headings and
the motion closes on it (a cell beside or behind, left behind, is not); a spin reaches every
cell within the circle.

The robot's own body is not an obstacle: a fixed object no larger than a body standing where
the sighting is (every cell within own_m of it, centred on it laterally, and apart from every
other cell) is that body: a look-alike robot that stood in the reference, seen while the probe
tests it, or the robot itself where it stood when the reference was taken. A box beside the
robot reaches on beyond the circle, or lies to one side of it, and stays an obstacle.

Heading: learnt from the line the robot travels while driven straight (both wheels one way:
the chord over the last window_s, at least min_run_m), within the positions' noise across
that chord; kept while it stands, forgotten when it spins (a turn's angle is known only
roughly; the controller's facing is then assumed, with a wider spread).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np


def own_body(cells: np.ndarray, z: float, x: float, own_m: float, centre_m: float,
             apart_m: float) -> np.ndarray:
    """A mask of the cells that are a body standing at (z, x): all those within own_m of it,
    when their lateral mean is within centre_m of x and no other cell lies within own_m +
    apart_m (the group is a whole object of a body's size, not a corner of a larger one)."""
    mask = np.zeros(len(cells), bool)
    if not len(cells):
        return mask
    d = np.hypot(cells[:, 0] - z, cells[:, 1] - x)
    near = d < own_m
    if not near.any() or ((d >= own_m) & (d < own_m + apart_m)).any():
        return mask
    if abs(float(cells[near, 1].mean()) - x) >= centre_m:
        return mask
    return near


def in_the_way(cells: np.ndarray, z: float, x: float, heading: float | None, travel_m: float,
               radius_m: float, spread: float = 0.0, curvature: float = 0.0,
               step_m: float = 0.01) -> float | None:
    """How far along the motion (m, from the centre; 0 for a spin) the nearest cell in its way
    lies, or None when the way is clear. heading None: a spin in place (every cell within
    radius_m); else a run of travel_m starting along any heading within spread (rad) of
    heading, on an arc of this curvature (1/m, positive turning toward +x's side as heading
    grows), sampled every step_m: a cell within radius_m of the path that the motion closes on
    (ahead of the centre along heading at the start)."""
    if not len(cells):
        return None
    dz, dx = cells[:, 0] - z, cells[:, 1] - x
    rho = np.hypot(dz, dx)
    if heading is None:
        return 0.0 if (rho < radius_m).any() else None
    near = rho < travel_m + radius_m
    dz, dx = dz[near], dx[near]
    best: float | None = None
    s = np.arange(0.0, travel_m + step_m / 2, step_m)
    ahead = dz * math.cos(heading) + dx * math.sin(heading) > 0  # closing on it
    if not ahead.any():
        return None
    for h0 in np.linspace(heading - spread, heading + spread, 1 + 2 * int(spread > 0)
                          + 2 * int(spread > math.radians(5))):
        h = h0 + curvature * s
        if abs(curvature) > 1e-6:
            pz = (np.sin(h) - math.sin(h0)) / curvature
            px = (math.cos(h0) - np.cos(h)) / curvature
        else:
            pz, px = s * math.cos(h0), s * math.sin(h0)
        d = np.hypot(dz[ahead, None] - pz[None], dx[ahead, None] - px[None])
        inside = d < radius_m
        if inside.any():
            first = float(s[inside.any(axis=0)].min())
            best = first if best is None else min(best, first)
    return best


class Heading:
    """The robot's heading (rad) from the line it travels, or None when not known (a pure
    state machine: one update a frame with the position and the command in force)."""

    def __init__(self, min_run_m: float = 0.03, window_s: float = 1.0,
                 noise_m: float = 0.005) -> None:
        self.min_run_m, self.window_s, self.noise_m = min_run_m, window_s, noise_m
        self.value: float | None = None
        self.spread = math.pi  # how far off it may be (rad): the positions' noise across
        # the chord it was taken over (noise_m: the estimator's, a filtered few mm)
        self._run: deque[tuple[float, float, float]] = deque()  # (t, z, x) driven one way
        self._sign = 0

    def update(self, t: float, z: float, x: float, left: int, right: int) -> float | None:
        if left * right < 0 or (left == 0) != (right == 0):  # a spin, or one wheel alone
            self.value, self._sign = None, 0
            self._run.clear()
            return None
        sign = (left > 0) - (left < 0)
        if sign == 0:  # standing: the heading stays (a push moves it, but does not turn it)
            self._sign = 0
            self._run.clear()
            return self.value
        if sign != self._sign:
            self._sign = sign
            self._run.clear()
        self._run.append((t, z, x))
        while self._run and t - self._run[0][0] > self.window_s:
            self._run.popleft()
        _, z0, x0 = self._run[0]
        chord = math.hypot(z - z0, x - x0)
        if chord >= self.min_run_m:
            self.value = math.atan2(sign * (x - x0), sign * (z - z0))
            self.spread = math.atan2(self.noise_m, chord)
        return self.value
