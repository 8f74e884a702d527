"""Exact symmetry of the push and push-diameter functions (definitions 3, 6, 7, 8).

The shifts ``T`` under which a finite set of ``q`` angles on the circle maps onto itself form
a group: the multiples of ``360 / b`` for some ``b`` dividing ``q``, and the shift by ``360 k / q``
sends the ``i``-th angle (in circular order) to the ``(i + k)``-th. So the smallest period is
found by testing the divisors ``k`` of ``q`` in increasing order, each in O(q): the number of
periods ``b = q / k``. Periods of two functions combine through the gcd of their numbers of
periods. Values of the push-diameter function are compared through ``labels`` (one per stable
state): exact diameters for the part's own symmetry, indistinguishable sets for a sensor.
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.angles import ANGLE_EPS
from feederkit.mechanics.push import PushFunction

DIAMETER_REL_EPS = 1e-9
"""Diameters equal within this fraction of the part's size are the same diameter."""


def _divisors(q: int) -> list[int]:
    small = [k for k in range(1, math.isqrt(q) + 1) if q % k == 0]
    return sorted(set(small) | {q // k for k in small})


def _invariant(angles: np.ndarray, k: int, ids: np.ndarray | None, eps: float) -> bool:
    """Whether the shift by ``360 k / q`` sends angle ``i`` onto angle ``i + k``, ids kept."""
    q = len(angles)
    t = 360.0 * k / q
    gap = np.mod(np.roll(angles, -k) - angles - t + 180.0, 360.0) - 180.0
    if not bool(np.all(np.abs(gap) < eps)):
        return False
    return ids is None or bool(np.array_equal(np.roll(ids, -k), ids))


def periods_of(
    angles: Sequence[float], ids: Sequence[int] | None = None, eps: float = ANGLE_EPS
) -> int:
    """The number of periods ``b`` of a set of angles (with ids that a shift must keep).

    Its smallest period is ``360 / b``; ``b = 1`` when only the full turn maps it onto itself.
    An empty set has no structure to keep: it returns 0 (every shift is a period).
    """
    q = len(angles)
    if q == 0:
        return 0
    order = np.argsort(np.mod(np.asarray(angles, dtype=float), 360.0), kind="stable")
    a = np.mod(np.asarray(angles, dtype=float), 360.0)[order]
    lab = None if ids is None else np.asarray(ids)[order]
    for k in _divisors(q):
        if k < q and _invariant(a, k, lab, eps):
            return q // k
    return 1


def _period_deg(b: int) -> float:
    return 360.0 / b if b > 0 else 0.0


def push_periods(pf: PushFunction) -> int:
    """Number of periods of the push function: stable and divergent orientations shift alike."""
    s = np.array([x.normal_deg for x in pf.states])
    d = np.array(pf.divergent_deg)
    both = np.concatenate([s, d])
    kind = np.concatenate([np.zeros(len(s), dtype=int), np.ones(len(d), dtype=int)])
    return periods_of(both.tolist(), kind.tolist())


def push_period(pf: PushFunction) -> float:
    """Smallest T in (0, 360] with p(phi + T) = p(phi) + T (definition 3); 360 when asymmetric."""
    return _period_deg(push_periods(pf))


def exact_labels(pf: PushFunction) -> list[int]:
    """Label each state by its diameter; diameters within DIAMETER_REL_EPS of the size are alike."""
    eps = DIAMETER_REL_EPS * pf.part.size
    diam = [s.diameter for s in pf.states]
    order = sorted(range(len(diam)), key=lambda i: diam[i])
    labels = [0] * len(diam)
    label, last = -1, -math.inf
    for i in order:
        if diam[i] - last > eps:
            label += 1
        labels[i] = label
        last = diam[i]
    return labels


def _steps(pf: PushFunction, labels: Sequence[Hashable]) -> tuple[list[float], list[int]]:
    """Breakpoints of the push-diameter step function and an id of the label starting at each."""
    ids: dict[Hashable, int] = {}
    angles, out = [], []
    for k, start in enumerate(pf.divergent_deg):
        here = labels[pf.range_state[k]]
        if here != labels[pf.range_state[k - 1]]:
            angles.append(start)
            out.append(ids.setdefault(here, len(ids)))
    return angles, out


def push_diameter_periods(pf: PushFunction, labels: Sequence[Hashable] | None = None) -> int:
    """Number of periods of the push-diameter function (definition 6); 0 when it is constant."""
    labels = exact_labels(pf) if labels is None else labels
    angles, ids = _steps(pf, labels)
    return periods_of(angles, ids)


def push_diameter_period(pf: PushFunction, labels: Sequence[Hashable] | None = None) -> float:
    """Smallest T in (0, 360] with d(phi + T) = d(phi) (definition 6); 0 when d is constant."""
    return _period_deg(push_diameter_periods(pf, labels))


def stable_periods(pf: PushFunction) -> int:
    """Number of periods of the set S of stable orientations (definitions 7 and 8)."""
    return periods_of([s.normal_deg for s in pf.states])


@dataclass(frozen=True)
class Symmetry:
    """The symmetry of a part's push and push-diameter functions.

    ``kind`` of the push-diameter function: ``"constant"`` (one value), ``"aperiodic"``,
    ``"quasi-symmetric"`` (definition 7: periodic, but no period maps the stable orientations
    onto themselves) or ``"symmetric"`` (definition 8). ``period_deg`` is the push-diameter
    function's smallest symmetric period when symmetric, its smallest period when
    quasi-symmetric, 360 when aperiodic and 0 when constant. ``push_period_deg`` is the push
    function's (definition 3). ``part_period_deg`` is the smallest shift under which the part
    behaves identically (push function and exact diameters alike): orientation is possible
    only up to it.
    """

    kind: str
    period_deg: float
    push_period_deg: float
    part_period_deg: float

    @property
    def periods(self) -> int:
        """Number of periods p of the push-diameter function in 360 degrees."""
        return max(1, round(360.0 / self.period_deg)) if self.period_deg > 0 else 1


def pose_difference(pf: PushFunction, a: int, b: int) -> float:
    """How far apart (mm) the part looks resting in stable states ``a`` and ``b``: the
    Hausdorff distance of its hull in the two poses on the fence, each resting on the fence
    line and centred along it (the position along the fence is not observed). 0 for states
    that a symmetry of the hull maps onto each other (definitions 3, 6); small for the
    near-symmetric states a plan under uncertainty may list together.

    >>> from feederkit.mechanics.push import push_function
    >>> from feederkit.part import make_part
    >>> from feederkit.outline import make_outline
    >>> rect = push_function(make_part(make_outline("r", [[0, 0], [4, 0], [4, 2], [0, 2]])))
    >>> round(pose_difference(rect, 0, 2), 9), round(pose_difference(rect, 0, 1), 3)
    (0.0, 2.0)
    """
    from shapely import Polygon, hausdorff_distance

    hull = np.asarray(pf.part.hull, dtype=float)

    def placed(state: int) -> np.ndarray:
        t = math.radians(pf.states[state].pose_deg)
        rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
        pts = hull @ rot.T
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return pts - np.array([(lo[0] + hi[0]) / 2.0, lo[1]])

    return float(hausdorff_distance(Polygon(placed(a)), Polygon(placed(b))))


def symmetry(pf: PushFunction, labels: Sequence[Hashable] | None = None) -> Symmetry:
    """Classify the push-diameter function by definitions 6-8 for the given state labels."""
    labels = exact_labels(pf) if labels is None else list(labels)
    a = push_periods(pf)
    part_b = push_diameter_periods(pf)
    part_t = _period_deg(a if part_b == 0 else math.gcd(a, part_b))
    b = push_diameter_periods(pf, labels)
    tp = _period_deg(a)
    if b == 0:
        return Symmetry("constant", 0.0, tp, part_t)
    if b == 1:
        return Symmetry("aperiodic", 360.0, tp, part_t)
    g = math.gcd(b, stable_periods(pf))
    if g > 1:
        return Symmetry("symmetric", 360.0 / g, tp, part_t)
    return Symmetry("quasi-symmetric", 360.0 / b, tp, part_t)
