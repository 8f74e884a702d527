"""Statistics of a plan tree: worst-case length, expected length, smallest margin, and the
expected and worst seconds per part under action costs (docs/cell.md).

The expected number of operations uses the distribution of :mod:`feederkit.planning.readings`
(uniform initial orientation, uniform reading error), the same one the planners minimise.
Subtrees may be shared (a plan is then a DAG in memory); every statistic is memoised per
node, so shared subtrees cost once.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

from feederkit.machine import PushAlignMachine, ReadingBranch, members
from feederkit.planning.options import ActionCosts
from feederkit.planning.readings import reading_probability
from feederkit.planning.tree import Leaf, PlanTree, Step, branch_pairs


def tree_length(node: PlanTree, _memo: dict[int, int] | None = None) -> int:
    """Worst-case number of operations of a subtree (each Step is one operation)."""
    if isinstance(node, Leaf):
        return 0
    memo = {} if _memo is None else _memo
    hit = memo.get(id(node))
    if hit is None:
        hit = 1 + max((tree_length(sub, memo) for _, sub in node.branches), default=0)
        memo[id(node)] = hit
    return hit


def node_states(root: PlanTree) -> int:
    """How many (node, state) pairs a plan has: over its distinct steps, the states of each
    branch (those that can reach the node below it). Verifying a plan walks each pair once,
    so this measures the work after the planner (``Deadline.commit``); without recursion.

    >>> from feederkit.machine import ReadingBranch
    >>> leaf = Leaf(0b11)
    >>> node_states(Step(None, ((ReadingBranch(1.0, 2.0, 0b11), leaf),)))
    2
    """
    seen: set[int] = set()
    stack: list[PlanTree] = [root]
    total = 0
    while stack:
        node = stack.pop()
        if isinstance(node, Leaf) or id(node) in seen:
            continue
        seen.add(id(node))
        total += branch_pairs(node.branches)
        stack.extend(sub for _b, sub in node.branches)
    return total


def tree_min_margin(node: PlanTree, _memo: dict[int, float] | None = None) -> float:
    """Smallest margin of the subtree's actions (inf when it has none)."""
    if isinstance(node, Leaf):
        return math.inf
    memo = {} if _memo is None else _memo
    hit = memo.get(id(node))
    if hit is None:
        here = math.inf if node.action is None else node.action.margin
        hit = min([here] + [tree_min_margin(sub, memo) for _, sub in node.branches])
        memo[id(node)] = hit
    return hit


def expected_operations(machine: PushAlignMachine, root: Step) -> float:
    """Expected number of push-align operations of a plan, the first alignment counted.

    Masses start at each state's weight; an action moves a state's mass to its successor
    under the action's representative rotation; a reading branch keeps each state's mass
    times the probability that its reading falls in the branch. By linearity this is the
    weighted sum, over start states, of the expected operations of a part in that state.
    """
    return _expected(machine, root, lambda _node: 1.0)


def expected_seconds(machine: PushAlignMachine, root: Step, costs: ActionCosts) -> float:
    """Expected seconds per part of a plan (docs/cell.md): each operation costs
    ``costs.seconds`` of its representative rotation, the first alignment ``costs.first_s``;
    the distribution is the one of :func:`expected_operations`."""
    return _expected(machine, root, lambda node: _node_seconds(node, costs))


def worst_seconds(root: PlanTree, costs: ActionCosts) -> float:
    """Seconds per part on the plan's slowest path (every branch any state can take)."""
    memo: dict[int, float] = {}

    def slowest(node: PlanTree) -> float:
        if isinstance(node, Leaf):
            return 0.0
        hit = memo.get(id(node))
        if hit is None:
            hit = _node_seconds(node, costs) + max(
                (slowest(sub) for _, sub in node.branches), default=0.0
            )
            memo[id(node)] = hit
        return hit

    return slowest(root)


def _node_seconds(node: Step, costs: ActionCosts) -> float:
    return costs.seconds(None if node.action is None else node.action.representative)


def _expected(machine: PushAlignMachine, root: Step, cost: Callable[[Step], float]) -> float:
    """The expectation of the summed ``cost`` of the operations a part goes through.

    With outcome sets a state's mass moves to its outcome set, shared equally
    (docs/planning.md); a part follows a branch with the probability that its reading falls
    in it."""
    walk = _Expectation(machine, cost)
    return sum(s.weight * walk.ops(root, i) for i, s in enumerate(machine.states))


class _Expectation:
    """The expected summed cost from each (node, state) of one plan, memoised.

    A class rather than a recursive closure: a closure that calls itself is a reference
    cycle, and its memo would wait for the cyclic collector (paused while planning,
    ``budget.collector_paused``)."""

    def __init__(self, machine: PushAlignMachine, cost: Callable[[Step], float]) -> None:
        self.machine = machine
        self.cost = cost
        self.memo: dict[tuple[int, int], float] = {}
        self.probs: dict[tuple[float | None, float | None, int], float] = {}
        self.holding = _Holding()

    def ops(self, node: PlanTree, state: int) -> float:
        """The expected summed cost from ``node`` on, for a part resting in ``state`` before
        it (0 at a leaf)."""
        if isinstance(node, Leaf):
            return 0.0
        key = (id(node), state)
        hit = self.memo.get(key)
        if hit is not None:
            return hit
        m = self.machine
        if node.action is None:
            outs = [state]
        elif m.deterministic:
            outs = [m.successor(state, node.action.representative)]
        else:
            outs = members(m.outcomes(state, node.action.representative))
        total = self.cost(node)
        probs = self.probs
        for t in outs:
            for b, sub in self.holding(node, t):
                if not b.mask >> t & 1 or isinstance(sub, Leaf):
                    continue  # a leaf adds p * 0.0: nothing
                p = probs.get((b.lo, b.hi, t))
                if p is None:
                    p = probs[(b.lo, b.hi, t)] = reading_probability(m, b, t)
                if p > 0.0:
                    total += p * self.ops(sub, t) / len(outs)
        self.memo[key] = total
        return total


_INDEXED = 16
"""Nodes with more reading branches than this are indexed by state (:class:`_Holding`)."""


class _Holding:
    """Per node, the branches whose set holds a state, in the node's branch order.

    Most nodes have a few branches, but the root and the nodes of a near-round part or a
    large mix have hundreds and each state lies in one to three of them: those are indexed
    once (by the members of each branch), so a statistic costs their branch members, not
    states times branches. The sums keep the branch order: the figures are the same to the
    last bit.
    """

    def __init__(self) -> None:
        self._index: dict[int, dict[int, list[tuple[ReadingBranch, PlanTree]]]] = {}

    def __call__(self, node: Step, state: int) -> Sequence[tuple[ReadingBranch, PlanTree]]:
        """The node's branches holding ``state``, or (a node of few branches) all of them:
        the caller tests the state's bit."""
        if len(node.branches) <= _INDEXED:
            return node.branches
        index = self._index.get(id(node))
        if index is None:
            index = {}
            for b, sub in node.branches:
                for s in members(b.mask):
                    index.setdefault(s, []).append((b, sub))
            self._index[id(node)] = index
        return index.get(state, [])
