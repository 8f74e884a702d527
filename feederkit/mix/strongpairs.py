"""Pairs of parts that section 8 tells apart on the ideal model but no strong plan does under
a declared uncertainty (design.md, "Uncertainty").

The exact test of section 8 assumes exact rotations: two parts that differ only by resting
ranges a fraction of a degree apart (a near-duplicate drawn 0.05 mm longer) are told apart
there, and confused by every plan at a rotation error of 1 degree. For one pair of parts,
:func:`check_strong_pair` builds the machine of the two under the uncertainty and takes
the pairs of their physical states that no strong plan resolves: the bisimilar ones and the
unresolvable ones (:func:`feederkit.planning.lumping.unresolvable_pairs`), across the two
parts: the pairs ``changeover compile`` reports for a mix of the two
(:func:`feederkit.mix.changeover.strong_witnesses`; the states named may differ, compile
naming those its whole plan lumps). :func:`reading_pairs` gives the pairs worth checking.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass

from feederkit.machine import PushAlignMachine, members
from feederkit.machine.build import build_machine, uncertain_machine
from feederkit.machine.widths import Offsets, widen_widths, widened_span, widens
from feederkit.mechanics.modelerror import Offset, part_offsets
from feederkit.mechanics.push import PushFunction
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS
from feederkit.mechanics.uncertain import UncertainMechanics, uncertain_mechanics
from feederkit.mix.changeover import strong_witnesses
from feederkit.mix.pairs import PairWitness
from feederkit.planning.budget import Deadline
from feederkit.planning.lumping import may_lump, try_lumping, unresolvable_pairs, within_first
from feederkit.planning.options import Lumping
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.reindex import by_diameter
from feederkit.planning.solvable import solve
from feederkit.planning.wandering import twinned
from feederkit.sensors import Diameter, Sensor, span
from feederkit.uncertainty import Uncertainty


@dataclass(frozen=True)
class StrongPairCheck:
    """Whether some strong plan tells two parts apart: ``witness`` the pair of their states
    no strong plan resolves (None when one does), ``decided`` False when the search ran out
    of sets before it knew (``witness`` is then None)."""

    witness: PairWitness | None
    decided: bool = True


ALONE_SETS = 2_000
"""The most sets :func:`check_alone` explores in each of its searches before it calls a
member undecided: a screen must not hang on one member (a random 1000-point outline read at
0.3 mm explores about 700 sets a second, and 200,000 without an answer)."""


@dataclass(frozen=True)
class AloneCheck:
    """Whether some strong plan orients one member on its own (a mix of it alone), even when
    the plan may list near-symmetric states together (the default lumping rule of ``plan``
    and ``changeover compile``): ``orients``; where none does, ``states`` names the member's
    ideal resting states to blame (those of the pairs no strong plan resolves, else those of
    the reading sets no strong plan orients together). ``decided`` False when the search ran
    out of sets (``orients`` is then False and ``states`` empty). A mix that plans such a
    member has no strong plan, whatever the other parts."""

    orients: bool
    states: tuple[int, ...] = ()
    decided: bool = True


def reading_pairs(
    pfs: Sequence[PushFunction],
    sensor: Sensor,
    uncertainty: Uncertainty | None = None,
    *,
    mechanics: Sequence[UncertainMechanics] | None = None,
    offsets: Offsets | None = None,
) -> set[tuple[int, int]]:
    """The pairs ``(i, j)``, ``i < j``, of parts with some states that may read alike: the
    only pairs a strong plan may fail to tell apart.

    On the parts' nominal diameters these are the pairs in one connected component of the
    sensor's overlap relation over all their states (Definition 10). The ideal analysis's
    candidates are fewer (its grid looks at the smallest and largest diameters), since on
    the ideal model a plan can always rotate into the states that read apart; under a
    rotation error it may not reach them (a bar standing on its end). Off the ideal model a
    physical state reads anything its diameter interval can (:func:`physical_diameters`):
    under a shape or COM tolerance every state's, and under rotation error alone a state
    holding ideal states a breath of vibration carries across (an arc's facets) spans their
    diameters, so it may read alike a state of another part between two of them that no
    nominal diameter reaches. The pairs with two such states that may read alike
    (:func:`range_pairs`) are added: a pair no strong plan tells apart has, in the machine
    of the two, states "with overlapping sensor ranges" (section 5; every pair of states
    the strong analysis keeps together can read alike), and these intervals hold theirs.
    ``mechanics``: the parts' :func:`~feederkit.mechanics.uncertain.uncertain_mechanics`,
    when the caller has them (:func:`physical_mechanics`). The planner reads each state over
    its part's reading ``offsets`` too (:func:`part_offsets`, the widths of the part itself
    where import simplified its contact hull: :mod:`feederkit.machine.widths`), so do these
    intervals (:func:`widened_diameters`); None: no part's are known.
    """
    owner = [k for k, pf in enumerate(pfs) for _ in pf.states]
    diameters = [s.diameter for pf in pfs for s in pf.states]
    out: set[tuple[int, int]] = set()
    for component in sensor.indistinguishable_sets(diameters):
        parts = sorted({owner[i] for i in component})
        out.update((a, b) for x, a in enumerate(parts) for b in parts[x + 1 :])
    mechs = None
    if uncertainty is not None and not uncertainty.is_ideal:
        mechs = mechanics or physical_mechanics(pfs, uncertainty)
        out |= range_pairs(physical_diameters(pfs, mechs), sensor)
    if offsets is not None and widens(offsets):
        out |= range_pairs(widened_diameters(pfs, offsets, mechs), sensor)
    return out


def widened_diameters(
    pfs: Sequence[PushFunction],
    offsets: Offsets,
    mechanics: Sequence[UncertainMechanics] | None = None,
) -> list[list[tuple[float, float]]]:
    """Per part, its states' diameter intervals read over its reading ``offsets`` (each
    state over its ideal members' least and largest, as
    :func:`~feederkit.machine.widths.widen_widths` widens them): the ideal states', and
    with ``mechanics`` the physical states' (:func:`physical_diameters`) too."""
    out = []
    for k, pf in enumerate(pfs):
        own = offsets[k]
        spans = [widened_span(s.diameter, s.diameter, own, (s.id,)) for s in pf.states]
        if mechanics is not None:
            phys = physical_diameters([pf], [mechanics[k]])[0]
            ideal = [s.members for s in mechanics[k].states]
            spans += [widened_span(lo, hi, own, m) for (lo, hi), m in zip(phys, ideal, strict=True)]
        out.append(spans)
    return out


