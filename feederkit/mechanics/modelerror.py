"""How far a part's readings may stray from its model's: the part against its contact hull.

Every plan is made on the part's contact hull, which import simplifies (``clean_hull``,
``--hull-tolerance``: a flattened arc's many chords become a few). The part itself rests on
its outline's hull: on a stable edge of the outline's own push function (section 3), where
it reads the outline's width, while the plan expects the diameter of the model's state
whose edge stands for that one (the outline's edges it replaced lie along it). Across a
flattened arc the two differ by up to about twice the simplification error, and more where
a longer chord turns the resting edge; a
sensor finer than that can read a part made exactly to its drawing outside every branch of a
plan made on its model (design.md: the executor must then stop).

A chord also rests where the arc rolls: :func:`keeping_tolerance` is the largest tolerance
at which the simplified hull's resting states are the outline's own.

The plan file's diameters are the model's (design.md); the machine reads each state over its
offsets before planning (:mod:`feederkit.machine.widths`). A smaller ``--hull-tolerance``
shrinks them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from feederkit.angles import norm360
from feederkit.hull import convex_hull
from feederkit.mechanics.analysis import FRAGILE_BARRIER_REL
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS
from feederkit.mechanics.uncertain import UncertainMechanics, uncertain_mechanics
from feederkit.part import Part, make_part
from feederkit.uncertainty import IDEAL

Offset = tuple[float, float]


def exact_push_function(model: PushFunction) -> PushFunction | None:
    """The push function of ``model``'s part on its outline's exact hull (same COM), or None
    when the contact hull already is that hull (nothing simplified beyond rounding)."""
    part = model.part
    if len(convex_hull(part.outline.vertices)) == len(part.hull):
        return None
    return push_function(make_part(part.outline, part.com))


def _distances(points: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """Distance of each point (rows) to each edge of the ring (columns, edge ``i`` from
    vertex ``i`` to ``i + 1``)."""
    a, b = ring, np.roll(ring, -1, axis=0)
    d = b - a
    rel = points[:, None, :] - a[None, :, :]
    len2 = np.maximum((d * d).sum(axis=1), 1e-300)
    t = np.clip((rel * d[None, :, :]).sum(axis=2) / len2[None, :], 0.0, 1.0)
    gap = rel - t[..., None] * d[None, :, :]
    return np.sqrt((gap * gap).sum(axis=2))


def state_offsets(model: PushFunction, exact: PushFunction) -> tuple[Offset | None, ...]:
    """Per state of ``model``: the least and largest ``exact`` diameter minus the model's,
    over the ``exact`` stable states resting on an edge the model's edge stands for (both
    its ends within the simplification's reach of the model's edge: ``slack``, twice the
    furthest the outline's hull strays from the model's, a little more for rounding), where
    the part itself rests when the model says it is in that state; None when none does (a
    state of the simplification only, such as a chord's across an arc's top).
    """
    mh = np.asarray(model.part.hull, dtype=float)
    eh = np.asarray(exact.part.hull, dtype=float)
    dist = _distances(eh, mh)  # exact vertex x model edge
    slack = 2.0 * float(dist.min(axis=1).max()) + 1e-9 * model.part.size
    n = len(eh)
    eps = DIAMETER_REL_EPS * model.part.size
    out: list[Offset | None] = []
    for s in model.states:
        ds = [
            e.diameter - s.diameter
            for e in exact.states
            if dist[e.edge, s.edge] <= slack and dist[(e.edge + 1) % n, s.edge] <= slack
        ]
        out.append((_rounded(min(ds), eps), _rounded(max(ds), eps)) if ds else None)
    return tuple(out)


def _rounded(offset: float, eps: float) -> float:
    """An offset within rounding of 0 (the machine's diameter snap) is 0."""
    return 0.0 if abs(offset) <= eps else offset


def reading_offsets(model: PushFunction) -> tuple[Offset | None, ...]:
    """:func:`state_offsets` of ``model`` against its outline's exact hull; all None when
    its contact hull is exact.

    >>> import math
    >>> from feederkit.outline import make_outline
    >>> arc = [(30 + 10 * math.cos(a / 20), 10 + 10 * math.sin(a / 20)) for a in range(-31, 32)]
    >>> d = make_outline("d", [(0.0, 0.0), (30.0, 0.0)] + arc + [(30.0, 20.0), (0.0, 20.0)])
    >>> offsets = reading_offsets(push_function(make_part(d, hull_tolerance=0.05)))
    >>> largest_offset(offsets)[0] > 0.01  # the arc's top cut by a chord
    True
    """
    exact = exact_push_function(model)
    if exact is None:
        return (None,) * model.n
    return state_offsets(model, exact)


def part_offsets(pfs: Sequence[PushFunction]) -> list[tuple[Offset | None, ...]]:
    """Each part's :func:`reading_offsets`, computed once for every machine built from the
    parts (a plan, a design, a catalog screen)."""
    return [reading_offsets(pf) for pf in pfs]


def largest_offset(offsets: Sequence[Offset | None]) -> tuple[float, int | None]:
    """The largest of ``offsets`` in absolute value (mm) and its state; (0, None) when
    there is none."""
    worst, which = 0.0, None
    for k, off in enumerate(offsets):
        if off is not None and max(-off[0], off[1]) > worst:
            worst, which = max(-off[0], off[1]), k
    return worst, which


KEEP_STEPS = 4
"""How many times :func:`keeping_tolerance` halves a hull tolerance before taking the exact
hull."""


@dataclass(frozen=True)
class KeptTolerance:
    """The hull tolerance :func:`keeping_tolerance` chose, and why it is below the asked one.

    ``model`` and ``outline``: at ``asked`` mm, how many resting states the simplified hull
    had where the outline's own hull has ``outline`` (0 and 0 when nothing was lowered).
    """

    tolerance: float
    asked: float
    model: int = 0
    outline: int = 0

    @property
    def lowered(self) -> bool:
        """Whether the tolerance is below the asked one."""
        return self.tolerance < self.asked


def _resting(part: Part) -> UncertainMechanics:
    """The part's physical resting states with a breath of vibration and nothing else
    uncertain (section 3's stable states, those vibration carries across merged, the facets of
    a hill left out)."""
    return uncertain_mechanics(part, IDEAL, vibration_mm=FRAGILE_BARRIER_REL * part.size)


def splits(model: UncertainMechanics, outline: UncertainMechanics) -> bool:
    """Whether ``model`` rests in two states where ``outline`` rests in one: two of its
    physical states' resting normals in one of the outline's capture ranges (a chord across
    an arc makes a stable edge the arc does not have; the part rolls over it), or one in no
    capture range (where the outline's facets are a hill the part rolls off).

    >>> import math
    >>> pts = [(30 * math.cos(k * math.pi / 64), 27 * math.sin(k * math.pi / 64))
    ...        for k in range(128)]
    >>> from feederkit.outline import make_outline
    >>> ellipse = make_outline("e", pts)
    >>> splits(_resting(make_part(ellipse, hull_tolerance=0.05)), _resting(make_part(ellipse)))
    True
    """
    owner: set[int] = set()
    for s in model.states:
        normal = (s.rest_deg[0] + s.rest_deg[1]) / 2.0
        for o in outline.states:
            lo, hi = o.capture_deg
            if norm360(normal - lo) < hi - lo or hi - lo >= 360.0:
                if o.id in owner:
                    return True
                owner.add(o.id)
                break
        else:
            return True
    return False


def kept_part(part: Part, tolerance: float | None) -> tuple[Part, KeptTolerance | None]:
    """``part`` (on its outline's exact hull) with its contact hull simplified at
    ``tolerance`` or the :func:`keeping_tolerance` below it, and that choice (None when
    nothing is simplified: no tolerance, or no hull vertex to drop)."""
    if tolerance is None:
        return part, None  # already on its exact hull
    if tolerance <= 0.0:
        return _simplified(part, tolerance), None
    first = _simplified(part, tolerance)
    if len(first.hull) == len(part.hull):
        return first, None
    kept = keeping_tolerance(part, tolerance)
    return (_simplified(part, kept.tolerance) if kept.lowered else first), kept


def _simplified(part: Part, tolerance: float | None) -> Part:
    return make_part(
        part.outline, part.com, hull_tolerance=tolerance, revision=part.revision, name=part.name
    )


def keeping_tolerance(part: Part, tolerance: float) -> KeptTolerance:
    """The largest of ``tolerance``, its halves (:data:`KEEP_STEPS` of them) and 0 at which
    the part's simplified contact hull rests where its outline does (:func:`splits` false).

    ``part`` is the part on its outline's exact hull. Simplifying a hull (``clean_hull``)
    replaces an arc's facets by chords; on a near-round part a chord's stable edge holds
    the part where the arc lets it roll (a 60 x 54 mm ellipse: 16 resting states at 0.05 mm
    where it has 2), and a plan made on them fails on the belt.
    """
    if tolerance <= 0.0:
        return KeptTolerance(0.0, tolerance)
    exact = _resting(part)
    first = None
    tol = tolerance
    for _ in range(KEEP_STEPS + 1):
        model = _resting(_simplified(part, tol))
        if not splits(model, exact):
            break
        if first is None:
            first = model.n
        tol /= 2.0
    else:
        tol = 0.0
    if first is None:
        return KeptTolerance(tolerance, tolerance)
    return KeptTolerance(tol, tolerance, first, exact.n)
