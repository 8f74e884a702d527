"""Building the push-align machine from push functions (sections 3 and 8.5).

This is where the abstract machine meets geometry: each part's resting states, resting
ranges and action ranges (:mod:`feederkit.mechanics`) become machine states and maps. Under a
declared uncertainty (design.md, "Uncertainty") the states are the physical resting states of
:mod:`feederkit.mechanics.uncertain`, each with its diameter interval, and each action range
leads to the set of states nature may pick; the ideal model (``IDEAL``) gives exactly the
paper's machine.
"""

from __future__ import annotations

from collections.abc import Sequence

from feederkit.angles import ActionRange
from feederkit.machine.inseparable import inseparable_masks
from feederkit.machine.model import MachineState, OutcomeRange, PushAlignMachine
from feederkit.mechanics.actions import action_ranges
from feederkit.mechanics.outcomes import action_map
from feederkit.mechanics.push import PushFunction, resting_widths
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS, look_alike, unlike_pairs
from feederkit.mechanics.uncertain import UncertainMechanics, uncertain_mechanics
from feederkit.sensors import NoSensor, Sensor
from feederkit.uncertainty import IDEAL, Uncertainty


def snap(values: Sequence[float], eps: float) -> list[float]:
    """Replace each value by its cluster's first (:func:`snap_spans`)."""
    return [lo for lo, _hi in snap_spans(values, eps)]


def snap_spans(values: Sequence[float], eps: float) -> list[tuple[float, float]]:
    """Per value, the smallest and largest value of its cluster: in sorted order, a cluster
    is a value and every later one within ``eps`` of it.

    A state whose diameter is snapped reads as its cluster's span: equal spans keep exact
    ties (symmetric poses read alike exactly), and the span holds every member's true,
    unsnapped value, so no reading a member can give falls outside the reading sets the
    planner branches on (docs/conventions.md, "Numeric tolerances").

    >>> snap_spans([2.0, 1.0, 1.0 + 1e-12, 3.0], 1e-9)
    [(2.0, 2.0), (1.0, 1.000000000001), (1.0, 1.000000000001), (3.0, 3.0)]
    """
    order = sorted(range(len(values)), key=lambda i: values[i])
    out: list[tuple[float, float]] = [(0.0, 0.0)] * len(values)
    k = 0
    while k < len(order):
        j = k + 1
        while j < len(order) and values[order[j]] - values[order[k]] <= eps:
            j += 1
        span = (values[order[k]], values[order[j - 1]])
        for i in order[k:j]:
            out[i] = span
        k = j
    return out


def snap_intervals(
    intervals: Sequence[tuple[float, float]], eps: float
) -> list[tuple[float, float]]:
    """Diameter intervals with their ends snapped outward: each lower end to its cluster's
    smallest value, each upper end to its cluster's largest (ends of all intervals clustered
    together, as :func:`snap_spans`).

    Equal-within-``eps`` intervals become exactly equal and each still holds its true one,
    so the reading sets the planner branches on hold every reading a state can give.

    >>> snap_intervals([(1.0, 2.0), (1.0 + 1e-12, 2.0 - 1e-12)], 1e-9)
    [(1.0, 2.0), (1.0, 2.0)]
    """
    spans = snap_spans([x for iv in intervals for x in iv], eps)
    return [(spans[2 * k][0], spans[2 * k + 1][1]) for k in range(len(intervals))]


