"""Critical tolerances: the largest sensor tolerance at which parts can still be told apart.

On the ideal model (all uncertainty bounds zero); :mod:`feederkit.design.strong` decides
them for strong plans at a declared uncertainty with the same search.

With a tolerance sensor of tolerance ``e`` two states of diameters ``d`` and ``d'`` read
alike iff ``|d - d'| < 2e`` (design.md's open interval). The read-alike relation, and so
everything decided from it (distinguishability, definition 11 and Theorem 9; the plan
length), changes only at the *breakpoints* ``e = |d - d'| / 2``: it is the same for every
``e`` in ``(b_k, b_{k+1}]``. Between breakpoints nothing changes, so the exact answer is
reached by a binary search over the sorted breakpoints with the exact pair test
(:func:`feederkit.mix.pairs.distinguishable`), not by bisection on floats.

Distinguishability is monotone in ``e``: a larger tolerance only adds read-alike pairs, so
the greatest fixpoint of inseparable pairs only grows (the tests check it exhaustively on
random pairs). Diameters equal within the library's relative ``DIAMETER_REL_EPS`` always
read alike and give no breakpoint.

Where import simplified a part's contact hull the planner reads each of its states over the
part's own widths (:mod:`feederkit.machine.widths`, :func:`planned_machine`); a pair with
such a part is decided on that machine, its states' intervals giving the breakpoints
(:func:`widened_pair_critical`), so no critical tolerance rests on a difference only the
simplification makes. Parts with exact hulls are decided on their diameters as above.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, replace

from feederkit.angles import ActionRange
from feederkit.design.limit import PAIRS, DesignClock
from feederkit.machine import OutcomeRange, PushAlignMachine, members
from feederkit.machine.build import build_machine
from feederkit.machine.inseparable import inseparable_masks
from feederkit.machine.widths import Offsets, widen_widths, widens
from feederkit.mechanics.modelerror import part_offsets
from feederkit.mechanics.push import PushFunction
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS
from feederkit.mix.pairs import PairWitness, distinguishable
from feederkit.plans.model import PlanMember
from feederkit.sensors import NoSensor, Sensor, ToleranceSensor, span
from feederkit.uncertainty import IDEAL, Uncertainty

Span = tuple[float, float]


def _eps(pfs: Sequence[PushFunction]) -> float:
    """Diameters closer than this are the same diameter (as the machine and pair test say)."""
    return DIAMETER_REL_EPS * max(pf.part.size for pf in pfs)


def breakpoints_of(diameters_a: Sequence[float], diameters_b: Sequence[float], eps: float):
    """The sorted distinct ``|d - d'| / 2`` over ``d`` in a and ``d'`` in b above ``eps / 2``."""
    return tuple(
        sorted({abs(x - y) / 2.0 for x in diameters_a for y in diameters_b if abs(x - y) > eps})
    )


def pair_breakpoints(pf_a: PushFunction, pf_b: PushFunction) -> tuple[float, ...]:
    """The tolerances at which two parts' cross read-alike relation changes."""
    return breakpoints_of(
        [s.diameter for s in pf_a.states], [s.diameter for s in pf_b.states], _eps([pf_a, pf_b])
    )


def interval_gap(x: Span, y: Span) -> float:
    """How far apart two diameter intervals are (negative or zero when they meet): they read
    alike under a tolerance ``e`` iff the gap is below ``2e``."""
    return max(x[0] - y[1], y[0] - x[1])


def gap_breakpoints(spans_a: Sequence[Span], spans_b: Sequence[Span]) -> tuple[float, ...]:
    """The sorted distinct ``gap / 2`` over the pairs of an interval of a and one of b whose
    gap is positive: the tolerances at which their read-alike relation changes."""
    return tuple(
        sorted({g / 2.0 for x in spans_a for y in spans_b if (g := interval_gap(x, y)) > 0})
    )


def sub_machine(machine: PushAlignMachine, parts: Sequence[int]) -> PushAlignMachine:
    """The states of ``parts`` (in that order of parts) of a mix machine, as a machine.

    A part's outcomes are its own states, so the parts' states with their action maps
    (outcome masks renumbered) are closed; intervals, weights and records stay the mix's.
    """
    keep = [i for p in parts for i, s in enumerate(machine.states) if s.part == p]
    new = {old: k for k, old in enumerate(keep)}
    part_of = {p: k for k, p in enumerate(parts)}

    def moved(r: ActionRange | OutcomeRange) -> OutcomeRange:
        out = 0
        for t in members(_mask(r)):
            out |= 1 << new[t]
        return OutcomeRange(r.lo, r.hi, out)

    states = tuple(replace(machine.states[i], part=part_of[machine.states[i].part]) for i in keep)
    maps = tuple(tuple(moved(r) for r in machine.action_maps[i]) for i in keep)
    return PushAlignMachine(
        part_names=tuple(machine.part_names[p] for p in parts),
        states=states,
        action_maps=maps,
        sensor=machine.sensor,
        uncertainty=machine.uncertainty,
    )


