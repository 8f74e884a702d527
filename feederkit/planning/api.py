"""The planners' public entry point: ``plan(machine, options) -> PlanResult``.

The root is the first alignment from an unknown orientation (``Step(action=None)``); its
branches are the readings of the full set of states. Each branch is then oriented by a
minimum worst-case plan (sections 4 and 6), ties broken by the order of docs/planning.md
(see :mod:`feederkit.planning.refine`). ``length`` counts the first alignment (design.md).

References
----------
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), sections 4 (sensorless plans), 6
(AND/OR search 6.1, bottom-up 6.4) and 8.5 (mixes).
Goldberg, K. Y. (1993). Orienting polygonal parts without sensors. Algorithmica 10
(backchaining, the sensorless fallback here).
"""

from __future__ import annotations

import math

from feederkit.errors import InputError, PlanningError
from feederkit.machine import OverlapRange, PushAlignMachine, search_space
from feederkit.planning.andor import Deadline, Timeout, WorstCase
from feederkit.planning.margins import largest_margin
from feederkit.planning.methods import make_oracle, root_lengths
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.refine import EXPECTED_HORIZON, Refiner, child_masses
from feederkit.planning.reindex import by_diameter, remap_tree
from feederkit.planning.sensorless import Backchain, push_circle
from feederkit.planning.solvable import solve, unsolvable
from feederkit.planning.stats import expected_operations, tree_length, tree_min_margin
from feederkit.planning.tree import Leaf, PlanResult, Step

FALLBACK_SHARE = 0.3
"""With a time limit, the share of it kept for finding some plan when the exact search fails."""


class NoStrongPlan(PlanningError):
    """No strong plan exists under the machine's declared uncertainty (design.md)."""


def _no_strong_plan(machine: PushAlignMachine, undecided: bool = False) -> NoStrongPlan:
    u = machine.uncertainty
    what = (
        f"rotation error {u.rotation_error_deg:g} deg, shape tolerance "
        f"{u.shape_tolerance_mm:g} mm, COM tolerance {u.com_tolerance_mm:g} mm"
    )
    if undecided:
        return NoStrongPlan(f"no strong plan found within {_limit(machine)} operations ({what})")
    return NoStrongPlan(
        f"no strong plan exists under the declared uncertainty ({what}): for every action "
        "some outcome leaves states that must be told apart reading alike"
    )


def strong_plan_exists(machine: PushAlignMachine, options: PlanningOptions | None = None) -> bool:
    """Whether some strong plan orients every state of ``machine`` (no margin floor).

    Decided by :func:`~feederkit.planning.solvable.unsolvable`; True when undecided (too
    many sets), so a bisection over uncertainties on it errs toward the planner's own answer.
    """
    options = options or PlanningOptions()
    if machine.n == 0:
        return False
    if machine.deterministic:
        return True  # the ideal push machine: a part is always oriented up to inseparable states
    sorted_machine, _old = by_diameter(machine)
    problem = Problem(sorted_machine, options.grouping, 0.0)
    every = sorted({b.mask for b in problem.readings.branches(problem.full)})
    bad = unsolvable(problem, sorted(maximal_sets(every)))
    return bad is None or not bad


FIRST_LIMIT = 8
"""Under uncertainty with readings, the AND/OR search first tries plans of at most this many
operations before deciding whether a strong plan exists at all (:func:`_decide`)."""


def _decide(problem: Problem, roots, deadline: Deadline, machine: PushAlignMachine):
    """Every reachable set's length (``solve``), raising NoStrongPlan when a root has none;
    None when undecided (too many sets, or out of time)."""
    try:
        known = solve(problem.with_margin(0.0), roots, deadline)
    except Timeout:
        return None
    if known is not None and any(known[r] == math.inf for r in roots):
        raise _no_strong_plan(machine)
    return known


def _limit(machine: PushAlignMachine) -> int:
    """A cap on a strong plan's length when solvability is undecided (sets too many)."""
    return 4 * machine.n + 4


