"""Exact symmetry of the push and push-diameter functions (definitions 3, 6, 7, 8).

Periods form a group: every period is a multiple of the smallest one, which divides 360.
Values of the push-diameter function are compared through ``labels`` (one label per stable
state): exact diameters for the part's own symmetry, indistinguishable sets for a sensor.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from dataclasses import dataclass

from feederkit.angles import ANGLE_EPS, angle_close, norm360
from feederkit.mechanics.push import PushFunction

DIAMETER_REL_EPS = 1e-9
"""Diameters equal within this fraction of the part's size are the same diameter."""


def _shift_invariant(angles: Sequence[float], shift: float, eps: float = ANGLE_EPS) -> bool:
    """Whether the set of angles maps onto itself under ``+shift``."""
    return all(any(angle_close(a + shift, b, eps) for b in angles) for a in angles)


def _candidate_shifts(angles: Sequence[float]) -> list[float]:
    if not angles:
        return []
    base = angles[0]
    return sorted({norm360(a - base) for a in angles[1:]} - {0.0})


def push_period(pf: PushFunction) -> float:
    """Smallest T in (0, 360] with p(phi + T) = p(phi) + T (definition 3); 360 when asymmetric."""
    stable = [s.normal_deg for s in pf.states]
    for t in _candidate_shifts(stable):
        if t <= ANGLE_EPS:
            continue
        if _shift_invariant(stable, t) and _shift_invariant(pf.divergent_deg, t):
            return t
    return 360.0


def exact_labels(pf: PushFunction) -> list[int]:
    """Label each state by its diameter, equal diameters (within DIAMETER_REL_EPS) alike."""
    eps = DIAMETER_REL_EPS * pf.part.size
    reps: list[float] = []
    labels = []
    for s in pf.states:
        for k, r in enumerate(reps):
            if abs(s.diameter - r) <= eps:
                labels.append(k)
                break
        else:
            reps.append(s.diameter)
            labels.append(len(reps) - 1)
    return labels


def _steps(pf: PushFunction, labels: Sequence[Hashable]) -> list[tuple[float, Hashable]]:
    """Breakpoints of the push-diameter step function with the label that starts at each."""
    m = len(pf.divergent_deg)
    out = []
    for k in range(m):
        here = labels[pf.range_state[k]]
        before = labels[pf.range_state[k - 1]]
        if here != before:
            out.append((pf.divergent_deg[k], here))
    return out


def push_diameter_period(pf: PushFunction, labels: Sequence[Hashable] | None = None) -> float:
    """Smallest T in (0, 360] with d(phi + T) = d(phi) (definition 6); 0 when d is constant."""
    labels = exact_labels(pf) if labels is None else labels
    steps = _steps(pf, labels)
    if not steps:
        return 0.0
    base_angle, base_label = steps[0]
    for angle, label in steps[1:]:
        if label != base_label:
            continue
        t = norm360(angle - base_angle)
        if t <= ANGLE_EPS:
            continue
        if all(any(angle_close(a + t, b) and la == lb for b, lb in steps) for a, la in steps):
            return t
    return 360.0


@dataclass(frozen=True)
class Symmetry:
    """The symmetry of a part's push and push-diameter functions.

    ``kind`` of the push-diameter function: ``"constant"`` (one value), ``"aperiodic"``,
    ``"quasi-symmetric"`` (definition 7) or ``"symmetric"`` (definition 8). ``period_deg`` is
    the push-diameter function's smallest symmetric period (or its smallest period when
    quasi-symmetric); ``push_period_deg`` the push function's (definition 3).
    ``part_period_deg`` is the smallest shift under which the part behaves identically
    (push function and diameters alike): orientation is possible only up to it.
    """

    kind: str
    period_deg: float
    push_period_deg: float
    part_period_deg: float

    @property
    def periods(self) -> int:
        """Number of periods p of the push-diameter function in 360 degrees."""
        return max(1, round(360.0 / self.period_deg)) if self.period_deg > 0 else 1


def symmetry(pf: PushFunction, labels: Sequence[Hashable] | None = None) -> Symmetry:
    """Classify the push-diameter function by definitions 6-8 for the given state labels."""
    labels = exact_labels(pf) if labels is None else list(labels)
    stable = [s.normal_deg for s in pf.states]
    tp = push_period(pf)
    part_t = _part_period(pf)
    td = push_diameter_period(pf, labels)
    if td == 0.0:
        return Symmetry("constant", 0.0, tp, part_t)
    if td >= 360.0:
        return Symmetry("aperiodic", 360.0, tp, part_t)
    k = 1
    while k * td < 360.0 - ANGLE_EPS:
        if _shift_invariant(stable, k * td):
            return Symmetry("symmetric", k * td, tp, part_t)
        k += 1
    return Symmetry("quasi-symmetric", td, tp, part_t)


def _part_period(pf: PushFunction) -> float:
    """Smallest shift preserving the push function and the exact diameters of the states."""
    labels = exact_labels(pf)
    stable = [s.normal_deg for s in pf.states]
    for t in _candidate_shifts(stable):
        if t <= ANGLE_EPS or not _shift_invariant(pf.divergent_deg, t):
            continue
        ok = True
        for s in pf.states:
            j = next((x for x in pf.states if angle_close(s.normal_deg + t, x.normal_deg)), None)
            if j is None or labels[j.id] != labels[s.id]:
                ok = False
                break
        if ok:
            return t
    return 360.0
