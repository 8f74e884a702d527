"""Push-align mechanics of one part (Akella & Mason 1999, section 3), computed exactly from the hull.

The radius function is piecewise sinusoidal: on the normal cone of hull vertex ``v`` it is
``|v - c| cos(phi - angle(v - c))``. Everything here follows from that: stable edges are its
local minima, divergent orientations its local maxima, resting ranges the intervals between
them, the push function maps each resting range onto its stable orientation.
"""

from feederkit.mechanics.push import (
    PushFunction,
    StableState,
    diameter,
    push,
    push_diameter,
    push_function,
    radius,
)

__all__ = [
    "PushFunction",
    "StableState",
    "diameter",
    "push",
    "push_diameter",
    "push_function",
    "radius",
]
