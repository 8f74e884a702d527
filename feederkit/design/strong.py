"""Sensor design under a declared uncertainty: the figures of strong plans (design.md,
"Uncertainty"; docs/design.md).

Under a rotation error, shape or COM tolerance the machine's states are physical resting
states with diameter *intervals* ``[lo, hi]`` and their action ranges lead to outcome sets
(:func:`feederkit.machine.build.build_machine`); none of that depends on the sensor. A
tolerance sensor reads such a state anywhere in the open ``(lo - e, hi + e)``, so two states
read alike iff ``max(lo_i - hi_j, lo_j - hi_i) < 2e``
(:meth:`feederkit.sensors.ToleranceSensor.can_read_alike`): the relation changes exactly at
the *breakpoints* ``e = max(lo_i - hi_j, lo_j - hi_i) / 2`` of the pairs whose intervals
have a gap (for exact diameters ``|d_i - d_j| / 2``, the ideal model's). At a breakpoint the
two still read apart.

- Two parts are distinguishable by strong plans when some strong plan ends, for every
  outcome and reading, in results that hold states of one part only (:func:`separable`).
  A state of the one bisimilar to a state of the other (:mod:`feederkit.machine.inseparable`)
  rules it out, but is not needed to: nature may keep two states apart, reading alike, by
  picking outcomes without mirroring every run (such pairs are not bisimilar, and the
  planner lumps them, docs/planning.md). So the pair test is the exact solvability of the
  two parts' states of the mix machine (:func:`sub_machine`, with the mix's own intervals)
  for the goal "one part". It is monotone in ``e`` (the goal does not depend on it, and a
  strong plan at ``e`` works at every smaller tolerance: below), and the critical tolerance
  is found by a binary search over the pair's breakpoints, as on the ideal model
  (:mod:`feederkit.design.critical`).
- The plan length is monotone in ``e`` while the planner's goal is the same
  (:mod:`feederkit.design.steps`): the bisimilar pairs and, when no strong plan reaches
  them, the lumped pairs no strong plan resolves (docs/planning.md, "Near-symmetric states
  under uncertainty"). Both are monotone chains: bisimilarity grows with ``e``; with the
  bisimilar goal fixed, a strong plan at ``e`` works at every smaller tolerance, so
  solvability only fails and the unresolvable pairs only grow as ``e`` grows. Their
  change points are found by bisection on equality (a chain equal at two intervals is
  constant between them), first for the bisimilar relation, then for the whole goal within
  each of its segments; the length search runs segment by segment. Where no strong plan
  exists the step says so (length None) instead of a length.
"""

from __future__ import annotations

import bisect
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import reduce
from operator import or_

from feederkit.design.critical import (
    MixCritical,
    PairCritical,
    Span,
    gap_breakpoints,
    interval_gap,
    interval_probe,
    last_true,
    last_true_top_first,
    machine_witness,
    planned_machine,
    rejected_of,
    sub_machine,
    told_apart_pairs,
)
from feederkit.design.limit import GOALS, LENGTHS, PAIRS, DesignClock
from feederkit.design.steps import (
    Evaluation,
    LengthStep,
    _first_at_or_above,
    _segment_runs,
    checked_runs,
    fit_memo,
    recognizable_below,
)
from feederkit.machine import Grouping, PushAlignMachine, members
from feederkit.machine.inseparable import inseparable_masks, kept_apart
from feederkit.machine.weights import weigh_members
from feederkit.mechanics.modelerror import part_offsets
from feederkit.mechanics.push import PushFunction
from feederkit.mix.pairs import distinguishable
from feederkit.planning.andor import WorstCase
from feederkit.planning.api import FIRST_LIMIT, goal_relation, strong_plan_exists
from feederkit.planning.budget import Deadline
from feederkit.planning.lumping import try_lumping
from feederkit.planning.methods import longest_root, make_oracle
from feederkit.planning.options import Lumping
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.reindex import by_diameter
from feederkit.planning.solvable import unsolvable
from feederkit.planning.wandering import split_wandering, twin_masks
from feederkit.plans.make import make_plan
from feederkit.plans.model import PlanMember
from feederkit.sensors import NoSensor, Sensor, ToleranceSensor, span
from feederkit.uncertainty import Uncertainty, check_for_part


