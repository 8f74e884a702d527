"""The polygon classes of Fig. 14 and their worst-case plan lengths (section 6.2).

Lengths count the first alignment from an unknown orientation as operation 1 (design.md), as
the paper's table does (class 1: length 1).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from feederkit.mechanics.push import PushFunction
from feederkit.mechanics.symmetry import push_diameter_periods, push_periods, symmetry
from feederkit.sensors import Sensor

CLASS_NAMES = {
    1: "all unique diameter values",
    2: "some unique diameter values",
    3: "multiple diameter values, none unique, aperiodic push-diameter function",
    4: "multiple diameter values, none unique, quasi-symmetric push-diameter function",
    5: "multiple diameter values, symmetric push-diameter function, symmetric push function",
    6: "multiple diameter values, symmetric push-diameter function, asymmetric push function",
    7: "single diameter value, asymmetric push function (sensorless case)",
    8: "single diameter value, symmetric push function (sensorless case)",
}


@dataclass(frozen=True)
class PolygonClass:
    """A part's class in Fig. 14 under a sensor model, with the worst-case length ``bound``.

    ``m`` is the size of the largest indistinguishable set, ``n`` the number of stable states,
    ``p`` the number of periods the bound divides by (1 when it does not).
    """

    number: int
    bound: int
    m: int
    n: int
    p: int

    @property
    def description(self) -> str:
        """The class's wording in Fig. 14."""
        return CLASS_NAMES[self.number]


def polygon_class(
    pf: PushFunction, sensor: Sensor, sets: Sequence[Sequence[int]] | None = None
) -> PolygonClass:
    """Classify a part by Fig. 14 for ``sensor`` (a sensorless model gives class 7 or 8).

    Labels of the push-diameter function are the indistinguishable sets of definition 10.
    Class 5 needs a common period of the (symmetric) push-diameter and push functions; ``p``
    is then the number of such common periods, and ``p`` the push function's in class 8.
    ``sets``: the indistinguishable sets of the states' diameters, when already known.
    """
    diam = [s.diameter for s in pf.states]
    if sets is None:
        sets = sensor.indistinguishable_sets(diam)
    n = len(diam)
    m = max(len(g) for g in sets)
    a = push_periods(pf)
    if len(sets) == 1:
        if a > 1:
            return PolygonClass(8, max(1, -(-2 * n // a) - 1), m, n, a)
        return PolygonClass(7, 2 * n - 1, m, n, 1)
    if m == 1:
        return PolygonClass(1, 1, m, n, 1)
    if any(len(g) == 1 for g in sets):
        return PolygonClass(2, m, m, n, 1)
    labels = [0] * n
    for k, g in enumerate(sets):
        for i in g:
            labels[i] = k
    sym = symmetry(pf, labels)
    if sym.kind == "aperiodic":
        return PolygonClass(3, m, m, n, 1)
    if sym.kind == "quasi-symmetric":
        return PolygonClass(4, 2 * m - 1, m, n, 1)
    p = math.gcd(a, push_diameter_periods(pf, labels))
    if p > 1:
        return PolygonClass(5, max(1, -(-2 * m // p) - 1), m, n, p)
    return PolygonClass(6, 2 * m - 1, m, n, 1)
