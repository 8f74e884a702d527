"""Rotation-invariant signatures of a part's push and push-diameter functions (section 8.3).

Two push-diameter functions are the *same* (section 8.3) when a phase shift ``alpha`` maps
one onto the other with the same stable orientations, the same resting ranges (the
clockwise and counter-clockwise divergent orientations of each stable orientation) and the
same diameters. Two push functions are the same under the first two conditions alone.

A signature lists the stable states counter-clockwise, each as the width of its resting
range on either side of its stable orientation, ``(psi - kappa_cw, kappa_ccw - psi)``, and
its diameter. These numbers do not depend on the part frame, so "same within a tolerance"
is "some cyclic shift of one list matches the other element by element within it".
"""

from __future__ import annotations

from dataclasses import dataclass

from feederkit.angles import norm360
from feederkit.mechanics.push import PushFunction

ANGLE_TOL_DEG = 1e-6
"""Default tolerance (deg) on each side of each resting range when comparing push functions."""

LENGTH_TOL_MM = 1e-6
"""Default tolerance (mm) on each stable diameter when comparing push-diameter functions."""


@dataclass(frozen=True)
class Signature:
    """A part's push function (and diameters) up to rotation.

    ``before[k]``/``after[k]`` are the resting-range widths (deg) clockwise and
    counter-clockwise of the k-th stable orientation counter-clockwise from ``start_deg``;
    ``diameters[k]`` its diameter (mm) and ``state_ids[k]`` its state id in the push
    function. ``start_deg`` is the stable orientation of the first entry.
    """

    name: str
    before: tuple[float, ...]
    after: tuple[float, ...]
    diameters: tuple[float, ...]
    state_ids: tuple[int, ...]
    start_deg: float
    normals: tuple[float, ...]

    @property
    def n(self) -> int:
        """Number of stable states."""
        return len(self.before)

    def push_feature(self) -> float:
        """A rotation-invariant scalar; moves at most ``720 tol`` if each width moves ``tol``."""
        return sum(x * x for x in self.before) + sum(x * x for x in self.after)

    def diameter_feature(self) -> float:
        """The sum of the stable diameters; moves at most ``n tol`` if each moves ``tol``."""
        return sum(self.diameters)


def signature(pf: PushFunction) -> Signature:
    """The signature of a push function: its states counter-clockwise from the smallest normal."""
    order = sorted(range(pf.n), key=lambda i: pf.states[i].normal_deg)
    before, after, diam, normals = [], [], [], []
    for i in order:
        s = pf.states[i]
        lo, hi = s.resting_range_deg
        before.append(s.normal_deg - lo)
        after.append(hi - s.normal_deg)
        diam.append(s.diameter)
        normals.append(s.normal_deg)
    return Signature(
        name=pf.part.name,
        before=tuple(before),
        after=tuple(after),
        diameters=tuple(diam),
        state_ids=tuple(order),
        start_deg=pf.states[order[0]].normal_deg,
        normals=tuple(normals),
    )


def _matches(
    a: Signature, b: Signature, shift: int, angle_tol: float, length_tol: float | None
) -> bool:
    n = a.n
    for k in range(n):
        j = (k + shift) % n
        if abs(a.before[k] - b.before[j]) > angle_tol or abs(a.after[k] - b.after[j]) > angle_tol:
            return False
        if length_tol is not None and abs(a.diameters[k] - b.diameters[j]) > length_tol:
            return False
    return True


def matching_shifts(
    a: Signature,
    b: Signature,
    *,
    angle_tol: float = ANGLE_TOL_DEG,
    length_tol: float | None = None,
) -> list[int]:
    """Cyclic shifts ``s`` with state ``k`` of ``a`` matching state ``k + s`` of ``b``.

    Angles within ``angle_tol`` deg; with ``length_tol`` (mm) also the diameters
    (push-diameter function), else the push function only.
    """
    if a.n != b.n:
        return []
    return [s for s in range(a.n) if _matches(a, b, s, angle_tol, length_tol)]


def phase_shift(a: Signature, b: Signature, shift: int) -> float:
    """The phase shift ``alpha`` (deg, [0, 360)) of section 8.3 for a matching cyclic shift."""
    return norm360(b.normals[shift % b.n] - a.normals[0])


def same_push_function(
    a: PushFunction | Signature, b: PushFunction | Signature, angle_tol: float = ANGLE_TOL_DEG
) -> float | None:
    """The phase shift alpha under which the two push functions agree, or None (section 8.2)."""
    sa, sb = _sig(a), _sig(b)
    shifts = matching_shifts(sa, sb, angle_tol=angle_tol)
    return phase_shift(sa, sb, shifts[0]) if shifts else None


def same_push_diameter_function(
    a: PushFunction | Signature,
    b: PushFunction | Signature,
    angle_tol: float = ANGLE_TOL_DEG,
    length_tol: float = LENGTH_TOL_MM,
) -> float | None:
    """The phase shift alpha under which the push-diameter functions are the same (8.3), or None."""
    sa, sb = _sig(a), _sig(b)
    shifts = matching_shifts(sa, sb, angle_tol=angle_tol, length_tol=length_tol)
    return phase_shift(sa, sb, shifts[0]) if shifts else None


def _sig(x: PushFunction | Signature) -> Signature:
    return x if isinstance(x, Signature) else signature(x)