class StrongMix:
    """The mix machine at a declared uncertainty (built once, without a sensor) and its
    two-part sub-machines, for the pair tests.

    ``members`` (one per push function, as :func:`~feederkit.plans.make.make_plan` takes
    them; None: the parts, each accepted) say which members the plan rejects: ``planned``
    is the machine with their states marked, as the planner plans it (a set of rejected
    states only is a goal), and two rejected members are not a pair to tell apart.

    As :func:`~feederkit.plans.make.make_plan` plans, each state reads over its part's
    reading ``offsets`` (:func:`~feederkit.design.critical.planned_machine`: the part
    itself may read a little off its simplified contact hull's diameters); ``widened``
    names the parts whose states that widens."""

    def __init__(
        self,
        pfs: Sequence[PushFunction],
        uncertainty: Uncertainty,
        members: Sequence[PlanMember] | None = None,
    ) -> None:
        for pf in pfs:
            check_for_part(uncertainty, pf.part)
        self.pfs = list(pfs)
        self.uncertainty = uncertainty
        self.members = None if members is None else tuple(members)
        self.rejected = rejected_of(self.members)
        self.offsets = part_offsets(self.pfs)
        self.machine, self.widened = planned_machine(
            self.pfs, self.offsets, NoSensor(), uncertainty
        )
        self.planned = weigh_members(self.machine, None, self.rejected)

    def pair(self, a: int, b: int) -> PushAlignMachine:
        """Parts ``a`` and ``b`` (states of a first) of the mix machine."""
        return sub_machine(self.machine, (a, b))


NO_STRONG_PLAN = "no strong plan exists at the declared uncertainty"

STRONG_REASON = "no strong plan tells their resting states apart under {what}"


def uncertainty_words(u: Uncertainty) -> str:
    """The declared uncertainty in words (design.md's three bounds)."""
    return (
        f"rotation error {u.rotation_error_deg:g} deg, shape tolerance "
        f"{u.shape_tolerance_mm:g} mm, COM tolerance {u.com_tolerance_mm:g} mm"
    )


def bisimilar_cross_pairs(
    machine: PushAlignMachine, tolerance: float, deadline: Deadline | None = None
) -> list[tuple[int, int]]:
    """The bisimilar (state of part 0, state of part 1) pairs of a two-part machine under a
    tolerance sensor, as machine indices; the fixpoint polls ``deadline`` (default none)."""
    check = None if deadline is None else deadline.check
    masks = inseparable_masks(replace(machine, sensor=ToleranceSensor(tolerance)), check)
    first = [i for i, s in enumerate(machine.states) if s.part == 0]
    return [(i, j) for i in first for j in members(masks[i]) if machine.states[j].part == 1]


def separable(machine: PushAlignMachine, tolerance: float) -> bool:
    """Whether a strong plan tells the two parts of a two-part machine apart under a
    tolerance sensor: one whose every result holds states of one part only.

    Decided exactly (:func:`~feederkit.planning.solvable.unsolvable`) on the goal "every
    pair of one part's states" (orienting each part is not asked); a bisimilar cross pair,
    or one nature keeps apart (:func:`kept_cross_pairs`), answers no at once. Undecided
    (more sets than the solver explores) counts as no, so a critical tolerance is never
    overstated. No time limit here; :func:`strong_pair_critical` takes one, and a test cut
    short by it raises Timeout, never answers no.
    """
    return _PairProbes(machine).separable(tolerance)