def physical_mechanics(
    pfs: Sequence[PushFunction], uncertainty: Uncertainty
) -> list[UncertainMechanics]:
    """Each part's physical states, bands and fence cells under ``uncertainty``
    (:func:`~feederkit.mechanics.uncertain.uncertain_mechanics`), computed once for every
    check of a catalog (a part's machine is built again for each pair it is in). Raises
    InputError naming the part for a tolerance too large for it."""
    return [uncertain_mechanics(pf.part, uncertainty) for pf in pfs]


def physical_diameters(
    pfs: Sequence[PushFunction], mechanics: Sequence[UncertainMechanics]
) -> list[list[tuple[float, float]]]:
    """Per part, its physical resting states' diameter intervals (``mechanics``, the parts'
    :func:`physical_mechanics`), each widened by twice the largest snap any machine of these
    parts makes (``DIAMETER_REL_EPS`` of the largest part:
    :func:`~feederkit.machine.build.snap_intervals` moves an end outward by at most that),
    so each holds what the state reads in the machine of any two of them."""
    if not pfs:
        return []
    pad = 2.0 * DIAMETER_REL_EPS * max(pf.part.size for pf in pfs)
    return [
        [(lo - pad, hi + pad) for lo, hi in (s.diameter for s in mech.states)] for mech in mechanics
    ]


def _machine(
    pfs: Sequence[PushFunction],
    sensor: Sensor,
    uncertainty: Uncertainty,
    mechanics: Sequence[UncertainMechanics] | None,
    offsets: Offsets | None = None,
) -> PushAlignMachine:
    """The machine of ``pfs`` numbered by diameter that ``make_plan`` plans on: as
    ``build_machine`` makes it, from the parts' mechanics when given
    (:func:`physical_mechanics`), each state read over its part's reading ``offsets``
    (default :func:`part_offsets`; :func:`~feederkit.machine.widths.widen_widths`)."""
    if mechanics is None or uncertainty.is_ideal:
        machine = build_machine(pfs, sensor, uncertainty)
    else:
        machine = uncertain_machine(pfs, mechanics, sensor)
    machine = widen_widths(machine, part_offsets(pfs) if offsets is None else offsets)
    return by_diameter(machine)[0]


def range_pairs(diameters: Sequence[Sequence[Diameter]], sensor: Sensor) -> set[tuple[int, int]]:
    """The pairs ``(i, j)``, ``i < j``, of parts ``diameters[i]`` and ``diameters[j]`` with a
    state each that may read alike (:meth:`~feederkit.sensors.Sensor.can_read_alike`).

    A sweep in order of the intervals' lower ends: a state meets only the later states whose
    lower end lies within the sensor's reach (:meth:`~feederkit.sensors.Sensor.reading_reach`)
    of its upper end.

    >>> from feederkit.sensors import ToleranceSensor
    >>> sorted(range_pairs([[10.0], [(10.8, 11.0)], [11.5]], ToleranceSensor(0.5)))
    [(0, 1), (1, 2)]
    """
    states = sorted((*span(d), k) for k, ds in enumerate(diameters) for d in ds)
    los = [lo for lo, _hi, _k in states]
    reach = sensor.reading_reach()
    out: set[tuple[int, int]] = set()
    for x, (lo, hi, k) in enumerate(states):
        # The bound only prunes (with a rounding margin): can_read_alike decides.
        bound = hi + reach + 1e-9 * (abs(hi) + reach)
        end = len(states) if math.isinf(reach) else bisect.bisect_right(los, bound)
        for lo2, hi2, k2 in states[x + 1 : end]:
            if k2 != k and sensor.can_read_alike((lo, hi), (lo2, hi2)):
                out.add((min(k, k2), max(k, k2)))
    return out