def build_machine(
    push_functions: Sequence[PushFunction],
    sensor: Sensor | None = None,
    uncertainty: Uncertainty | None = None,
) -> PushAlignMachine:
    """The machine of one part or a mix (section 8.5): the parts' states side by side.

    ``uncertainty`` defaults to design.md's ``Uncertainty()`` (rotation error 1 degree);
    ``IDEAL`` gives the paper's machine: one state per stable state, exact diameters, one
    target per action range. Otherwise a state is a physical resting state with a diameter
    interval and its action ranges lead to outcome sets (:func:`uncertain_machine`).
    Diameters equal within ``DIAMETER_REL_EPS`` of the largest part are snapped
    (docs/conventions.md): each such state reads as its cluster's span (``diameter`` the
    span's smallest value, ``diameter_range`` the span when it is not a point), so exact
    symmetry survives rounding and every reading a state's true diameter can give lies in
    the reading sets the planner branches on. Raises InputError for a shape tolerance too
    large for a part.
    """
    sensor = NoSensor() if sensor is None else sensor
    uncertainty = Uncertainty() if uncertainty is None else uncertainty
    if not uncertainty.is_ideal:
        mechs = [uncertain_mechanics(pf.part, uncertainty) for pf in push_functions]
        return uncertain_machine(push_functions, mechs, sensor)
    offsets = []
    total = 0
    for pf in push_functions:
        offsets.append(total)
        total += pf.n
    eps = DIAMETER_REL_EPS * max(pf.part.size for pf in push_functions)
    spans = snap_spans([s.diameter for pf in push_functions for s in pf.states], eps)
    states = []
    maps = []
    k = 0
    share = len(push_functions)
    for p, pf in enumerate(push_functions):
        widths = resting_widths(pf)
        for s in pf.states:
            lo, hi = spans[k]
            reads = None if lo == hi else (lo, hi)
            states.append(MachineState(p, s.id, lo, widths[s.id] / 360.0 / share, reads))
            ranges = action_ranges(pf, s.id)
            maps.append(tuple(ActionRange(r.lo, r.hi, r.target + offsets[p]) for r in ranges))
            k += 1
    return PushAlignMachine(
        part_names=tuple(pf.part.name for pf in push_functions),
        states=tuple(states),
        action_maps=tuple(maps),
        sensor=sensor,
        uncertainty=IDEAL,
    )


def uncertain_machine(
    push_functions: Sequence[PushFunction],
    mechanics: Sequence[UncertainMechanics],
    sensor: Sensor,
) -> PushAlignMachine:
    """The machine of the parts' physical resting states under their mechanics' uncertainty.

    A state's ``members`` are its ideal stable states, ``state`` the first of them,
    ``diameter_range`` its reading interval (ends snapped outward, :func:`snap_intervals`) and its
    weight the resting ranges of the ideal states a first alignment can end in, each shared
    equally among the physical states it may settle in (``destinations``). ``look_alike``
    names the part's other physical states whose poses are near-congruent
    (:func:`~feederkit.mechanics.symmetry.look_alike`: within ``NEAR_SYMMETRIC_REL`` of the
    part's size) or that no plan tells apart even on the ideal model (:func:`ideal_twins`):
    the pairs of one part a leaf may list together.
    """
    offsets = []
    total = 0
    for mech in mechanics:
        offsets.append(total)
        total += mech.n
    eps = DIAMETER_REL_EPS * max(pf.part.size for pf in push_functions)
    ends = snap_intervals([s.diameter for mech in mechanics for s in mech.states], eps)
    share = len(push_functions)
    states = []
    maps = []
    k = 0
    for p, (pf, mech) in enumerate(zip(push_functions, mechanics, strict=True)):
        widths = resting_widths(pf)
        weight = [0.0] * mech.n
        for i, dest in enumerate(mech.destinations):
            for t in dest:
                weight[t] += widths[i] / 360.0 / share / len(dest)
        alike = look_alike(pf, [s.members for s in mech.states])
        # Only pairs that do not look alike can be twins worth finding (the ideal fixpoint
        # costs more than the build on a part of hundreds of near-round facets).
        unlike = any(len(alike[s.id]) < mech.n - 1 for s in mech.states)
        twins = ideal_twins(pf, mech) if unlike else [set()] * mech.n
        wandering = unlike_members(pf, mech)
        for s in mech.states:
            lo, hi = ends[k]
            k += 1
            states.append(
                MachineState(
                    p,
                    s.members[0],
                    (lo + hi) / 2.0,
                    weight[s.id],
                    (lo, hi),
                    s.members,
                    look_alike=tuple(
                        mech.states[t].members[0] for t in sorted({*alike[s.id], *twins[s.id]})
                    ),
                    unlike_members=s.id in wandering,
                )
            )
            ranges = []
            for a, b, targets in action_map(mech, s.id):
                mask = 0
                for t in targets:
                    mask |= 1 << (t + offsets[p])
                ranges.append(OutcomeRange(a, b, mask))
            maps.append(tuple(ranges))
    return PushAlignMachine(
        part_names=tuple(pf.part.name for pf in push_functions),
        states=tuple(states),
        action_maps=tuple(maps),
        sensor=sensor,
        uncertainty=mechanics[0].uncertainty,
    )