class _PairProbes:
    """The pair tests of one two-part machine, each computed once per tolerance: the
    bisimilar cross pairs, the one-part problem, the kept cross pairs and the exact solve
    are pure in the tolerance, and the binary searches of :func:`strong_pair_critical`
    ask several of them at the same tolerances. Every test polls ``deadline`` (default
    none); one it stops raises Timeout and records nothing, so no timed-out test is ever
    remembered as "not separable"."""

    def __init__(self, machine: PushAlignMachine, deadline: Deadline | None = None) -> None:
        self.machine = machine
        self.deadline = deadline or Deadline()
        self._bisimilar: dict[float, list[tuple[int, int]]] = {}
        self._problems: dict[float, Problem] = {}
        self._unkept: dict[float, bool] = {}
        self._separable: dict[float, bool] = {}

    def bisimilar(self, tolerance: float) -> list[tuple[int, int]]:
        if tolerance not in self._bisimilar:
            self.deadline.check()
            self._bisimilar[tolerance] = bisimilar_cross_pairs(
                self.machine, tolerance, self.deadline
            )
        return self._bisimilar[tolerance]

    def problem(self, tolerance: float) -> Problem:
        if tolerance not in self._problems:
            self._problems[tolerance] = _one_part_problem(self.machine, tolerance)
        return self._problems[tolerance]

    def no_kept_cross_pair(self, tolerance: float) -> bool:
        """No bisimilar cross pair and none nature keeps apart (cheap necessary tests)."""
        if tolerance not in self._unkept:
            self.deadline.check()
            self._unkept[tolerance] = not self.bisimilar(tolerance) and not kept_cross_pairs(
                self.problem(tolerance)
            )
        return self._unkept[tolerance]

    def separable(self, tolerance: float) -> bool:
        """:func:`separable` at ``tolerance``."""
        if tolerance not in self._separable:
            self.deadline.check()
            self._separable[tolerance] = self.no_kept_cross_pair(tolerance) and self._solve(
                tolerance
            )
        return self._separable[tolerance]

    def _solve(self, tolerance: float) -> bool:
        problem = self.problem(tolerance)
        roots = sorted(maximal_sets(b.mask for b in problem.readings.branches(problem.full)))
        # A short strong plan, when there is one, is found by the planner's depth-first
        # length search long before the exact fixpoint has explored every reachable set
        # (as :func:`feederkit.planning.api.plan` does); only a failure needs the fixpoint.
        worst = make_oracle(problem, "auto", self.deadline)
        if all(worst.within(r, FIRST_LIMIT - 1) for r in roots):
            return True
        bad = unsolvable(problem, roots, self.deadline)  # Timeout propagates: not a "no"
        return bad is not None and not bad


def _one_part_problem(machine: PushAlignMachine, tolerance: float) -> Problem:
    """The two-part machine under a tolerance sensor, numbered by diameter, with the goal
    "every pair of one part's states"."""
    ordered, _old = by_diameter(replace(machine, sensor=ToleranceSensor(tolerance)))
    part_mask = [0, 0]
    for i, s in enumerate(ordered.states):
        part_mask[s.part] |= 1 << i
    goal = tuple(part_mask[s.part] for s in ordered.states)
    return Problem(ordered, Grouping.EXACT, 0.0, goal)


def kept_cross_pairs(problem: Problem) -> set[tuple[int, int]]:
    """The cross pairs nature can keep apart for ever, reading alike
    (:func:`~feederkit.machine.inseparable.kept_apart`): when there is one, some first reading
    holds both states of it, and no strong plan separates the parts (a cheap, sound no).
    Monotone in the tolerance (a greatest fixpoint over read-alike pairs)."""
    m = problem.machine
    sensed = [s.sensed for s in m.states]
    pairs = [
        (i, j)
        for i in range(m.n)
        for j in range(i + 1, m.n)
        if m.states[i].part != m.states[j].part and m.sensor.can_read_alike(sensed[i], sensed[j])
    ]
    return kept_apart(m, pairs)


def outcomes_cover_parts(machine: PushAlignMachine) -> bool:
    """Whether every state's outcomes (over all its action ranges) are all of its part's
    states: some rotation sends it to each resting state of its part."""
    part_mask: dict[int, int] = {}
    for i, s in enumerate(machine.states):
        part_mask[s.part] = part_mask.get(s.part, 0) | 1 << i
    return all(
        reduce(or_, machine.outcomes_of[i], 0) == part_mask[s.part]
        for i, s in enumerate(machine.states)
    )


def apart_up_to(
    machine: PushAlignMachine,
    spans_a: Sequence[Span],
    spans_b: Sequence[Span],
    breaks: Sequence[float],
) -> int:
    """The last index of ``breaks`` at which a two-part machine has no bisimilar cross
    pair because some state of one part reads apart from every state of the other
    (a directed Hausdorff gap of at least ``2e``), or -1.

    Bisimilar states match each other's outcomes with bisimilar ones
    (:func:`~feederkit.machine.inseparable.inseparable_masks`), so when every state's
    outcomes cover its part (:func:`outcomes_cover_parts`) one bisimilar cross pair gives
    every state of both parts a partner of the other that reads alike.
    """
    if not spans_a or not spans_b or not outcomes_cover_parts(machine):
        return -1
    far = max(
        max(min(interval_gap(x, y) for y in spans_b) for x in spans_a),
        max(min(interval_gap(x, y) for x in spans_a) for y in spans_b),
    )
    # b <= far / 2 iff 2 b <= far (both halvings exact): every such b reads that state apart.
    return bisect.bisect_right(breaks, far / 2.0) - 1


