"""Behaviour classes of a catalog: parts with the same push function, or the same push-diameter
function (sections 8.2-8.3), found without comparing every pair.

Each part gets a rotation-invariant signature (:mod:`feederkit.mix.signatures`). Parts are
hashed into buckets by the number of stable states and a quantised scalar of the signature
that moves by at most a known amount when each entry moves by the tolerance (the grid is
wider than that amount, so two matching parts land in the same or neighbouring buckets: the
quantisation cannot split them). Inside the buckets a part is compared exactly (every cyclic
shift, every entry within the tolerance) with each class's first member only.

"Same within a tolerance" is not transitive; a class is the set of parts matching its first
member (taken in input order). With exact data (look-alikes built by the constructions of
Theorems 4 and 6) and the default tolerances the distinction does not arise.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass

from feederkit.mix.signatures import (
    ANGLE_TOL_DEG,
    LENGTH_TOL_MM,
    Signature,
    matching_shifts,
    phase_shift,
)


@dataclass(frozen=True)
class BehaviourClass:
    """Parts (indices into the input) that share a push function or push-diameter function.

    ``phases_deg[k]`` is the phase shift alpha from member 0 to member k (section 8.3).
    """

    kind: str
    members: tuple[int, ...]
    phases_deg: tuple[float, ...]

    @property
    def size(self) -> int:
        """Number of parts in the class."""
        return len(self.members)


def _classes(
    sigs: Sequence[Signature],
    indices: Sequence[int],
    kind: str,
    angle_tol: float,
    length_tol: float | None,
) -> list[BehaviourClass]:
    # Grid widths: push feature moves by <= 2 * 360 * angle_tol (sum of squares of widths
    # summing to 360); diameter feature by <= n * length_tol. Factor 2 for rounding slack.
    g_push = 2.0 * 720.0 * angle_tol
    buckets: dict[tuple[int, int, int], list[int]] = defaultdict(list)  # key -> class ids
    reps: list[int] = []
    members: list[list[int]] = []
    phases: list[list[float]] = []
    for i in indices:
        s = sigs[i]
        kp = math.floor(s.push_feature() / g_push)
        if length_tol is None:
            kd, probes_d = 0, (0,)
        else:
            g_d = 2.0 * max(s.n, 1) * length_tol
            kd, probes_d = math.floor(s.diameter_feature() / g_d), (-1, 0, 1)
        found = None
        for dp in (-1, 0, 1):
            for dd in probes_d:
                for c in buckets.get((s.n, kp + dp, kd + dd), ()):
                    r = sigs[reps[c]]
                    shifts = matching_shifts(r, s, angle_tol=angle_tol, length_tol=length_tol)
                    if shifts:
                        found = (c, phase_shift(r, s, shifts[0]))
                        break
                if found:
                    break
            if found:
                break
        if found is None:
            c = len(reps)
            reps.append(i)
            members.append([i])
            phases.append([0.0])
            buckets[(s.n, kp, kd)].append(c)
        else:
            c, alpha = found
            members[c].append(i)
            phases[c].append(alpha)
    return [BehaviourClass(kind, tuple(m), tuple(p)) for m, p in zip(members, phases, strict=True)]


def push_classes(
    sigs: Sequence[Signature], angle_tol: float = ANGLE_TOL_DEG
) -> list[BehaviourClass]:
    """Classes of parts with the same push function (section 8.2), in order of first member."""
    return _classes(sigs, range(len(sigs)), "push", angle_tol, None)


def push_diameter_classes(
    sigs: Sequence[Signature],
    angle_tol: float = ANGLE_TOL_DEG,
    length_tol: float = LENGTH_TOL_MM,
) -> list[BehaviourClass]:
    """Classes of parts with the same push-diameter function (section 8.3), by first member."""
    return _classes(sigs, range(len(sigs)), "push-diameter", angle_tol, length_tol)