def _mask(r: ActionRange | OutcomeRange) -> int:
    return r.targets if isinstance(r, OutcomeRange) else 1 << r.target


def planned_machine(
    pfs: Sequence[PushFunction],
    offsets: Offsets,
    sensor: Sensor | None = None,
    uncertainty: Uncertainty = IDEAL,
) -> tuple[PushAlignMachine, frozenset[int]]:
    """The machine :func:`~feederkit.plans.make.make_plan` plans on (before it weighs and
    marks the members): ``build_machine``'s, each state read over its part's ``offsets``
    (:func:`~feederkit.machine.widths.widen_widths`,
    :func:`~feederkit.mechanics.modelerror.part_offsets`), and the parts whose states that
    widens. With no part widened the machine is ``build_machine``'s own,
    and every figure of the design is the one the parts' model gives."""
    built = build_machine(list(pfs), NoSensor() if sensor is None else sensor, uncertainty)
    machine = widen_widths(built, offsets)
    wide = frozenset(
        s.part for s, t in zip(machine.states, built.states, strict=True) if s is not t
    )
    return machine, wide


PROBE_REL = 1e-6
"""An interval's probe lies this far below its right end, relative (and at least this many
mm), or at its middle when the interval is narrower."""


def interval_probe(breaks: Sequence[float], k: int) -> float:
    """A tolerance inside interval ``k``: ``(b_{k-1}, b_k]`` (``b_{-1} = 0``), or past the last.

    Just below the right end ``b_k`` for ``k < len(breaks)`` (``PROBE_REL``), not at it: the
    machine snaps the reading intervals outward by a hair (``DIAMETER_REL_EPS`` of the
    parts' size, so that exact ties survive rounding), so at ``b_k`` itself the two
    diameters that meet there already read alike, as in the next interval (at a pair's
    critical tolerance the pair is then inseparable and the plan shorter); twice the last
    breakpoint (or 1 mm without breakpoints) for the unbounded last interval.

    >>> interval_probe([0.5, 2.0], 1) < 2.0 < interval_probe([0.5, 2.0], 2)
    True
    """
    if k < len(breaks):
        hi = breaks[k]
        lo = breaks[k - 1] if k else 0.0
        return hi - min((hi - lo) / 2.0, max(PROBE_REL * hi, PROBE_REL))
    return 2.0 * breaks[-1] if breaks else 1.0


def last_true(count: int, test: Callable[[int], bool], known: int = -1) -> int:
    """The largest ``k`` in ``[0, count)`` with ``test(k)``, for a test true then false; -1 if none.

    Binary search: ``ceil(log2(count - known))`` calls of ``test``; ``known``: an index
    where ``test`` is already known to hold (-1: none).
    """
    lo, hi = known, count  # test(lo) is true (or lo = -1), test(hi) false (or hi = count)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if test(mid):
            lo = mid
        else:
            hi = mid
    return lo


def last_true_top_first(count: int, test: Callable[[int], bool], known: int = -1) -> int:
    """:func:`last_true`, asking ``test(count - 1)`` first: one call when the test holds on
    the whole range, one more than the binary search otherwise."""
    if known >= count - 1:
        return count - 1
    if test(count - 1):
        return count - 1
    return last_true(count - 1, test, known)


@dataclass(frozen=True)
class PairCritical:
    """A pair of parts and its critical tolerance (mm): the largest ``e`` still distinguishable.

    None when no tolerance tells them apart (then ``witness`` says why, e.g. the same
    push-diameter function, Lemma 8). At exactly ``critical_tolerance`` the pair reads apart
    (the open interval); at any larger tolerance it does not.
    """

    a: str
    b: str
    critical_tolerance: float | None
    witness: PairWitness | None = None

    def to_dict(self) -> dict[str, object]:
        """``{"a", "b", "critical_tolerance_mm"}`` and, when none works, the ``reason``."""
        out: dict[str, object] = {
            "a": self.a,
            "b": self.b,
            "critical_tolerance_mm": self.critical_tolerance,
        }
        if self.witness is not None:
            out["reason"] = self.witness.reason
        return out