def strong_pair_critical(
    mix: StrongMix, a: int, b: int, clock: DesignClock | None = None
) -> PairCritical:
    """The critical tolerance of parts ``a`` and ``b`` of the mix for strong plans: the
    largest tolerance at which a strong plan tells them apart (:func:`separable`).

    Binary search over the pair's breakpoints (the module docstring): separability is
    monotone in the tolerance (a strong plan at one tolerance works at every smaller one,
    its goal being the same, and bisimilar cross pairs only grow). The search first finds
    the last interval without a bisimilar cross pair (the last breakpoint's is asked first,
    and none below :func:`apart_up_to` is asked), then without a cross pair nature keeps
    apart (both fixpoints over pairs, cheap, monotone and necessary), and solves there; only
    when that fails does it search the intervals below with the solver. Every test polls
    ``clock``'s deadline (:mod:`feederkit.design.limit`).
    """
    clock = clock or DesignClock()
    m = mix.pair(a, b)
    spans = [span(s.sensed) for s in m.states]
    sa = [x for x, s in zip(spans, m.states, strict=True) if s.part == 0]
    sb = [x for x, s in zip(spans, m.states, strict=True) if s.part == 1]
    breaks = gap_breakpoints(sa, sb)
    # Separable implies no bisimilar cross pair, which is cheap to test and monotone too:
    # its last interval bounds the answer, and is most often the answer itself. That
    # interval is most often the last breakpoint's, so it is asked first.
    probes = _PairProbes(m, clock.deadline)
    apart = apart_up_to(m, sa, sb, breaks)
    k = last_true_top_first(len(breaks), lambda k: not probes.bisimilar(breaks[k]), apart)
    if k >= 0 and not probes.no_kept_cross_pair(breaks[k]):
        k = last_true(k, lambda k: probes.no_kept_cross_pair(breaks[k]))
    if k >= 0 and not probes.separable(breaks[k]):
        k = last_true(k, lambda k: probes.separable(breaks[k]))
    pa, pb = mix.pfs[a], mix.pfs[b]
    if k >= 0:
        return PairCritical(pa.part.name, pb.part.name, breaks[k])
    probe = interval_probe(breaks, 0)
    pairs = probes.bisimilar(probe)
    ideal = distinguishable(pa, pb, ToleranceSensor(probe), index_a=a, index_b=b)
    if ideal is not None and ideal.kind == "same-push-diameter":
        reason, kind = ideal.reason, ideal.kind
    else:
        reason = STRONG_REASON.format(what=uncertainty_words(mix.uncertainty))
        kind = "uncertainty"
    witness = machine_witness(pa, pb, m, pairs, reason, kind, a, b)
    return PairCritical(pa.part.name, pb.part.name, None, witness)


def strong_mix_critical(mix: StrongMix, clock: DesignClock | None = None) -> MixCritical:
    """Every pair's critical tolerance for strong plans, in part order, and so the mix's
    (pairs of two rejected members left out, :func:`~feederkit.design.critical.told_apart_pairs`);
    ``clock`` (:mod:`feederkit.design.limit`) is polled and told of each pair decided."""
    clock = clock or DesignClock()
    wanted = told_apart_pairs(len(mix.pfs), mix.rejected)
    clock.begin(PAIRS, len(wanted))
    pairs = []
    for i, j in wanted:
        clock.check()
        pairs.append(strong_pair_critical(mix, i, j, clock))
        clock.advance()
    return MixCritical(tuple(pairs))


Goal = tuple[int, ...] | None
"""The planner's goal masks at one tolerance (None: no strong plan exists there)."""

KEPT_SEARCHES = 4
"""Searches (per tolerance: problem, oracle, roots) the strong oracle keeps."""


