"""The true body's clearance to an object's region, for the back-off's tests: the rectangle
(half 0.08 m across and along) turned theta off the depth axis, sampled on its outline, against
the region across from the side at x_side (toward -x) and at or behind the face at face_z."""

from __future__ import annotations

import math


def rect_clear(x: float, z: float, theta: float, x_side: float, face_z: float,
               half: float = 0.08, n: int = 40) -> float:
    """The least distance (m) from the body to the region x <= x_side, z >= face_z; negative
    where a point of the body's outline is inside it (how deep)."""
    least = math.inf
    sa, ca = math.sin(theta), math.cos(theta)
    for k in range(4 * n):
        side, f = divmod(k, n)
        s = 2 * f / n - 1
        a, c = [(s, 1), (1, -s), (-s, -1), (-1, s)][side]
        px = x + half * (a * sa + c * ca)
        pz = z + half * (a * ca - c * sa)
        u, v = px - x_side, pz - face_z
        least = min(least, -min(-u, v) if u <= 0 <= v else math.hypot(max(u, 0.0),
                                                                        max(-v, 0.0)))
    return least
