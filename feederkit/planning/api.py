"""The planners' public entry point: ``plan(machine, options) -> PlanResult``.

The root is the first alignment from an unknown orientation (``Step(action=None)``); its
branches are the readings of the full set of states. Each branch is then oriented by a
minimum worst-case plan (sections 4 and 6), ties broken by the order of docs/planning.md
(see :mod:`feederkit.planning.refine`). ``length`` counts the first alignment (design.md).
When the exact search runs out of its budget, :mod:`feederkit.planning.fallback` answers.

References
----------
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), sections 4 (sensorless plans), 6
(AND/OR search 6.1, bottom-up 6.4) and 8.5 (mixes).
Goldberg, K. Y. (1993). Orienting polygonal parts without sensors. Algorithmica 10
(backchaining: the plan where the readings carry nothing).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import replace

from feederkit.errors import InputError, PlanningError
from feederkit.machine import PushAlignMachine, search_space
from feederkit.machine.inseparable import inseparable_masks
from feederkit.planning.andor import WorstCase
from feederkit.planning.budget import (
    Checkpoint,
    Deadline,
    Timeout,
    WorkBudget,
    collector_paused,
)
from feederkit.planning.fallback import NoFallback, fallback, sensorless_plan
from feederkit.planning.lumping import try_lumping, unlike_words
from feederkit.planning.margins import largest_margin
from feederkit.planning.methods import longest_root, make_oracle
from feederkit.planning.options import Lumping, OutOfBudget, PlanningOptions, out_of_budget
from feederkit.planning.problem import Problem
from feederkit.planning.quiet import QuietWorst, chain_plan, widest_chain
from feederkit.planning.readings import maximal_sets
from feederkit.planning.refine import Refiner, child_masses, stage, tie_floor
from feederkit.planning.reindex import by_diameter, remap_tree, share_bisimilar
from feederkit.planning.sensorless import BackchainWorst
from feederkit.planning.solvable import (
    NoStrongPlan,
    decide,
    kept_roots,
    length_cap,
    no_strong_plan,
    unsolvable,
)
from feederkit.planning.stats import expected_operations, tree_length, tree_min_margin
from feederkit.planning.tree import (
    TIES_CHAIN,
    TIES_EXACT,
    TIES_MARGIN,
    TIES_NONE,
    PlanResult,
    Step,
    branch_pairs,
    root_step,
)
from feederkit.planning.wandering import twinned, wandering_words

FALLBACK_SHARE = 0.3
"""With a time limit, the share of it kept for finding some plan when the exact search fails."""

EXACT_CHECK_SHARE = 0.4
"""With a time limit, the share of the exact search's own time (from when it starts to
``1 - FALLBACK_SHARE`` of the limit) after which it goes on only when at least this share
of the root branches' lengths is proven (:func:`_on_course`); else the fallback gets the
rest of the limit (:class:`~feederkit.planning.budget.Checkpoint`)."""

UNDECIDED_CHECK_SHARE = 0.1
"""For a lumped goal that lumping left undecided (more sets reach it from the roots than
``LUMPED_ROOT_SETS``, or lumping's share of the limit ran out), the share of the exact
search's own time after which it is judged, instead of ``EXACT_CHECK_SHARE``; it must still
have proven ``EXACT_CHECK_SHARE`` of the roots by then, so it goes on only when well ahead of
pace: such a search rarely finishes, and the time goes to the anytime plans sooner (the
50-part mix at 5 % under 1 degree, 60 s: the exact search handed over after 14 s at
``EXACT_CHECK_SHARE`` and the first plan came at 36 s, 13 operations at the limit; at this
share after 3 s, the first plan at 21.5 s, 12 at the limit)."""

EXACT_MEMORY_SHARE = 0.8
"""With a memory limit, the share of it the exact search may hold; the rest is headroom for
the plan built when it stops."""

FIRST_TREE_SHARE = 0.85
"""Where (as a share of the time limit) the tree of a proven length with no tie-breaking
must be built; after that the fallback answers. It is a first plan: its verification may
take the caller's reserve (``Deadline.reserve_s``, :func:`_first_tree_budget`)."""

TIE_SHARE = 3.0
"""The ``worst`` objective's tie-breaking stages (the margin, then the expected operations)
may poll their budget this many times as often as the length proof did, plus
``TIE_GRACE_POLLS``: a budget of work (:class:`~feederkit.planning.budget.WorkBudget`), so
the same machine gives the same plan on any computer and under any load. A margin probe's
poll costs about what a proof's does (it asks the length search too: on the 20-part mix at
5 % under 1 degree 2,300 against 2,000 per CPU second), an expected-operations poll (a set,
or ``refine.BOUNDS_PER_POLL`` bounds) a quarter (``python benchmarks/bench_tie_budget.py``:
14,436 against 3,456 per CPU second over its cases, mostly that stage's), so the margin
stage takes at most about three times the proof's time and the expected stage at most
about a quarter of it, plus the grace. The margin stage needs 1.0-2.2 times the proof's
polls on the mixes of docs/performance.md's "Margin probes in the length search's order"."""

EXPECTED_SHARE = 1.0
"""Of that budget the expected-operations stage, the last and least of the tie-breaks, may
poll at most this many times as often as the length proof did, plus ``TIE_GRACE_POLLS``:
the margin stage (the larger margin, what a real feeder's rotation error needs) gets the
rest first."""

TIE_GRACE_POLLS = 10_000
"""Polls the tie-breaking stages get on top of ``TIE_SHARE`` of the length proof's (a second
of expected-operations polls on the benchmark machine, up to four of margin probes): the
small cases, whose proof polls a few hundred times, break their ties exactly."""


def strong_plan_exists(
    machine: PushAlignMachine,
    options: PlanningOptions | None = None,
    deadline: Deadline | None = None,
) -> bool:
    """Whether some strong plan orients every state of ``machine`` (no margin floor), up to
    inseparable states or, as :func:`plan` does, to the lumped goal that ``options.lumping``
    allows (:func:`~feederkit.planning.lumping.try_lumping`).

    Decided by :func:`~feederkit.planning.solvable.unsolvable`; True when undecided (too
    many sets, or ``deadline`` passed), so a bisection over uncertainties on it errs toward
    the planner's own answer. As in :func:`plan`, no result may hold a state a part at rest
    wanders over unlike poses in (:func:`~feederkit.planning.wandering.split_wandering`)
    unless ``options.lumping`` is ``any``.
    """
    options = options or PlanningOptions()
    if machine.n == 0:
        return False
    budget = Deadline() if deadline is None else deadline
    if options.lumping is not Lumping.ANY:
        # No result may hold a state a part at rest wanders over unlike poses in; the goal
        # relation stays the machine's own (as in plan).
        try:
            machine = twinned(machine, budget.check)[0]
        except Timeout:
            return True
    if machine.deterministic:
        return True  # the ideal push machine: a part is always oriented up to inseparable states
    sorted_machine, _old = by_diameter(machine)
    try:
        insep = goal_relation(sorted_machine, budget)
        problem = Problem(sorted_machine, options.grouping, 0.0, insep)
        every = sorted({b.mask for b in problem.readings.branches(problem.full)})
        roots = sorted(maximal_sets(every))
        bad = unsolvable(problem, roots, budget)
    except Timeout:
        return True
    if bad is None or not bad:
        return True
    if options.lumping is Lumping.NONE:
        return False
    lumping = try_lumping(sorted_machine, options.grouping, budget, rule=options.lumping)
    return lumping.goal is not None or not lumping.decided


def shortest_length(
    machine: PushAlignMachine,
    options: PlanningOptions | None = None,
    *,
    budget: Deadline | None = None,
) -> int | None:
    """The minimum worst-case number of push-align operations of a plan for ``machine``
    on the ideal model (the first alignment counted, as a plan's ``length``), under
    ``options``' grouping, method and margin floor: the length search alone (section 6.1),
    with no tie-breaking and no tree, so it is what :func:`plan` proves first.

    None when ``budget`` (by default the options' limits from now) passes before it is
    proven, or when no plan keeps the margin floor. InputError under uncertainty: there a
    strong plan need not exist, and :func:`plan` decides it.

    >>> from feederkit.machine import ActionRange, MachineState, PushAlignMachine
    >>> from feederkit.sensors import NoSensor
    >>> m = PushAlignMachine(("toy",), (MachineState(0, 0, 1.0, 0.5), MachineState(0, 1, 2.0, 0.5)),
    ...     ((ActionRange(0.0, 180.0, 0), ActionRange(180.0, 360.0, 1)),
    ...      (ActionRange(0.0, 180.0, 0), ActionRange(180.0, 360.0, 0))), NoSensor())
    >>> shortest_length(m)
    2
    """
    options = PlanningOptions() if options is None else options
    if not machine.deterministic:
        raise InputError("the shortest length alone is for the ideal model: plan it instead")
    if machine.n == 0:
        raise InputError("the machine has no states")
    if budget is None:
        budget = Deadline(options.time_limit_s, options.memory_limit_mb)
    min_margin = options.min_margin_deg
    with collector_paused():
        sorted_machine, _old = by_diameter(machine)
        try:
            insep = goal_relation(sorted_machine, budget)
            problem = Problem(sorted_machine, options.grouping, min_margin, insep)
            _check_method(problem, options.method.value)
            every = sorted({b.mask for b in problem.readings.branches(problem.full)})
            roots = sorted(maximal_sets(every)) if min_margin == 0.0 else every
            if min_margin > 0.0 and largest_margin(problem, roots, budget) < min_margin:
                return None
            worst = make_oracle(problem, options.method.value, budget)
            return 1 + longest_root(problem, worst, roots, options.method.value)
        except Timeout:
            return None


def _check_method(problem: Problem, method: str) -> None:
    """InputError when ``method`` cannot plan ``problem``."""
    if method in ("bfs", "backchain") and not problem.sensorless:
        raise InputError(f"method {method!r} is for sensorless machines (readings all alike)")
    if method == "backchain" and not problem.machine.deterministic:
        raise InputError(
            "backchaining needs the ideal model (exact push functions): use rotation error 0, "
            "or the bfs or andor method under uncertainty"
        )


RESULT_S_PER_PAIR = 3e-6
"""Seconds per (node, state) pair of the plan of what :func:`plan` does after its last poll:
the result's statistics (expected operations, a walk of every pair) and the renumbering of
the tree. With no caller's budget its deadline comes this much earlier per pair of the plan
it makes (``Deadline.per_pair_s``), as a command's own budget does for its verification
and file (``plans.timelimit.POST_S_PER_PAIR``). Measured 2.8e-6 s on a
200-part mix's fallback plan at 1 % on the ideal model (994,000 pairs, 2.8 s: it answered
1.3 s past a 15 s limit) and 3.3-4.5e-6 s on 50- and 100-part mixes' plans (43,000-114,000
pairs, whose fixed costs weigh more)."""

FIRST_LIMIT = 8
"""Under uncertainty with readings, the AND/OR search first tries plans of at most this many
operations before deciding whether a strong plan exists at all (:func:`_decide`)."""


def _decide(problem: Problem, roots, deadline: Deadline, machine: PushAlignMachine):
    """Every reachable set's length (``solvable.decide``), raising NoStrongPlan when a root
    has none; None when undecided (too many sets, or out of time), or when a root's pair
    decided it and the sets were not explored."""
    try:
        bad, known = decide(problem.with_margin(0.0), roots, deadline)
    except Timeout:
        return None
    if bad:
        raise no_strong_plan(machine)
    return known


KEPT_SHARE = 0.1
"""The share of the time limit (counted from when it is asked) within which :func:`plan` asks,
before its search, whether nature keeps a pair of some root apart (``solvable.kept_roots``): 0.2 s
on a 50-part mix at 5 % under 1 degree, whose search ran 30 s before giving up; 0.9 s on a
200-part mix at 0.5 %, which has a plan."""

LUMPING_SHARE = 0.15
"""The share of the time limit (counted from when it is asked) within which :func:`plan`
decides which near-symmetric states a plan may list together; past it the undecided goals go
to the search, as past ``LUMPED_ROOT_SETS``. The 50-part mix at 5 % under 1 degree took 9 s of
a 60 s limit on an idle machine and 20 s on a loaded one, undecided both times, and the
search then had too little left to find any plan."""

LUMPED_ROOT_SETS = 5_000
"""The most sets :func:`plan` lets lumping explore to decide the lumped goal's roots; past it
the search to that goal decides (the 50-part mix at 5 % under 1 degree: 200,000 sets in 91 s
left them undecided, where the search found a plan in 33 s)."""


def plan(
    machine: PushAlignMachine,
    options: PlanningOptions | None = None,
    *,
    budget: Deadline | None = None,
) -> PlanResult:
    """A plan orienting every state of ``machine`` (up to inseparable states).

    The plan has the minimum worst-case number of operations (sections 4 and 6) among plans
    whose rotations all keep a margin above ``ANGLE_EPS / 2`` (narrower cells are not
    physical: docs/conventions.md), ties broken as :mod:`feederkit.planning.refine` says;
    ``options`` default to :class:`PlanningOptions` ``()``. ``budget`` is the deadline and
    memory limit to plan under when a caller keeps part of the options' limits for its own
    work after the plan (a command's verification and file); by default the options' limits
    from now, the deadline coming ``RESULT_S_PER_PAIR`` earlier per (node, state) pair of the
    plan made (its statistics after the last poll). Messages name the options' limits.

    Raises InputError for bad options and PlanningError when no plan keeps the minimum
    margin (naming the largest margin that works) or none is found within the time limit.

    >>> from feederkit.machine import ActionRange, MachineState, PushAlignMachine
    >>> from feederkit.sensors import NoSensor
    >>> m = PushAlignMachine(("toy",), (MachineState(0, 0, 1.0, 0.5), MachineState(0, 1, 2.0, 0.5)),
    ...     ((ActionRange(0.0, 180.0, 0), ActionRange(180.0, 360.0, 1)),
    ...      (ActionRange(0.0, 180.0, 0), ActionRange(180.0, 360.0, 0))), NoSensor())
    >>> result = plan(m)
    >>> result.length, result.root.branches[0][1].action.representative
    (2, 90.0)
    """
    options = PlanningOptions() if options is None else options
    if not isinstance(options, PlanningOptions):
        raise InputError(f"the planning options must be PlanningOptions, got {options!r}")
    # The one budget of this call: every stage below polls it (docs/planning.md).
    if budget is None:
        budget = Deadline(
            options.time_limit_s, options.memory_limit_mb, per_pair_s=RESULT_S_PER_PAIR
        )
    if machine.n == 0:
        raise InputError("the machine has no states")
    with collector_paused():
        return _plan_machine(machine, options, budget)


def _plan_machine(
    machine: PushAlignMachine, options: PlanningOptions, budget: Deadline
) -> PlanResult:
    """:func:`plan` with its options checked and its budget made."""
    # A result may not hold a state where a part at rest wanders between unlike poses
    # (feederkit.planning.wandering), unless lumping 'any' lists anything together.
    split, twin_of = machine, None
    if options.lumping is not Lumping.ANY:
        # The goal relation stays the machine's own (planning.wandering.twinned).
        try:
            split, twin_of = twinned(machine, budget.check)
        except Timeout as exc:
            raise OutOfBudget(
                f"no plan found within {out_of_budget(options, exc.reason)}: it ran out while "
                f"finding which of the {machine.n} states are inseparable",
                exc.reason,
            ) from None
    if split is machine:
        twin_of = None
    # Plan with the states numbered by diameter (readings then pick runs of bits).
    sorted_machine, old = by_diameter(split)
    share_bisimilar(split, sorted_machine, old)
    lumping = None
    try:
        root, optimal, length, lower, ties, cut = _plan(sorted_machine, options, budget)
    except NoStrongPlan as exc:
        if options.lumping is Lumping.NONE:
            if twin_of is None:
                raise
            # No pairs are looked at: say which states no result may hold.
            twins = [(twin_of[k], k) for k in range(machine.n, split.n)]  # appended twins
            raise NoStrongPlan(exc.reason, wandering_words(split, twins, False)) from None
        # Near-symmetric states (docs/planning.md): lump the pairs no strong plan resolves
        # that the rule allows (by default: poses that look alike).
        tried = try_lumping(
            sorted_machine,
            options.grouping,
            budget,
            LUMPED_ROOT_SETS,
            rule=options.lumping,
            share=budget.share_from_now(LUMPING_SHARE),
        )
        goals = (tried.goal,) if tried.goal is not None else tried.undecided
        if not goals and tried.cut_by in ("time", "memory"):
            # Unproven: listing near-symmetric states together may still give a plan.
            raise OutOfBudget(
                f"no plan found within {out_of_budget(options, tried.cut_by)}: no strong "
                "plan tells every pair of states apart, and it ran out while deciding which "
                "near-symmetric states a plan may list together",
                tried.cut_by,
            ) from None
        hint = unlike_words(sorted_machine, tried.unlike)
        if not goals:
            raise NoStrongPlan(exc.reason, hint) from None
        for k, lumping in enumerate(goals):
            try:
                root, optimal, length, lower, ties, cut = _plan(
                    sorted_machine,
                    options,
                    budget,
                    lumping.insep,
                    UNDECIDED_CHECK_SHARE if tried.goal is None else None,
                )
                break
            except NoStrongPlan as again:  # its roots were undecided: the search decided
                if k == len(goals) - 1:
                    raise NoStrongPlan(again.reason, hint) from None
    share_bisimilar(split, sorted_machine, old)
    if twin_of is not None:
        old = [twin_of[i] for i in old]  # each twin is its wandering state again
    if sorted_machine is not machine:
        root = remap_tree(root, old)
    result = _result(
        machine, root, optimal, length, lower, options.objective.value, options.grouping.value
    )
    result = replace(result, tie_breaks=ties, ties_cut_by=cut)
    if lumping is None:
        return result
    return replace(result, lumped_pairs=lumping.renumbered(old).in_leaves(root))


def goal_relation(machine: PushAlignMachine, budget: Deadline) -> tuple[int, ...]:
    """The machine's goal relation (``SearchSpace.inseparable``), its fixpoint polled.

    The inseparability fixpoint is the first long stage of a plan, so it runs under the
    plan's budget (:func:`~feederkit.machine.inseparable.inseparable_masks` polls it); its
    result fills the search space's cached table, so nothing computes it twice.
    """
    space = search_space(machine)
    if "inseparable" not in vars(space):
        slot = "bisimilar" if hasattr(type(space), "bisimilar") else "inseparable"
        if slot not in vars(space):
            vars(space)[slot] = inseparable_masks(machine, budget.check)
    return space.inseparable


def _plan(
    machine: PushAlignMachine,
    options: PlanningOptions,
    budget: Deadline,
    goal: tuple[int, ...] | None = None,
    check_share: float | None = None,
):
    """``plan`` on a machine whose states are numbered by diameter, under ``budget``; ``goal``
    replaces the goal relation (the lumped one, :func:`~feederkit.planning.lumping.lumped_goal`);
    ``check_share``: when the exact search must be on course (:func:`_exact_budget`;
    None: ``EXACT_CHECK_SHARE``).

    Returns the plan tree, whether it is proven optimal, its proven length (None when the
    tree's own length is the answer), a proven lower bound, which tie-breaks are exact
    (``TIES_EXACT``, ``TIES_MARGIN`` or ``TIES_NONE``) and, when a tie-breaking stage was
    cut short, why (a :class:`~feederkit.planning.budget.Timeout`'s reason: ``"work"``
    for the tie-breaking budget, ``"time"`` or ``"memory"`` for the run's limits).
    """
    objective = options.objective.value
    min_margin = options.min_margin_deg
    grouping = options.grouping
    method = options.method.value
    # The goal tells every pair apart, yet lumping may follow (when no strong plan reaches
    # it): a bound proven here need not hold for the plan the lumped goal gets.
    apart = goal is None and not machine.deterministic and options.lumping is not Lumping.NONE
    try:
        insep = goal_relation(machine, budget) if goal is None else goal
    except Timeout as exc:
        raise OutOfBudget(
            f"no plan found within {out_of_budget(options, exc.reason)}: it ran out while "
            f"finding which of the {machine.n} states are inseparable",
            exc.reason,
        ) from None
    problem = Problem(machine, grouping, min_margin, insep)
    if problem.sensorless and objective == "expected":
        # One path for every start: the expected number of operations is the length, so
        # the plans of minimum length are exactly those of minimum expected length.
        objective = "worst"
    elif objective in ("expected", "time"):
        problem = Problem(machine, grouping, min_margin, problem.insep, distinct_maps=True)
    _check_method(problem, method)
    root_branches = problem.readings.branches(problem.full)
    # Without a margin floor a reading set inside another is oriented by its rotations in no
    # more operations, so the length depends on the maximal ones only. Margins are not
    # monotone that way (Choices.exact_actions): the floor below looks at every branch.
    every = sorted({b.mask for b in root_branches})
    roots = sorted(maximal_sets(every)) if min_margin == 0.0 else every
    start_mass = [s.weight for s in machine.states]
    exact_deadline = _exact_budget(budget, options.fallback, check_share)
    limit = None
    known: dict[int, float] | None = None
    kept_known = False  # whether kept_roots found that nature keeps no pair of a root apart
    if not machine.deterministic:
        # Strong plans need not exist. Sensorless, decide first: one pass over the reachable
        # sets gives every set's length (a shortest path, which iterative deepening finds
        # slowly), and the search reads them. With readings, plans are short: search to
        # FIRST_LIMIT operations, and decide only when that fails (below).
        if problem.sensorless:
            known = _decide(problem, roots, exact_deadline, machine)
            limit = None if known is not None else length_cap(machine)
        else:
            limit = FIRST_LIMIT
            # A pair nature keeps apart in a root settles it before any search (cheap,
            # solvable.kept_roots); the search would run until it gave up. Within
            # KEPT_SHARE of the limit from now, so that solvable machines lose little (from
            # the plan's start, the goal relation of a 100-part mix at 5 % under 1 degree
            # took the whole share, and the fallback asked again 30 s later).
            try:
                if kept_roots(problem.with_margin(0.0), roots, budget.share_from_now(KEPT_SHARE)):
                    raise no_strong_plan(machine)
                kept_known = True  # none: the fallback need not ask again
            except Timeout:
                pass  # the search and its fallback decide
    worst = make_oracle(problem, method, exact_deadline)
    if min_margin > 0.0:
        try:
            _check_margin(problem, roots, min_margin, exact_deadline)
        except Timeout as exc:
            return fallback(
                problem, worst, roots, root_branches, budget, options, exc.reason, apart, kept_known
            )
    if known is not None and min_margin == 0.0 and method in ("auto", "andor"):
        worst.exact.update({m: int(v) for m, v in known.items() if v != math.inf})
    checkpoint = exact_deadline if isinstance(exact_deadline, Checkpoint) else None
    if checkpoint is not None:
        # Judged while the roots' lengths are searched (the stages before go on).
        checkpoint.on_course = lambda: _on_course(problem, worst, roots)
    stopped = None
    try:
        try:
            longest = longest_root(problem, worst, roots, method, limit)
        except ValueError:
            if machine.deterministic or known is not None or method in ("bfs", "bottom-up"):
                raise
            if checkpoint is not None:
                checkpoint.go_on()  # deciding whether a strong plan exists: the whole share
            known = _decide(problem, roots, exact_deadline, machine)
            if known is not None and min_margin == 0.0:
                worst.exact.update({m: int(v) for m, v in known.items() if v != math.inf})
            longest = longest_root(problem, worst, roots, method, length_cap(machine))
    except Timeout as exc:
        stopped = exc.reason
    except ValueError:
        exact = method in ("bfs", "bottom-up") or known is not None
        raise no_strong_plan(machine, undecided=not exact) from None
    finally:
        if checkpoint is not None:
            # The question is asked while the lengths are searched only; its closure holds
            # the search, which holds the checkpoint: a cycle only the collector would free.
            checkpoint.on_course = None
    if stopped is not None:
        return fallback(
            problem, worst, roots, root_branches, budget, options, stopped, apart, kept_known
        )
    if checkpoint is not None:
        checkpoint.go_on()  # every root's length is proven: the rest of the share is ours
    length = 1 + longest
    budget_ops = length - 1
    if objective == "worst" and isinstance(worst, BackchainWorst) and not problem.sensorless:
        # The readings carry nothing (methods.readings_carry_nothing): the backchaining plan
        # of the whole set is a shortest plan (its rotations the widest that shorten the
        # set), and any plan that follows the readings grows a tree of every reading set.
        try:  # under a copy: a chain too large to verify leaves its commits behind
            chain = sensorless_plan(problem, root_branches, budget.ending(None), by_image=True)
        except Timeout as exc:
            return fallback(
                problem, worst, roots, root_branches, budget, options, exc.reason, apart, kept_known
            )
        if chain is not None and tree_length(chain) == length:
            return chain, True, length, length, TIES_CHAIN, None
    if objective == "worst" and isinstance(worst, QuietWorst):
        # The same with several parts: the shortest paths the length search found, one chain,
        # then the largest margin among such chains under the tie-breaking budget.
        try:
            chain = chain_plan(problem, worst, roots, root_branches, budget.ending(None))
        except Timeout as exc:
            return fallback(
                problem, worst, roots, root_branches, budget, options, exc.reason, apart, kept_known
            )
        if tree_length(chain) == length:
            allowance = TIE_SHARE * exact_deadline.polls + TIE_GRACE_POLLS
            floor = tree_min_margin(chain)
            wider = widest_chain(
                worst, roots, longest, floor, WorkBudget(exact_deadline, allowance)
            )
            cut = wider.cut_by
            if wider.search is not None and wider.margin > floor:
                try:
                    chain = chain_plan(
                        wider.search.p, wider.search, roots, root_branches, budget.ending(None)
                    )
                except Timeout as exc:  # the first chain stays
                    cut = exc.reason
            # Cut short, the margin is the best found, not proven the largest.
            return chain, True, length, length, TIES_CHAIN if cut is None else TIES_NONE, cut
    children = _root_children(problem, root_branches, start_mass)
    ties_deadline = exact_deadline
    if objective == "worst":
        # Tie-breaking must not dominate: a bounded multiple of the length proof's work.
        allowance = TIE_SHARE * exact_deadline.polls + TIE_GRACE_POLLS
        ties_deadline = WorkBudget(exact_deadline, allowance)
    worst.deadline = ties_deadline
    refiner = Refiner(problem, worst, ties_deadline, costs=options.costs, timed=objective == "time")
    staged = False
    try:
        tie, horizon = stage(objective, refiner, every, budget_ops)
        staged = True
        then = None
        if objective == "worst":
            # The last tie-break gets its own share; out of it, the root branches built so
            # far keep their subtrees and the rest follow the margin probes (_build).
            cap = EXPECTED_SHARE * exact_deadline.polls + TIE_GRACE_POLLS
            left = ties_deadline.allowance - ties_deadline.polls
            worst.deadline = refiner.deadline = WorkBudget(exact_deadline, min(left, cap))

            def then() -> Deadline:
                return _first_tree_budget(budget)

        root, cut = _build(refiner, children, roots, horizon, tie, then)
        ties = TIES_EXACT if cut is None else TIES_MARGIN
    except Timeout as exc:
        # The lengths are proven; the tie-breaking stages ran out of time: a tree that
        # keeps the proven length and the margin decided or found so far, following the
        # plans the margin probes found (Refiner.follow), while time remains.
        worst.deadline = refiner.deadline = _first_tree_budget(budget)
        ties = TIES_MARGIN if staged and objective == "worst" else TIES_NONE
        cut = exc.reason
        if cut != "work" and not options.fallback:
            raise NoFallback(options, cut) from None  # a limit, not the ties' own work: cut short
        if not staged:
            refiner.floor = tie_floor(refiner.floor_found) if objective == "worst" else -math.inf
        try:
            root, _cut = _build(refiner, children, roots, budget_ops, "first")
        except Timeout as exc:
            return fallback(
                problem, worst, roots, root_branches, budget, options, exc.reason, apart, kept_known
            )
        complete = objective == "worst"
    else:
        complete = True
    shortest = objective in ("worst", "worst-time")
    return root, complete, length if shortest else None, length, ties, cut


def _first_tree_budget(budget: Deadline) -> Deadline:
    """The budget of the tree of a proven length once the tie-breaks ran out: until
    ``FIRST_TREE_SHARE`` of ``budget``, the caller's reserve of its verification free (a
    plan whose certificate is cut beats none; a short limit keeps no reserve, and its end
    holds)."""
    return budget.until(FIRST_TREE_SHARE).with_grace(budget.reserve_s)


def _exact_budget(
    budget: Deadline, fallback: bool = True, check_share: float | None = None
) -> Deadline:
    """The exact search's budget: ``1 - FALLBACK_SHARE`` of the time limit and
    ``EXACT_MEMORY_SHARE`` of the memory; with a time limit a
    :class:`~feederkit.planning.budget.Checkpoint` at ``check_share`` (by default
    ``EXACT_CHECK_SHARE``) of the time from now to that share's end (its ``on_course`` set
    when the roots' lengths are searched).
    Without a ``fallback`` to hand over to: all of ``budget``'s limits, no checkpoint."""
    if not fallback:
        return budget.until(1.0)
    share = budget.until(1.0 - FALLBACK_SHARE, EXACT_MEMORY_SHARE)
    if share.end is None:
        return share
    now = time.perf_counter()
    if check_share is None:
        check_share = EXACT_CHECK_SHARE
    first = now + check_share * max(0.0, share.end - now)
    return Checkpoint(share, first, share.end)


def _on_course(problem: Problem, worst: WorstCase, roots: list[int]) -> bool:
    """Whether the exact search is on course to finish in its share: at least
    ``EXACT_CHECK_SHARE`` of the roots have a proven length or fit within the longest so far
    (asked when that share of its time has passed; it proves them one after the other,
    :func:`~feederkit.planning.methods.longest_root`)."""
    exact = getattr(worst, "exact", {})
    fits = getattr(worst, "ub", {})
    done = sum(1 for r in roots if problem.is_goal(r) or r in exact or r in fits)
    return done >= EXACT_CHECK_SHARE * len(roots)


def _build(
    refiner: Refiner,
    children,
    roots: list[int],
    horizon: int,
    tie: str,
    then: Callable[[], Deadline] | None = None,
) -> tuple[Step, str | None]:
    """The plan: the first alignment, then a subtree per root branch; and None when every
    subtree was chosen by ``tie``, else why it stopped (the Timeout's reason).

    ``then``, for the ``worst`` objective's expected-operations stage: when that stage runs
    out of its budget, the root branches built so far keep their subtrees, and the others
    follow the margin probes' plans (``"first"``) under the budget ``then()`` gives, which
    the kept subtrees' (node, state) pairs are committed to. Without ``then``, Timeout.
    A root branch with no plan of its own (neither a probe's nor the length proof's, which
    proves the maximal ones, ``roots``) follows the plan of a maximal one holding it.
    """

    def chooser(mask, masses, k):
        return refiner.choose_worst(mask, masses, k, tie)

    refiner.new_tree()
    shared: dict = {}
    subs: list = []
    cut = None
    for b, _pb, ms in children:
        if tie != "first":
            try:
                subs.append((b, refiner.build(b.mask, ms, horizon, chooser)))
                continue
            except Timeout as exc:
                if then is None:
                    raise
                deadline = then()
                deadline.commit(sum(branch_pairs(s.branches) for s in refiner.nodes()), False)
                refiner.w.deadline = refiner.deadline = deadline
                tie, cut = "first", exc.reason
        # No choice left to make: follow the plans the margin probes found, with no new
        # search where they recorded one (Refiner.follow), else the first allowed action.
        witness = None
        if not refiner.planned(b.mask, horizon):
            witness = next((r for r in roots if b.mask & ~r == 0), None)
        subs.append((b, refiner.follow(b.mask, horizon, witness, shared)))
    return root_step(subs, refiner.deadline), cut


def _check_margin(
    problem: Problem, roots: list[int], min_margin: float, deadline: Deadline
) -> None:
    """Raise PlanningError when no plan keeps ``min_margin``, naming the largest that does
    (Timeout when ``deadline`` passes first)."""
    floored = largest_margin(problem, roots, deadline)
    if floored >= min_margin:
        return
    best = largest_margin(problem.with_margin(0.0), roots, deadline)
    if best == -math.inf:
        raise no_strong_plan(problem.machine)
    raise PlanningError(
        f"no plan keeps a margin of {min_margin:g} deg; the largest margin any plan keeps is "
        f"{best:.6g} deg"
    )


def _root_children(problem: Problem, root_branches, start_mass):
    """The root's branches with their probabilities and normalised masses."""
    return child_masses(problem, problem.full, tuple(start_mass), None, tuple(root_branches))


def _result(
    machine, root: Step, optimal: bool, length: int | None, lower: int, objective, grouping
) -> PlanResult:
    """The result with its statistics; ``length`` (when given) must be the tree's own.

    A plan that meets its proven lower bound is optimal for the ``worst`` objective however
    it was found (a time-limited search may stop with one)."""
    real = tree_length(root)
    if length is not None and real != length:
        raise AssertionError(f"plan length {real} differs from the proven optimum {length}")
    if objective == "worst" and real <= lower:
        optimal = True
    return PlanResult(
        machine=machine,
        root=root,
        length=real,
        expected_length=expected_operations(machine, root),
        min_margin=tree_min_margin(root),
        optimal=optimal,
        lower_bound=min(lower, real),
        objective=objective,
        grouping=grouping,
    )