class StrongLengthOracle:
    """The planner's minimum worst-case length of a mix at any tolerance under a declared
    uncertainty, without a plan tree, and the goal it plans for.

    As :class:`feederkit.design.steps.LengthOracle`, on the uncertain machine (built and
    numbered by diameter once; only the sensor changes): the goal is what
    :func:`feederkit.planning.api.plan` uses with the default lumping, the bisimilar
    relation, or, when no strong plan reaches it, the lumped goal of
    :func:`~feederkit.planning.lumping.try_lumping` (None when neither has a strong plan).
    Every search polls ``deadline`` (default none) and raises Timeout when it passes; a
    goal is recorded only when decided. The machine is the mix's as planned
    (:attr:`StrongMix.planned`: rejected members' states marked).
    """

    def __init__(self, mix: StrongMix, deadline: Deadline | None = None) -> None:
        self.mix = mix
        self.deadline = deadline or Deadline()
        self.machine = mix.planned
        # The planner's machine: numbered by diameter, then a twin for each state where a part
        # at rest wanders over unlike poses (no result may hold it: planning.wandering).
        self._plain, _old = by_diameter(self.machine)
        self._sorted, self._twin_of = split_wandering(self._plain)
        self._bisimilar: dict[float, tuple[int, ...]] = {}
        self._goals: dict[float, Goal] = {}
        self._searches: OrderedDict[
            tuple[float, tuple[int, ...]], tuple[Problem, WorstCase, list[int]]
        ] = OrderedDict()

    def at(self, tolerance: float) -> PushAlignMachine:
        """The sorted machine with a tolerance sensor of ``tolerance`` mm."""
        return replace(self._sorted, sensor=ToleranceSensor(tolerance))

    def bisimilar(self, tolerance: float) -> tuple[int, ...]:
        """The bisimilar relation (masks, sorted numbering) at ``tolerance`` mm."""
        if tolerance not in self._bisimilar:
            plain = replace(self._plain, sensor=ToleranceSensor(tolerance))
            goal = goal_relation(plain, self.deadline)
            if self._sorted is not self._plain:
                # The machine's own relation, over the twins and keeping each apart from
                # its state (planning.wandering.twinned).
                goal = twin_masks(goal, self._twin_of, apart=True)
            self._bisimilar[tolerance] = goal
        return self._bisimilar[tolerance]

    def _problem(self, tolerance: float, goal: tuple[int, ...]):
        key = (tolerance, goal)
        found = self._searches.get(key)
        if found is not None:
            self._searches.move_to_end(key)
            return found
        problem = Problem(self.at(tolerance), Grouping.EXACT, 0.0, goal)
        roots = sorted(maximal_sets(b.mask for b in problem.readings.branches(problem.full)))
        worst = make_oracle(problem, "auto", self.deadline)
        self._searches[key] = (problem, worst, roots)
        while len(self._searches) > KEPT_SEARCHES:
            self._searches.popitem(last=False)
        return problem, worst, roots

    def goal(self, tolerance: float) -> Goal:
        """The planner's goal at ``tolerance`` mm (the class docstring)."""
        if tolerance in self._goals:
            return self._goals[tolerance]
        base = self.bisimilar(tolerance)
        problem, worst, roots = self._problem(tolerance, base)
        goal: Goal = base
        if not all(worst.within(r, FIRST_LIMIT - 1) for r in roots):
            bad = unsolvable(problem, roots, self.deadline)
            if bad:
                tried = try_lumping(self.at(tolerance), Grouping.EXACT, self.deadline,
                                    rule=Lumping.NEAR_SYMMETRIC)  # fmt: skip
                # try_lumping answers "undecided" when the deadline passes: not a goal.
                self.deadline.check()
                goal = tried.goal.insep if tried.goal is not None else None
        self._goals[tolerance] = goal
        return goal

    def length(self, tolerance: float) -> int | None:
        """The minimum worst-case number of operations of a strong plan at ``tolerance`` mm
        (as ``plan``'s), or None when there is none."""
        goal = self.goal(tolerance)
        if goal is None:
            return None
        problem, worst, roots = self._problem(tolerance, goal)
        try:
            longest = longest_root(problem, worst, roots, "auto", 4 * problem.n + 4)
        except ValueError:
            return None
        return 1 + longest

    def within(self, tolerance: float, length: int) -> bool:
        """Whether some strong plan at ``tolerance`` mm takes at most ``length`` operations."""
        goal = self.goal(tolerance)
        if goal is None or length < 1:
            return False
        _problem, worst, roots = self._problem(tolerance, goal)
        return all(worst.within(r, length - 1) for r in roots)


