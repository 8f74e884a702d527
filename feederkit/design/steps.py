"""The optimal plan length as a step function of the sensor tolerance, with exact breakpoints.

A plan's length depends on the sensor only through which states read alike (and, with exact
branching, through the order of the reading intervals' ends, which changes at the same
places): for a tolerance ``e`` the relation is ``|d_i - d_j| < 2e`` over the mix's states
(:mod:`feederkit.design.critical`). So the length is constant on each interval
``(b_k, b_{k+1}]`` between consecutive breakpoints ``b = |d_i - d_j| / 2`` of the machine's
diameters.

It is also monotone while the goal stays the same: a plan for a tolerance ``e`` works for
every smaller ``e'``. Each state's reading interval ``(d - e', d + e')`` lies inside its
interval at ``e``, so every reading the plan meets at ``e'`` is one it could meet at ``e``
and lies in the same branches; the states consistent with it at ``e'`` are a subset of those
at ``e``, and a plan that orients a set orients its subsets (the actions' images of a
subset are subsets of the images). So the minimum worst-case length is non-decreasing in
``e`` (the tests verify plans made at one tolerance under smaller ones, and compare the
table with a plan at every interval). The goal, the inseparable pairs, depends on the
tolerance too: up to the mix's critical tolerance no two parts are inseparable and one
part's own inseparable states are its symmetric poses, which read alike at every
tolerance; past a pair's critical tolerance its parts are inseparable, the plan need no
longer tell them apart and may get shorter. The table is therefore searched in segments
between the pairs' critical tolerances.

Under a declared rotation error (strong plans) the same argument holds for the physical
states' reading intervals ``(lo - e, hi + e)`` (the outcome sets do not depend on the
sensor), provided the goal is the same at both tolerances: bisimilar pairs and the lumped
near-symmetric pairs (docs/planning.md, "Strong plans") are decided with the sensor, so a
strong-plan table also splits its segments where they change. This module is the ideal
model's table; :mod:`feederkit.design.strong` builds the strong one from the same search
(:func:`_segment_runs`).

A plan that rejects some members (``changeover compile --accept``, design.md "Landings")
has a coarser goal: every set of rejected members' states only is a goal (a reject result),
whatever the tolerance, and pairs of two rejected members are not the mix's pairs
(:func:`feederkit.design.critical.told_apart_pairs`). That part of the goal does not depend
on the sensor, so the argument above holds unchanged on the machine whose rejected states
are marked as :func:`feederkit.plans.make.make_plan` marks them.

The search: within a segment, the length at the first interval is proven by the planner's
own AND/OR oracle (:class:`LengthOracle`, no plan tree built); then, for a known length
``L``, monotonicity turns "how long is the plan here" into "is there a plan of at most
``L`` operations here", which needs no proof that shorter plans fail. An exponential then
binary search from the step's start finds its last interval (``O(log run)`` decisions, and
the probes stay near the step, at its cheaper smaller tolerances); the next interval's
length is the least ``L' > L`` that fits, at most the segment's last length. Each step's
plan is then made and verified just below its right end (:func:`plan_evaluation` at
``interval_probe``: at the end itself the machine's outward-snapped reading intervals
already meet), and must have the length the search found.

The expected number of operations changes continuously inside an interval (reading
probabilities depend on ``e``); each step reports it at the interval's right end, its
largest (least accurate) tolerance.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, replace
from typing import Protocol

from feederkit.design.critical import (
    MixCritical,
    breakpoints_of,
    gap_breakpoints,
    interval_probe,
    last_true,
    mix_critical_tolerance,
    planned_machine,
    rejected_of,
)
from feederkit.design.limit import LENGTHS, DesignClock
from feederkit.errors import CheckFailed
from feederkit.machine import Grouping, PushAlignMachine
from feederkit.machine.weights import weigh_members
from feederkit.machine.widths import Offsets
from feederkit.mechanics.modelerror import part_offsets
from feederkit.mechanics.push import PushFunction
from feederkit.planning.andor import WorstCase
from feederkit.planning.api import goal_relation, plan
from feederkit.planning.budget import Deadline
from feederkit.planning.methods import longest_root, make_oracle
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.reindex import by_diameter
from feederkit.plans.make import make_plan
from feederkit.plans.model import PlanMember
from feederkit.sensors import ToleranceSensor, span
from feederkit.uncertainty import IDEAL


@dataclass(frozen=True)
class LengthStep:
    """Tolerances in ``(lo, hi]`` (mm; ``hi`` None: unbounded) all give plans of ``length``.

    ``expected``: the expected number of operations of the optimal plan at ``hi`` (at twice
    ``lo`` when unbounded). ``recognizable``: whether the mix is recognizable there (else
    the plan's results lump parts that no plan can tell apart at these tolerances). Under a
    declared uncertainty ``length`` and ``expected`` are None where no strong plan exists.
    """

    lo: float
    hi: float | None
    length: int | None
    expected: float | None
    recognizable: bool = True

    def to_dict(self) -> dict[str, object]:
        """``{"tolerance_mm": [lo, hi], "length", "expected", "recognizable"}``."""
        return {
            "tolerance_mm": [self.lo, self.hi],
            "length": self.length,
            "expected": self.expected,
            "recognizable": self.recognizable,
        }


@dataclass(frozen=True)
class Evaluation:
    """The optimal plan's worst-case and expected number of operations at one tolerance;
    ``mixes_parts``: its results list states of two parts together (lumped pairs of a strong
    plan), so it does not recognize the mix."""

    length: int
    expected: float
    mixes_parts: bool = False


def mix_breakpoints(pfs: Sequence[PushFunction]) -> tuple[float, ...]:
    """Where the read-alike relation of the mix's states changes (the diameters of the
    machine the planner plans on, :func:`~feederkit.design.critical.planned_machine`)."""
    machine, wide = planned_machine(pfs, part_offsets(pfs))
    return machine_breakpoints(machine, bool(wide))


def machine_breakpoints(machine: PushAlignMachine, widened: bool = False) -> tuple[float, ...]:
    """:func:`mix_breakpoints` of an ideal machine already built: its diameters', or, when
    ``widened`` (its states read over the parts' own widths), its reading intervals' gaps
    (:func:`~feederkit.design.critical.gap_breakpoints`: two states whose intervals meet
    read alike at every tolerance)."""
    if widened:
        spans = [span(s.sensed) for s in machine.states]
        return gap_breakpoints(spans, spans)
    diameters = [s.diameter for s in machine.states]
    eps = 0.0  # the machine has already made equal diameters exactly equal
    return breakpoints_of(diameters, diameters, eps)


BREAKPOINT_REL_EPS = 1e-9
"""A tolerance within this fraction of a breakpoint is that breakpoint: critical tolerances
are computed from a pair's diameters, breakpoints from the mix machine's (snapped) ones, and
the two may differ in the last digits (docs/conventions.md, numeric tolerances)."""


def _first_at_or_above(breaks: Sequence[float], x: float) -> int:
    """The index of the first breakpoint at or above ``x``, one within ``BREAKPOINT_REL_EPS``
    of ``x`` counting as ``x`` itself."""
    return bisect.bisect_left(breaks, x - BREAKPOINT_REL_EPS * abs(x))


def plan_evaluation(
    pfs: Sequence[PushFunction],
    tolerance: float,
    clock: DesignClock | None = None,
    members: Sequence[PlanMember] | None = None,
) -> Evaluation:
    """Length and expected length of the verified optimal plan at ``tolerance`` mm (no
    certificate: the table needs neither its rotation error nor its shape tolerance),
    within what is left of ``clock``'s limit (:meth:`DesignClock.plan`); ``members`` as
    :func:`~feederkit.plans.make.make_plan` takes them (landings, shares, accept/reject)."""
    sensor = ToleranceSensor(tolerance)
    clock = clock or DesignClock()
    made = clock.plan(
        lambda opts: make_plan(
            list(pfs), sensor, opts, uncertainty=IDEAL, certify=False, members=members
        )
    )
    return Evaluation(made.result.length, made.result.expected_length)


def optimal_length(pfs: Sequence[PushFunction], tolerance: float) -> int:
    """The proven minimum worst-case length at ``tolerance`` mm, from a whole plan on the
    machine the planner plans on (the reference the tests hold :class:`LengthOracle` to)."""
    machine, _wide = planned_machine(pfs, part_offsets(pfs), ToleranceSensor(tolerance))
    return plan(machine).length


class StrongOracle(Protocol):
    """What the length search asks (:class:`LengthOracle`; the strong plans' one is
    :class:`feederkit.design.strong.StrongLengthOracle`)."""

    def length(self, tolerance: float) -> int | None: ...

    def within(self, tolerance: float, length: int) -> bool: ...


class LengthOracle:
    """The planner's minimum worst-case length of one mix at any tolerance, without a plan.

    :func:`feederkit.planning.api.plan` proves the length (its AND/OR search, section 6.1,
    from the first alignment's maximal reading sets) and then builds a plan tree with its
    tie-breaks (margins, expected operations), which at large tolerances costs several times
    the proof. The table's probes need only the length, and often only whether a length
    fits: this asks the planner's own oracle (``make_oracle``, the ``auto`` method) those
    questions on the same problem ``plan`` builds (states numbered by diameter, the goal
    relation, exact reading branches, no margin floor). The ideal machine's states and
    action maps do not depend on the sensor, so they are built and numbered once; only the
    sensor, and with it the readings and the goal, change per tolerance. The oracle of the
    last tolerance asked is kept, so repeated questions share its proven bounds. Every
    search polls ``deadline`` (default: none) and raises Timeout when it passes.
    ``rejected``: the indices of members the plan rejects (their states marked as
    :func:`~feederkit.plans.make.make_plan` marks them, so a set of them only is a goal).
    The machine is the one ``make_plan`` plans on: each state read over its part's reading
    ``offsets`` (default :func:`~feederkit.mechanics.modelerror.part_offsets`); ``widened`` says
    whether they widened any state (the breakpoints are then the intervals' gaps).
    """

    def __init__(
        self,
        pfs: Sequence[PushFunction],
        deadline: Deadline | None = None,
        rejected: Collection[int] = (),
        offsets: Offsets | None = None,
    ) -> None:
        self.deadline = deadline or Deadline()
        offsets = part_offsets(pfs) if offsets is None else offsets
        built, wide = planned_machine(pfs, offsets)
        self.widened = bool(wide)
        self.machine = weigh_members(built, None, rejected)
        self._sorted, _old = by_diameter(self.machine)
        self._last: tuple[float, Problem, WorstCase, list[int]] | None = None

    def _search(self, tolerance: float) -> tuple[Problem, WorstCase, list[int]]:
        if self._last is not None and self._last[0] == tolerance:
            return self._last[1:]
        self._last = None  # free the previous tolerance's memo first
        machine = replace(self._sorted, sensor=ToleranceSensor(tolerance))
        budget = self.deadline
        problem = Problem(machine, Grouping.EXACT, 0.0, goal_relation(machine, budget))
        roots = sorted(maximal_sets(b.mask for b in problem.readings.branches(problem.full)))
        worst = make_oracle(problem, "auto", budget)
        self._last = (tolerance, problem, worst, roots)
        return problem, worst, roots

    def length(self, tolerance: float) -> int:
        """The minimum worst-case number of operations at ``tolerance`` mm (as ``plan``'s)."""
        problem, worst, roots = self._search(tolerance)
        return 1 + longest_root(problem, worst, roots, "auto")

    def within(self, tolerance: float, length: int) -> bool:
        """Whether some plan at ``tolerance`` mm takes at most ``length`` operations."""
        if length < 1:
            return False
        _problem, worst, roots = self._search(tolerance)
        return all(worst.within(r, length - 1) for r in roots)


def recognizable_below(breaks: Sequence[float], critical: MixCritical) -> int:
    """The first interval index at which the mix is no longer recognizable: interval ``k`` is
    recognizable iff its right end is at most the mix's critical tolerance."""
    mix_x = critical.critical_tolerance
    if mix_x is None:
        return 0
    if math.isinf(mix_x):
        return len(breaks) + 1
    return _first_at_or_above(breaks, mix_x) + 1


def length_steps(
    pfs: Sequence[PushFunction],
    up_to: float | None,
    oracle: LengthOracle | None = None,
    evaluate: Callable[[float], Evaluation] | None = None,
    critical: MixCritical | None = None,
    clock: DesignClock | None = None,
    members: Sequence[PlanMember] | None = None,
    offsets: Offsets | None = None,
) -> tuple[LengthStep, ...]:
    """The plan length's steps over tolerances ``(0, up_to]`` (None: every interval).

    ``up_to`` is rounded up to the end of its interval, so the last step is whole.
    ``oracle`` answers the search's length questions (default :class:`LengthOracle` of the
    mix); ``evaluate`` makes each step's verified plan at its right end (default
    :func:`plan_evaluation`) and must agree with the search (else CheckFailed).
    ``critical``: the mix's pairs' critical tolerances, if already known. ``clock``
    (:mod:`feederkit.design.limit`): the time limit every search polls (the default
    oracle's and plans'), told of each run of intervals decided. ``members``: the plan's
    members as :func:`~feederkit.plans.make.make_plan` takes them; the default oracle,
    plans and pairs then plan for rejected members as ``changeover compile --accept`` does.
    ``offsets``: the parts' reading offsets (default
    :func:`~feederkit.mechanics.modelerror.part_offsets`), for the default oracle and pairs: both
    read each state over the parts' own widths, as the plans do.

    The intervals are searched in segments between the pairs' critical tolerances (the
    goal changes there) and steps never span two segments; inside a segment the length is
    monotone (the module's docstring).
    """
    clock = clock or DesignClock()
    rejected = rejected_of(members)
    if offsets is None and (oracle is None or critical is None):
        offsets = part_offsets(pfs)
    oracle = oracle or LengthOracle(pfs, clock.deadline, rejected, offsets)
    breaks = machine_breakpoints(oracle.machine, oracle.widened)
    evaluate = evaluate or (lambda e: plan_evaluation(pfs, e, clock, members))
    critical = critical or mix_critical_tolerance(pfs, clock, rejected, offsets)
    last = len(breaks) if up_to is None else _first_at_or_above(breaks, up_to)
    clock.begin(LENGTHS, last + 1)
    # Interval k is recognizable for a pair iff its right end is at most the pair's critical.
    changes = {
        _first_at_or_above(breaks, p.critical_tolerance) + 1
        for p in critical.pairs
        if p.critical_tolerance is not None and not math.isinf(p.critical_tolerance)
    }
    starts = sorted({0} | {c for c in changes if 0 < c <= last})
    below = recognizable_below(breaks, critical)
    fit = fit_memo(oracle, breaks, clock)
    steps = []
    for first, end in zip(starts, [*starts[1:], last + 1], strict=True):
        runs = _segment_runs(first, end - 1, breaks, oracle, fit, evaluate, clock)
        for lo, hi, j, ev in checked_runs(runs, breaks, "plan"):
            steps.append(LengthStep(lo, hi, ev.length, ev.expected, j < below))
    return tuple(steps)


def fit_memo(
    oracle: LengthOracle | StrongOracle, breaks: Sequence[float], clock: DesignClock
) -> Callable[[int, int], bool]:
    """``fit(k, length)``: whether interval ``k`` has a plan of at most ``length`` operations
    (``oracle.within`` at the interval's probe), each question asked once per table (the
    gallop and the next step's search ask again); ``clock`` is polled before each."""
    fits: dict[tuple[int, int], bool] = {}

    def fit(k: int, length: int) -> bool:
        if (k, length) not in fits:
            clock.check()
            fits[k, length] = oracle.within(interval_probe(breaks, k), length)
        return fits[k, length]

    return fit


def checked_runs(
    runs: Sequence[tuple[int, int, int, Evaluation]], breaks: Sequence[float], plan: str
) -> list[tuple[float, float | None, int, Evaluation]]:
    """The runs of :func:`_segment_runs` as tolerances ``(lo, hi]`` (``hi`` None: unbounded)
    with their last interval and verified plan; CheckFailed, naming the ``plan``, when a
    verified plan's length is not the one the search found (the table must not lie)."""
    out = []
    for i, j, length, ev in runs:
        if ev.length != length:
            raise CheckFailed(
                f"the verified {plan} at {interval_probe(breaks, j):g} mm has length "
                f"{ev.length}, the search over tolerances found {length}"
            )
        out.append(
            (0.0 if i == 0 else breaks[i - 1], breaks[j] if j < len(breaks) else None, j, ev)
        )
    return out


def _segment_runs(
    first: int,
    j_last: int,
    breaks: Sequence[float],
    oracle: LengthOracle | StrongOracle,
    fit: Callable[[int, int], bool],
    evaluate: Callable[[float], Evaluation],
    clock: DesignClock | None = None,
) -> list[tuple[int, int, int, Evaluation]]:
    """The constant runs ``(i, j, length, verified plan at j)`` of intervals ``first..j_last``,
    over which the length is non-decreasing; ``clock`` is polled and told of each run."""
    clock = clock or DesignClock()
    clock.check()
    top = evaluate(interval_probe(breaks, j_last))  # the segment's last interval ends a step
    runs = []
    k = first
    clock.check()
    length = top.length if first == j_last else oracle.length(interval_probe(breaks, first))
    while length < top.length and k < j_last:
        # fit(k, length) holds, fit(j_last, length) does not: gallop, then bisect.
        lo, step, hi = k, 1, j_last
        while lo + step < j_last:
            if not fit(lo + step, length):
                hi = lo + step
                break
            lo += step
            step *= 2
        j = lo + 1 + last_true(hi - lo - 1, lambda d, lo=lo, n=length: fit(lo + 1 + d, n))
        clock.check()
        runs.append((k, j, length, evaluate(interval_probe(breaks, j))))
        clock.advance(j + 1 - k)
        k = j + 1
        # The length at k exceeds the last one and is at most the segment's last length.
        below = range(length + 1, top.length) if k < j_last else ()
        length = next((n for n in below if fit(k, n)), top.length)
    runs.append((k, j_last, length, top))
    clock.advance(j_last + 1 - k)
    return runs