def plan(machine: PushAlignMachine, options: PlanningOptions | None = None) -> PlanResult:
    """A plan orienting every state of ``machine`` (up to inseparable states).

    The plan has the minimum worst-case number of operations (sections 4 and 6), ties
    broken as :mod:`feederkit.planning.refine` says; ``options`` default to
    :class:`PlanningOptions` ``()``.

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
    if machine.n == 0:
        raise InputError("the machine has no states")
    # Plan with the states numbered by diameter (readings then pick runs of bits).
    sorted_machine, old = by_diameter(machine)
    root, optimal, length, lower = _plan(sorted_machine, options)
    if sorted_machine is not machine:
        root = remap_tree(root, old)
    return _result(
        machine, root, optimal, length, lower, options.objective.value, options.grouping.value
    )


def _plan(machine: PushAlignMachine, options: PlanningOptions):
    """``plan`` on a machine whose states are numbered by diameter.

    Returns the plan tree, whether it is proven optimal, its proven length (None when the
    tree's own length is the answer) and a proven lower bound.
    """
    objective = options.objective.value
    min_margin = options.min_margin_deg
    grouping = options.grouping
    time_limit = options.time_limit_s
    method = options.method.value
    problem = Problem(machine, grouping, min_margin)
    if problem.sensorless:
        # One path for every start: the expected number of operations is the length, so
        # the plans of minimum length are exactly those of minimum expected length.
        objective = "worst"
    elif objective == "expected":
        problem = Problem(machine, grouping, min_margin, problem.insep, distinct_maps=True)
    if method in ("bfs", "backchain") and not problem.sensorless:
        raise InputError(f"method {method!r} is for sensorless machines (readings all alike)")
    if method == "backchain" and not machine.deterministic:
        raise InputError(
            "backchaining needs the ideal model (exact push functions): use rotation error 0, "
            "or the bfs or andor method under uncertainty"
        )
    root_branches = problem.readings.branches(problem.full)
    # Without a margin floor a reading set inside another is oriented by its rotations in no
    # more operations, so the length depends on the maximal ones only. Margins are not
    # monotone that way (Choices.exact_actions): the floor below looks at every branch.
    every = sorted({b.mask for b in root_branches})
    roots = sorted(maximal_sets(every)) if min_margin == 0.0 else every
    start_mass = [s.weight for s in machine.states]
    exact_deadline = Deadline(None if time_limit is None else time_limit * (1 - FALLBACK_SHARE))
    limit = None
    known: dict[int, float] | None = None
    if not machine.deterministic:
        # Strong plans need not exist. Sensorless, decide first: one pass over the reachable
        # sets gives every set's length (a shortest path, which iterative deepening finds
        # slowly), and the search reads them. With readings, plans are short: search to
        # FIRST_LIMIT operations, and decide only when that fails (below).
        if problem.sensorless:
            known = _decide(problem, roots, exact_deadline, machine)
            limit = None if known is not None else _limit(machine)
        else:
            limit = FIRST_LIMIT
    if min_margin > 0.0:
        _check_margin(problem, roots, min_margin)
    worst = make_oracle(problem, method, exact_deadline)
    if known is not None and min_margin == 0.0 and method in ("auto", "andor"):
        worst.exact.update({m: int(v) for m, v in known.items() if v != math.inf})
    try:
        try:
            lengths = root_lengths(problem, worst, roots, method, limit)
        except ValueError:
            if machine.deterministic or known is not None or method in ("bfs", "bottom-up"):
                raise
            known = _decide(problem, roots, exact_deadline, machine)
            if known is not None and min_margin == 0.0:
                worst.exact.update({m: int(v) for m, v in known.items() if v != math.inf})
            lengths = root_lengths(problem, worst, roots, method, _limit(machine))
    except Timeout:
        return _fallback(problem, worst, roots, root_branches, time_limit)
    except ValueError:
        exact = method in ("bfs", "bottom-up") or known is not None
        raise _no_strong_plan(machine, undecided=not exact) from None
    length = 1 + max(lengths.values(), default=0)
    budget = length - 1
    children = _root_children(problem, root_branches, start_mass)
    refiner = Refiner(problem, worst, exact_deadline)
    try:
        if objective == "worst":
            # The smallest margin over the root branches; each only has to beat the least so far.
            floor = math.inf
            for r in sorted(every, key=lambda r: -r.bit_count()):
                floor = refiner.margin(r, budget, floor)
            refiner.floor = floor
            tie = "rotation" if problem.sensorless else "expected"
            horizon = budget
        else:
            tie = "expected"
            horizon = EXPECTED_HORIZON * budget
        root = _build(refiner, children, horizon, tie)
        complete = True
    except Timeout:
        # The lengths are proven; the tie-breaking stages ran out of time.
        worst.deadline = refiner.deadline = Deadline(None)
        refiner.floor = -math.inf
        root = _build(refiner, children, budget, "first")
        complete = objective == "worst"
    return root, complete, length if objective == "worst" else None, length


def _build(refiner: Refiner, children, horizon: int, tie: str) -> Step:
    """The plan: the first alignment, then a subtree per root branch."""

    def chooser(mask, masses, k):
        return refiner.choose_worst(mask, masses, k, tie)

    subs = [(b, refiner.build(b.mask, ms, horizon, chooser)) for b, _pb, ms in children]
    return Step(None, tuple(subs))


def _check_margin(problem: Problem, roots: list[int], min_margin: float) -> None:
    """Raise PlanningError when no plan keeps ``min_margin``, naming the largest that does."""
    floored = largest_margin(problem, roots)
    if floored >= min_margin:
        return
    best = largest_margin(problem.with_margin(0.0), roots)
    raise PlanningError(
        f"no plan keeps a margin of {min_margin:g} deg; the largest margin any plan keeps is "
        f"{best:.6g} deg"
    )


def _root_children(problem: Problem, root_branches, start_mass):
    """The root's branches with their probabilities and normalised masses."""
    return child_masses(problem, problem.full, tuple(start_mass), None, tuple(root_branches))


def _fallback(problem, worst, roots, root_branches, time_limit):
    """Some plan when the exact search ran out of time, with the lower bound it proved.

    A depth-first search with a generous budget (the greedy action order of
    ``Choices.lazy_actions``) finds a plan; the tree follows the actions that proved it. A
    reading set the search never met lies inside one it did (its "witness"), and without a
    margin floor it follows the witness's rotations.
    """
    lower = 1 + max((_proven(worst, r) for r in roots), default=0)
    blind = _sensorless_plan(problem, root_branches)
    anytime = WorstCase(problem, Deadline(time_limit * FALLBACK_SHARE))
    cap = 2 * problem.n + 1
    if blind is not None:
        cap = tree_length(blind) - 2  # look only for something shorter
    try:
        for r in roots:
            if not anytime.within(r, cap):
                raise Timeout
    except Timeout:
        if blind is not None:
            return blind, False, None, lower
        raise PlanningError(
            f"no plan found within the time limit of {time_limit:g} s "
            f"(a plan needs at least {lower} operations)"
        ) from None

    choice = anytime.choice

    def witness_of(mask: int, supersets) -> int:
        if problem.is_goal(mask) or mask in choice:
            return mask
        return next(c for c in supersets if mask & c == mask)

    made: dict[tuple[int, int], Step | Leaf] = {}  # equal cases share their subtree

    def build(mask: int, witness: int) -> Step | Leaf:
        if (mask, witness) not in made:
            made[(mask, witness)] = make(mask, witness)
        return made[(mask, witness)]

    def make(mask: int, witness: int) -> Step | Leaf:
        if problem.is_goal(mask):
            return Leaf(mask)
        k, act = choice[witness]
        if witness != mask:
            # Follow the witness's rotation: the set's range holding it (any rotation in it
            # sends the set inside the witness's image).
            r = act.action.representative
            lo, hi, img = next(
                c
                for c in search_space(problem.machine).overlap_cells(mask)
                if c[0] < r < c[1] or c[0] < r + 360.0 < c[1]
            )
            action = OverlapRange(lo, hi, img)
        else:
            action = act.action
        subs = []
        for b in problem.readings.image_branches(action.image):
            subs.append((b, build(b.mask, witness_of(b.mask, act.children))))
        return Step(action, tuple(subs))

    root = Step(None, tuple((b, build(b.mask, witness_of(b.mask, roots))) for b in root_branches))
    return root, False, None, lower


def _sensorless_plan(problem: Problem, root_branches) -> Step | None:
    """A plan that takes the readings but chooses rotations by backchaining, or None.

    For one part's push machine (no margin floor), Goldberg's table says how many
    operations collapse any set with no sensor; each step takes a rotation that lowers
    that number, and a reading only leaves a subset, which needs no more. Instant, and
    never longer than the sensorless plan.
    """
    if problem.min_margin > 0.0:
        return None
    circle = push_circle(problem.machine, problem.insep)
    if circle is None:
        return None
    chain = Backchain(circle)
    made: dict[int, Step | Leaf] = {}  # equal sets share their subtree

    def build(mask: int) -> Step | Leaf:
        if mask in made:
            return made[mask]
        if problem.is_goal(mask):
            node: Step | Leaf = Leaf(mask)
        else:
            k = chain.length(mask)
            lo, hi, img = next(
                c for c in problem.choices.cells(mask, False) if chain.length(c[2]) < k
            )
            subs = tuple((b, build(b.mask)) for b in problem.readings.image_branches(img))
            node = Step(OverlapRange(lo, hi, img), subs)
        made[mask] = node
        return node

    return Step(None, tuple((b, build(b.mask)) for b in root_branches))


def _proven(worst: WorstCase, mask: int) -> int:
    if worst.p.is_goal(mask):
        return 0
    return worst.exact.get(mask, worst.lb.get(mask, 1))


def _result(
    machine, root: Step, optimal: bool, length: int | None, lower: int, objective, grouping
) -> PlanResult:
    """The result with its statistics; ``length`` (when given) must be the tree's own."""
    real = tree_length(root)
    if length is not None and real != length:
        raise AssertionError(f"plan length {real} differs from the proven optimum {length}")
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