def machine_breakpoints(machine: PushAlignMachine) -> tuple[float, ...]:
    """Where the read-alike relation of a machine's states (diameter intervals) changes."""
    spans = [span(s.sensed) for s in machine.states]
    return gap_breakpoints(spans, spans)


def chain_changes(
    first: int,
    last: int,
    value: Callable[[int], object],
    settled: Callable[[int], None] | None = None,
) -> set[int]:
    """Every ``k`` in ``(first, last]`` with ``value(k) != value(k - 1)``, for a ``value``
    that is a monotone chain on ``first..last`` (equal at two intervals: constant between),
    by bisection: ``O(changes * log(last - first))`` calls. ``settled(n)`` is told each
    time ``n`` more of the ``last - first`` neighbouring pairs are decided."""
    out: set[int] = set()
    stack = [(first, last)]
    while stack:
        lo, hi = stack.pop()
        if hi <= lo or value(lo) == value(hi):
            if settled is not None and hi > lo:
                settled(hi - lo)
            continue
        if hi == lo + 1:
            out.add(hi)
            if settled is not None:
                settled(1)
            continue
        mid = (lo + hi) // 2
        stack.extend(((mid, hi), (lo, mid)))
    return out


def goal_segments(
    oracle: StrongLengthOracle,
    breaks: Sequence[float],
    last: int,
    clock: DesignClock | None = None,
) -> list[tuple[int, int]]:
    """The runs ``(first, last)`` of intervals ``0..last`` with one goal each: the bisimilar
    relation's segments, each split where the lumped goal changes (module docstring).
    ``clock`` is polled before each probe and told of the neighbouring intervals decided
    (``2 * last`` in all: each pair once per chain)."""
    clock = clock or DesignClock()
    clock.begin(GOALS, 2 * last)

    def probe(k: int) -> float:
        clock.check()
        return interval_probe(breaks, k)

    cuts = sorted(chain_changes(0, last, lambda k: oracle.bisimilar(probe(k)), clock.advance))
    clock.advance(len(cuts))  # the pairs across a cut: no goal chain spans them
    starts = set([0, *cuts])
    for s, e in zip([0, *cuts], [*(c - 1 for c in cuts), last], strict=True):
        starts |= chain_changes(s, e, lambda k: oracle.goal(probe(k)), clock.advance)
    ordered = sorted(starts)
    return list(zip(ordered, [*(c - 1 for c in ordered[1:]), last], strict=True))


def strong_evaluation(
    pfs: Sequence[PushFunction],
    uncertainty: Uncertainty,
    tolerance: float,
    clock: DesignClock | None = None,
    plan_members: Sequence[PlanMember] | None = None,
) -> Evaluation:
    """Length and expected length of the verified optimal strong plan at ``tolerance`` mm,
    and whether it lists states of two parts together (then it does not recognize the mix;
    two rejected members may share a reject result), within what is left of ``clock``'s
    limit (:meth:`DesignClock.plan`); ``plan_members`` as
    :func:`~feederkit.plans.make.make_plan` takes them."""
    sensor = ToleranceSensor(tolerance)
    clock = clock or DesignClock()
    result = clock.plan(
        lambda opts: make_plan(
            list(pfs), sensor, opts, uncertainty=uncertainty, certify=False, members=plan_members
        )
    ).result
    return Evaluation(
        result.length,
        result.expected_length,
        bool(_cross_lumps(result.machine, result.lumped_pairs)),
    )


def _cross_lumps(
    machine: PushAlignMachine, lumped: Sequence[tuple[int, int]]
) -> set[tuple[int, int]]:
    """The pairs of members ``(a, b)``, ``a < b``, whose states a strong plan lumps, but two
    rejected members (both end in a reject result)."""
    states = machine.states
    return {
        (min(states[i].part, states[j].part), max(states[i].part, states[j].part))
        for i, j in lumped
        if states[i].part != states[j].part and not (states[i].reject and states[j].reject)
    }