def pair_critical_tolerance(
    pf_a: PushFunction, pf_b: PushFunction, clock: DesignClock | None = None
) -> PairCritical:
    """The exact critical tolerance of two parts, by binary search over their breakpoints.

    Interval ``k`` of the breakpoints is tested at its right end with the exact pair test
    (definition 11); the largest distinguishable interval's right end is the answer. Past the
    last breakpoint every cross pair reads alike, so the pair is never distinguishable there.
    A Hausdorff bound starts the search: while some state of one part is farther than ``2e``
    from every state of the other, no inseparable pair can exist (every state of each part
    is in one, see :mod:`feederkit.mix.pairs`). ``clock`` is polled before each pair test
    (:mod:`feederkit.design.limit`).
    """
    clock = clock or DesignClock()
    breaks = pair_breakpoints(pf_a, pf_b)
    da = [s.diameter for s in pf_a.states]
    db = [s.diameter for s in pf_b.states]
    eps = _eps([pf_a, pf_b])
    hausdorff = max(
        max(min(abs(x - y) for y in db) for x in da),
        max(min(abs(x - y) for y in da) for x in db),
    )
    # Intervals whose right end is at most half the Hausdorff distance are distinguishable.
    sure = bisect.bisect_right(breaks, hausdorff / 2.0) - 1 if hausdorff > eps else -1

    def ok(k: int) -> bool:
        if k <= sure:
            return True
        clock.check()
        return distinguishable(pf_a, pf_b, ToleranceSensor(breaks[k])) is None

    k = last_true(len(breaks), ok)
    name_a, name_b = pf_a.part.name, pf_b.part.name
    if k < 0:
        why = distinguishable(pf_a, pf_b, ToleranceSensor(interval_probe(breaks, 0)))
        return PairCritical(name_a, name_b, None, why)
    return PairCritical(name_a, name_b, breaks[k])


@dataclass(frozen=True)
class MixCritical:
    """The critical tolerance of a mix and of each of its pairs of parts.

    The mix is recognizable (section 8.5) iff every pair of its parts is distinguishable,
    so its critical tolerance is the smallest of the pairs' (None when one pair has none:
    no tolerance works; a single part has no pair and is recognizable with any). A mix
    with rejected members holds the pairs a plan must tell apart (:func:`told_apart_pairs`).
    """

    pairs: tuple[PairCritical, ...]

    @property
    def critical_tolerance(self) -> float | None:
        """The largest tolerance (mm) at which the mix is recognizable (inf for one part)."""
        values = [p.critical_tolerance for p in self.pairs]
        if any(v is None for v in values):
            return None
        return min((v for v in values if v is not None), default=float("inf"))

    @property
    def inseparable(self) -> tuple[PairCritical, ...]:
        """The pairs that no tolerance can tell apart."""
        return tuple(p for p in self.pairs if p.critical_tolerance is None)

    @property
    def limiting(self) -> tuple[PairCritical, ...]:
        """The pairs whose critical tolerance is the mix's (the ones that set it)."""
        c = self.critical_tolerance
        return tuple(p for p in self.pairs if p.critical_tolerance == c)


def rejected_of(members: Sequence[PlanMember] | None) -> frozenset[int]:
    """The indices of the members the next station does not take (``accept`` False)."""
    return frozenset(k for k, m in enumerate(members or ()) if not m.accept)


def told_apart_pairs(n: int, rejected: Collection[int] = ()) -> list[tuple[int, int]]:
    """The pairs ``(i, j)``, ``i < j``, of ``n`` members that a plan must tell apart, in
    member order: every pair but two rejected members (both end in reject results, design.md
    "Landings"; :func:`feederkit.mix.changeover.reported_pairs`)."""
    out = set(rejected)
    return [(i, j) for i in range(n) for j in range(i + 1, n) if not (i in out and j in out)]


def mix_critical_tolerance(
    pfs: Sequence[PushFunction],
    clock: DesignClock | None = None,
    rejected: Collection[int] = (),
    offsets: Offsets | None = None,
) -> MixCritical:
    """Every pair's exact critical tolerance, in part order, and so the mix's; ``clock``
    (:mod:`feederkit.design.limit`) is polled and told of each pair decided. ``rejected``:
    the indices of members the plan rejects; two of them need not be told apart, so their
    pair is left out (:func:`told_apart_pairs`). ``offsets``: the parts' reading offsets
    (default :func:`~feederkit.mechanics.modelerror.part_offsets`); a pair with a part they
    widen is decided on the machine the planner plans on (:func:`widened_pair_critical`),
    the others on their diameters (:func:`pair_critical_tolerance`)."""
    clock = clock or DesignClock()
    offsets = part_offsets(pfs) if offsets is None else offsets
    machine, wide = planned_machine(pfs, offsets) if widens(offsets) else (None, frozenset())
    wanted = told_apart_pairs(len(pfs), rejected)
    clock.begin(PAIRS, len(wanted))
    pairs = []
    for i, j in wanted:
        clock.check()
        if machine is not None and (i in wide or j in wide):
            pairs.append(widened_pair_critical(machine, pfs, i, j, clock))
        else:
            pairs.append(pair_critical_tolerance(pfs[i], pfs[j], clock))
        clock.advance()
    return MixCritical(tuple(pairs))


