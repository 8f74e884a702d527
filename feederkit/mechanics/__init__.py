"""Push-align mechanics of one part (Akella & Mason 1999, section 3), exactly from the hull.

The radius function is piecewise sinusoidal: on the normal cone of hull vertex ``v`` it is
``|v - c| cos(phi - angle(v - c))``. Everything here follows from that: stable edges are its
local minima, divergent orientations its local maxima, resting ranges the intervals between
them, the push function maps each resting range onto its stable orientation.
"""

from feederkit.mechanics.actions import ActionRange, action_ranges
from feederkit.mechanics.polygon_classes import PolygonClass, polygon_class
from feederkit.mechanics.push import (
    PushFunction,
    StableState,
    diameter,
    push,
    push_diameter,
    push_function,
    radius,
)
from feederkit.mechanics.symmetry import Symmetry, push_diameter_period, push_period, symmetry

__all__ = [
    "ActionRange",
    "PolygonClass",
    "PushFunction",
    "StableState",
    "Symmetry",
    "action_ranges",
    "diameter",
    "polygon_class",
    "push",
    "push_diameter",
    "push_diameter_period",
    "push_function",
    "push_period",
    "radius",
    "symmetry",
]
