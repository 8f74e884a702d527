"""Statistics of a plan tree: worst-case length, expected length, smallest margin.

The expected number of operations uses the distribution of :mod:`feederkit.planning.readings`
(uniform initial orientation, uniform reading error), the same one the planners minimise.
"""

from __future__ import annotations

import math

from feederkit.machine import PushAlignMachine, successor
from feederkit.planning.readings import reading_probability
from feederkit.planning.tree import Leaf, PlanTree, Step


def tree_length(node: PlanTree) -> int:
    """Worst-case number of operations of a subtree (each Step is one operation)."""
    if isinstance(node, Leaf):
        return 0
    return 1 + max((tree_length(sub) for _, sub in node.branches), default=0)


def tree_min_margin(node: PlanTree) -> float:
    """Smallest margin of the subtree's actions (inf when it has none)."""
    if isinstance(node, Leaf):
        return math.inf
    here = math.inf if node.action is None else node.action.margin
    return min([here] + [tree_min_margin(sub) for _, sub in node.branches])


def expected_operations(machine: PushAlignMachine, root: Step) -> float:
    """Expected number of push-align operations of a plan, the first alignment counted.

    Masses start at each state's weight; an action moves a state's mass to its successor
    under the action's representative rotation; a reading branch keeps each state's mass
    times the probability that its reading falls in the branch.
    """
    start = {i: s.weight for i, s in enumerate(machine.states)}
    return _expected(machine, root, start, {})


def _expected(
    machine: PushAlignMachine,
    node: PlanTree,
    masses: dict[int, float],
    memo: dict[tuple[float | None, float | None, int], float],
) -> float:
    if isinstance(node, Leaf):
        return 0.0
    if node.action is not None:
        moved: dict[int, float] = {}
        rep = node.action.representative
        for s, w in masses.items():
            t = successor(machine, s, rep)
            moved[t] = moved.get(t, 0.0) + w
        masses = moved
    total = sum(masses.values())
    for b, sub in node.branches:
        kept = {}
        for s, w in masses.items():
            if b.mask >> s & 1:
                p = memo.get((b.lo, b.hi, s))
                if p is None:
                    d = machine.states[s].diameter
                    p = memo[(b.lo, b.hi, s)] = reading_probability(machine.sensor, b, d)
                kept[s] = w * p
        total += _expected(machine, sub, kept, memo)
    return total