TWIN_MAX_STATES = 64
"""Parts with more ideal stable states get no :func:`ideal_twins` (the pair fixpoint costs
0.7 s at 114 states and 14 s at 429; such near-round parts' alike poses are near-congruent)."""


WANDER_ARC_DEG = 90.0
"""A physical state whose resting orientations span at least this many degrees, with members
that do not look alike, is a part that may rest on unlike sides (a small part under a large
tolerance, a cam of shallow wells): no orientation. A narrower one (an arc's facets, two
near-metastable neighbours) is design.md's physical state, oriented up to its interval."""


def unlike_members(pf: PushFunction, mech: UncertainMechanics) -> set[int]:
    """The physical states of ``mech`` whose resting orientations span ``WANDER_ARC_DEG`` or
    more and that hold two ideal members that neither look alike
    (:func:`~feederkit.mechanics.symmetry.look_alike`) nor are told apart by no plan on the
    ideal model (:func:`ideal_twins`' rule): a part at rest may wander between unlike sides
    (the merge rule, docs/uncertainty.md), so a result holding such a state does not orient
    the part."""
    merged = [
        s
        for s in mech.states
        if len(s.members) > 1 and s.rest_deg[1] - s.rest_deg[0] >= WANDER_ARC_DEG
    ]
    out: set[int] = set()
    twins: tuple[int, ...] | None = None
    index: dict[int, int] = {}
    for s in merged:
        far = unlike_pairs(pf, [(m,) for m in s.members])
        if not far:
            continue
        if pf.n > TWIN_MAX_STATES:
            out.add(s.id)
            continue
        if twins is None:
            ideal = build_machine([pf], NoSensor(), IDEAL)
            twins = inseparable_masks(ideal)
            index = {x.state: i for i, x in enumerate(ideal.states)}
        rows = [index[m] for m in s.members]
        if any(not twins[rows[a]] >> rows[b] & 1 for a, b in far):
            out.add(s.id)
    return out


def ideal_twins(pf: PushFunction, mech: UncertainMechanics) -> list[set[int]]:
    """Per physical state of ``mech``, the part's other physical states that pushing alone
    cannot tell apart even on the ideal model: every ideal member of either is inseparable
    without a sensor (:func:`~feederkit.machine.inseparable.inseparable_masks`) from one of
    the other's. These are the paper's indistinguishable sets of a push function, symmetric
    poses and poses that behave identically (the three poses of Fig. 17's heptagon, which
    every rotation permutes), which a result may list together under any uncertainty. No
    sensor, so the record is the same whatever sensor the machine is later given (the
    sensor design swaps it). None beyond ``TWIN_MAX_STATES`` stable states.
    """
    if pf.n > TWIN_MAX_STATES:
        return [set() for _ in mech.states]
    ideal = build_machine([pf], NoSensor(), IDEAL)
    insep = inseparable_masks(ideal)
    index = {s.state: i for i, s in enumerate(ideal.states)}

    def together(a: int, b: int) -> bool:
        return a == b or bool(insep[index[a]] >> index[b] & 1)

    out: list[set[int]] = []
    for s in mech.states:
        out.append(
            {
                t.id
                for t in mech.states
                if t.id != s.id
                and all(any(together(a, b) for b in t.members) for a in s.members)
                and all(any(together(a, b) for a in s.members) for b in t.members)
            }
        )
    return out