def strong_length_steps(
    mix: StrongMix,
    up_to: float | None,
    critical: MixCritical,
    oracle: StrongLengthOracle | None = None,
    evaluate: Callable[[float], Evaluation] | None = None,
    clock: DesignClock | None = None,
) -> tuple[LengthStep, ...]:
    """The strong plan length's steps over tolerances ``(0, up_to]`` (None: every interval),
    as :func:`feederkit.design.steps.length_steps` on the ideal model, segment by segment of
    constant goal; a segment with no strong plan is one step of length None. ``clock``
    (:mod:`feederkit.design.limit`): the time limit every search polls (the default
    oracle's and plans'), told of the goal search's probes and of each run decided."""
    clock = clock or DesignClock()
    oracle = oracle or StrongLengthOracle(mix, clock.deadline)
    breaks = machine_breakpoints(oracle.machine)
    evaluate = evaluate or (
        lambda e: strong_evaluation(mix.pfs, mix.uncertainty, e, clock, mix.members)
    )
    last = len(breaks) if up_to is None else _first_at_or_above(breaks, up_to)
    below = recognizable_below(breaks, critical)
    fit = fit_memo(oracle, breaks, clock)
    steps = []
    segments = goal_segments(oracle, breaks, last, clock)
    clock.begin(LENGTHS, last + 1)
    for first, j_last in segments:
        lo = 0.0 if first == 0 else breaks[first - 1]
        if oracle.goal(interval_probe(breaks, first)) is None:
            hi = breaks[j_last] if j_last < len(breaks) else None
            steps.append(LengthStep(lo, hi, None, None, False))
            clock.advance(j_last + 1 - first)
            continue
        runs = _segment_runs(first, j_last, breaks, oracle, fit, evaluate, clock)
        for lo, hi, j, ev in checked_runs(runs, breaks, "strong plan"):
            ok = j < below and not ev.mixes_parts
            steps.append(LengthStep(lo, hi, ev.length, ev.expected, ok))
    return tuple(steps)


@dataclass(frozen=True)
class StrongPitch:
    """One LED pitch under a declared uncertainty: the pairs of parts with bisimilar states,
    and the verified strong plan's length and expected length (None: no strong plan)."""

    unrecognizable: tuple[tuple[str, str], ...]
    length: int | None
    expected: float | None
    no_plan: str | None = None


def strong_pitch(mix: StrongMix, sensor: Sensor, clock: DesignClock | None = None) -> StrongPitch:
    """Decide one LED array (``sensor``) for strong plans: bisimilar cross pairs of the mix
    machine (but two rejected members'), then (when there are none) a verified strong plan,
    whose results must not list two members together (but two rejected ones); every search
    polls ``clock``'s deadline."""
    clock = clock or DesignClock()
    machine = replace(mix.planned, sensor=sensor)
    masks = inseparable_masks(machine, clock.check)
    states = machine.states
    names = machine.part_names
    bad = sorted(
        {
            (states[i].part, states[j].part)
            for i in range(machine.n)
            for j in members(masks[i])
            if states[i].part < states[j].part and not (states[i].reject and states[j].reject)
        }
    )
    if bad:
        return StrongPitch(tuple((names[a], names[b]) for a, b in bad), None, None)
    exists = strong_plan_exists(machine, deadline=clock.deadline)
    clock.check()  # it answers True when its deadline passed: not a decision
    if not exists:
        return StrongPitch((), None, None, NO_STRONG_PLAN)
    result = clock.plan(
        lambda opts: make_plan(
            mix.pfs,
            sensor,
            opts,
            uncertainty=mix.uncertainty,
            certify=False,
            members=mix.members,
        )
    ).result
    lumped = sorted(_cross_lumps(result.machine, result.lumped_pairs))
    return StrongPitch(
        tuple((names[a], names[b]) for a, b in lumped), result.length, result.expected_length
    )


__all__ = [
    "StrongLengthOracle",
    "StrongMix",
    "StrongPitch",
    "chain_changes",
    "gap_breakpoints",
    "goal_segments",
    "interval_gap",
    "machine_breakpoints",
    "strong_evaluation",
    "strong_length_steps",
    "strong_mix_critical",
    "strong_pair_critical",
    "strong_pitch",
    "sub_machine",
]
