"""The planners' public entry point: ``plan(machine, ...) -> PlanResult``.

The root is the first alignment from an unknown orientation (``Step(action=None)``); its
branches are the readings of the full set of states. Each branch is then oriented by a
minimum worst-case plan (sections 4 and 6), ties broken by issue 3's order (see
:mod:`feederkit.planning.refine`). ``length`` counts the first alignment (design.md).
"""

from __future__ import annotations

import math
from typing import Literal

from feederkit.errors import InputError, PlanningError
from feederkit.machine import PushAlignMachine, SetAction, overlap_cells
from feederkit.planning.andor import Deadline, Timeout, WorstCase
from feederkit.planning.margins import largest_margin
from feederkit.planning.methods import make_oracle, root_lengths
from feederkit.planning.problem import Problem, maximal_sets
from feederkit.planning.refine import EXPECTED_HORIZON, Refiner, child_masses
from feederkit.planning.reindex import by_diameter, remap_tree
from feederkit.planning.sensorless import Backchain, push_circle
from feederkit.planning.stats import expected_operations, tree_length, tree_min_margin
from feederkit.planning.tree import Leaf, PlanResult, Step

Objective = Literal["worst", "expected"]
Method = Literal["auto", "andor", "bottom-up", "bfs", "backchain"]
METHODS = ("auto", "andor", "bottom-up", "bfs", "backchain")

FALLBACK_SHARE = 0.3
"""With a time limit, the share of it kept for finding some plan when the exact search fails."""


def plan(
    machine: PushAlignMachine,
    *,
    objective: Objective = "worst",
    min_margin: float = 0.0,
    grouping: str = "exact",
    time_limit: float | None = None,
    method: Method = "auto",
) -> PlanResult:
    """A plan orienting every state of ``machine`` (up to inseparable states), by issue 3's rules.

    Raises InputError for bad arguments and PlanningError when no plan keeps ``min_margin``
    (naming the largest margin that works) or none is found within ``time_limit``.
    """
    _check_args(machine, objective, min_margin, grouping, time_limit, method)
    # Plan with the states numbered by diameter (readings then pick runs of bits).
    sorted_machine, old = by_diameter(machine)
    root, optimal, length, lower = _plan(
        sorted_machine, objective, min_margin, grouping, time_limit, method
    )
    if sorted_machine is not machine:
        root = remap_tree(root, old)
    return _result(machine, root, optimal, length, lower, objective, grouping)


def _plan(machine, objective, min_margin, grouping, time_limit, method):
    """``plan`` on a machine whose states are numbered by diameter.

    Returns the plan tree, whether it is proven optimal, its proven length (None when the
    tree's own length is the answer) and a proven lower bound.
    """
    problem = Problem(machine, grouping, min_margin)  # type: ignore[arg-type]
    if problem.sensorless:
        # One path for every start: the expected number of operations is the length, so
        # the plans of minimum length are exactly those of minimum expected length.
        objective = "worst"
    elif objective == "expected":
        problem = Problem(machine, grouping, min_margin, problem.insep, distinct_maps=True)  # type: ignore[arg-type]
    if method in ("bfs", "backchain") and not problem.sensorless:
        raise InputError(f"method {method!r} is for sensorless machines (readings all alike)")
    root_branches = problem.branches(problem.full)
    # Without a margin floor a reading set inside another is oriented by its rotations in no
    # more operations, so the length depends on the maximal ones only. Margins are not
    # monotone that way (Problem.exact_actions): the floor below looks at every branch.
    every = sorted({b.mask for b in root_branches})
    roots = sorted(maximal_sets(every)) if min_margin == 0.0 else every
    start_mass = [s.weight for s in machine.states]
    if min_margin > 0.0:
        _check_margin(problem, roots, min_margin)

    exact_deadline = Deadline(None if time_limit is None else time_limit * (1 - FALLBACK_SHARE))
    worst = make_oracle(problem, method, exact_deadline)
    try:
        lengths = root_lengths(problem, worst, roots, method)
    except Timeout:
        return _fallback(problem, worst, roots, root_branches, time_limit)
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


def _check_args(machine, objective, min_margin, grouping, time_limit, method) -> None:
    if machine.n == 0:
        raise InputError("the machine has no states")
    if objective not in ("worst", "expected"):
        raise InputError(f"objective must be 'worst' or 'expected', got {objective!r}")
    if grouping not in ("exact", "components"):
        raise InputError(f"grouping must be 'exact' or 'components', got {grouping!r}")
    if method not in METHODS:
        raise InputError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if not math.isfinite(min_margin) or min_margin < 0.0:
        raise InputError(f"min_margin must be a non-negative number of degrees, got {min_margin}")
    if time_limit is not None and (not math.isfinite(time_limit) or time_limit <= 0.0):
        raise InputError(f"time_limit must be a positive number of seconds, got {time_limit}")


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
    ``Problem.lazy_actions``) finds a plan; the tree follows the actions that proved it. A
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
                for c in overlap_cells(problem.machine, mask)
                if c[0] < r < c[1] or c[0] < r + 360.0 < c[1]
            )
            action = SetAction(lo, hi, img)
        else:
            action = act.action
        subs = []
        for b in problem.image_branches(action.image):
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
            lo, hi, img = next(c for c in problem.cells(mask, False) if chain.length(c[2]) < k)
            subs = tuple((b, build(b.mask)) for b in problem.image_branches(img))
            node = Step(SetAction(lo, hi, img), subs)
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