def check_strong_pair(
    a: PushFunction,
    b: PushFunction,
    sensor: Sensor,
    uncertainty: Uncertainty,
    deadline: Deadline | None = None,
    *,
    mechanics: Sequence[UncertainMechanics] | None = None,
    offsets: Offsets | None = None,
) -> StrongPairCheck:
    """Whether a strong plan tells ``a`` from ``b`` under ``uncertainty`` with ``sensor``;
    where none does, the witness (its states: the ideal members of the physical states
    confused). ``mechanics``: the two parts' (:func:`physical_mechanics`); ``offsets``:
    their reading offsets (default :func:`part_offsets`): the check is on the machine
    ``make_plan`` plans on. Timeout when ``deadline`` passes."""
    machine = _machine([a, b], sensor, uncertainty, mechanics, offsets)
    problem = Problem(machine, "exact", 0.0)
    found = unresolvable_pairs(problem, deadline)
    if found is None:
        return StrongPairCheck(None, decided=False)
    # As ``plan`` lumps (planning.lumping.try_lumping): each part's near-symmetric states
    # first, so a pair across the parts unresolvable only because those had to be told
    # apart is no witness.
    lumpable = [p for p in found if may_lump(machine, *p, Lumping.NEAR_SYMMETRIC)]
    fewer = within_first(problem, lumpable, deadline)
    if fewer is not None:
        found = sorted(set(fewer) | (set(found) - set(lumpable)))
    states = machine.states
    across = [(i, j) for i, j in found if states[i].part != states[j].part]
    witnesses = strong_witnesses(machine, across)
    return StrongPairCheck(witnesses[0] if witnesses else None)


def check_alone(
    pf: PushFunction,
    sensor: Sensor,
    uncertainty: Uncertainty,
    deadline: Deadline | None = None,
    *,
    mechanics: UncertainMechanics | None = None,
    offsets: Sequence[Offset | None] | None = None,
) -> AloneCheck:
    """Whether a strong plan orients ``pf`` alone under ``uncertainty`` with ``sensor``, as
    ``plan`` decides "no strong plan exists": every reading set of the first alignment has a
    strong plan (:func:`~feederkit.planning.solvable.solve`, exact), or else the lumped goal
    of the default rule has one (:func:`~feederkit.planning.lumping.try_lumping`). Every pair
    of states may have a strong plan while the whole set has none. The searches for a plan
    explore at most ``ALONE_SETS`` sets (undecided beyond); the pairs to lump are decided at
    compile's budget. ``mechanics``: the part's (:func:`physical_mechanics`); ``offsets``:
    its reading offsets (default :func:`part_offsets`). Timeout when ``deadline`` passes.

    >>> from feederkit.mechanics.push import push_function
    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> from feederkit.sensors import ToleranceSensor
    >>> box = make_part(make_outline("box", [(0, 0), (40, 0), (40, 10), (0, 10)]))
    >>> check_alone(push_function(box), ToleranceSensor(0.5), Uncertainty(1.0)).orients
    True
    """
    machine = _machine(
        [pf],
        sensor,
        uncertainty,
        None if mechanics is None else [mechanics],
        None if offsets is None else [offsets],
    )
    # As plan: no result may hold a state a part at rest wanders over unlike poses in.
    machine = twinned(machine, None if deadline is None else deadline.check)[0]
    problem = Problem(machine, "exact", 0.0)
    roots = sorted(maximal_sets(b.mask for b in problem.readings.branches(problem.full)))
    value = solve(problem, roots, deadline, ALONE_SETS)
    if value is None:
        return AloneCheck(False, decided=False)
    if all(math.isfinite(value[r]) for r in roots):
        return AloneCheck(True)
    # The pair check at compile's own budget: past it try_lumping settles for fewer pairs,
    # a verdict compile (which decides them) need not share.
    tried = try_lumping(machine, deadline=deadline, max_sets=ALONE_SETS)
    if tried.goal is not None:
        return AloneCheck(True)
    if not tried.decided:
        return AloneCheck(False, decided=False)
    blamed = [k for pair in tried.unlike for k in pair]
    if not blamed:
        found = unresolvable_pairs(problem, deadline, ALONE_SETS) or ()
        blamed = [k for pair in found for k in pair]
    if not blamed:
        blamed = [k for r in roots if not math.isfinite(value[r]) for k in members(r)]
    ideal = {i for k in blamed for i in machine.states[k].ideal_states}
    return AloneCheck(False, tuple(sorted(ideal)))


__all__ = [
    "ALONE_SETS",
    "AloneCheck",
    "StrongPairCheck",
    "check_alone",
    "check_strong_pair",
    "physical_diameters",
    "physical_mechanics",
    "range_pairs",
    "reading_pairs",
    "widened_diameters",
]