HULL_REASON = (
    "the parts themselves read alike: their contact hulls simplify the outlines' arcs, and "
    "every action keeps states reading alike over the widths of the parts themselves (a "
    "smaller --hull-tolerance may tell them apart)"
)


def cross_inseparable(
    machine: PushAlignMachine, tolerance: float, clock: DesignClock | None = None
) -> list[tuple[int, int]]:
    """The inseparable (state of part 0, state of part 1) pairs of a two-part machine under
    a tolerance sensor, as machine indices (:func:`~feederkit.machine.inseparable.
    inseparable_masks`: on the ideal model the fixpoint of section 8.4 over the machine's
    reading intervals); the fixpoint polls ``clock`` (default none)."""
    check = None if clock is None else clock.check
    masks = inseparable_masks(replace(machine, sensor=ToleranceSensor(tolerance)), check)
    first = [i for i, s in enumerate(machine.states) if s.part == 0]
    return [(i, j) for i in first for j in members(masks[i]) if machine.states[j].part == 1]


def widened_pair_critical(
    machine: PushAlignMachine,
    pfs: Sequence[PushFunction],
    a: int,
    b: int,
    clock: DesignClock | None = None,
) -> PairCritical:
    """:func:`pair_critical_tolerance` of parts ``a`` and ``b`` on the ideal ``machine``
    the planner plans on (:func:`planned_machine`), whose states read over intervals: the
    parts' own widths where import simplified a contact hull.

    A state of diameter interval ``[lo, hi]`` reads anywhere in ``(lo - e, hi + e)``, so two
    states read alike iff their gap is below ``2e``: the breakpoints are the gaps' halves
    (:func:`gap_breakpoints`), and on them the same binary search with the same test (the
    greatest fixpoint of inseparable cross pairs, on the pair's states of ``machine``), the
    same Hausdorff start. Two states whose intervals meet read alike at every tolerance.
    """
    clock = clock or DesignClock()
    m = sub_machine(machine, (a, b))
    spans = [span(s.sensed) for s in m.states]
    sa = [x for x, s in zip(spans, m.states, strict=True) if s.part == 0]
    sb = [x for x, s in zip(spans, m.states, strict=True) if s.part == 1]
    breaks = gap_breakpoints(sa, sb)
    far = max(
        max(min(interval_gap(x, y) for y in sb) for x in sa),
        max(min(interval_gap(x, y) for x in sa) for y in sb),
    )
    # b <= far / 2: some state reads apart from every state of the other part.
    sure = bisect.bisect_right(breaks, far / 2.0) - 1 if far > 0.0 else -1

    def ok(k: int) -> bool:
        if k <= sure:
            return True
        clock.check()
        return not cross_inseparable(m, breaks[k], clock)

    k = last_true(len(breaks), ok)
    pa, pb = pfs[a], pfs[b]
    if k >= 0:
        return PairCritical(pa.part.name, pb.part.name, breaks[k])
    probe = interval_probe(breaks, 0)
    found = cross_inseparable(m, probe, clock)
    ideal = distinguishable(pa, pb, ToleranceSensor(probe))
    reason, kind = (HULL_REASON, "hull") if ideal is None else (ideal.reason, ideal.kind)
    witness = machine_witness(pa, pb, m, found, reason, kind)
    return PairCritical(pa.part.name, pb.part.name, None, witness)


def machine_witness(
    pa: PushFunction,
    pb: PushFunction,
    m: PushAlignMachine,
    pairs: Sequence[tuple[int, int]],
    reason: str,
    kind: str,
    index_a: int = 0,
    index_b: int = 1,
) -> PairWitness:
    """The witness that ``pa`` and ``pb`` are not told apart: the stable states of the pairs
    ``(i, j)`` of the two-part machine ``m`` (part a's state, part b's) that stay together."""
    return PairWitness(
        part_a=pa.part.name,
        part_b=pb.part.name,
        states_a=tuple(m.states[i].state for i, _ in pairs),
        states_b=tuple(m.states[j].state for _, j in pairs),
        reason=reason,
        kind=kind,
        index_a=index_a,
        index_b=index_b,
    )
