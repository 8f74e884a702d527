"""The parts' backchaining chains in turn: a plan on the ideal model for machines of a few
parts, each a long sensorless problem of its own (Goldberg 1993; sections 4 and 8).

On the ideal model a part's states form a push function, and Goldberg's table says how many
operations collapse any set of them with no sensor. Those rotations collapse the part's
states whatever other states ride along, and every other state goes to one state, so a class
of inseparable states stays one class (the relation is closed under actions). Applying the
parts' chains one after the other therefore leaves one class of each part, in at most the
sum of the parts' backchaining lengths. The plan follows the readings without using them
(every reading set of a step goes on with the subplan of the step's whole image, as the
one-part backchaining plan does), so it is one chain, one step per operation; only the
readings after its last operation are kept, and each must leave a goal: the parts read
apart there, or their last classes are inseparable (both landings of a part whose readings
carry nothing, where no plan tells up from down). Otherwise there is no such plan.

This is a first plan where the exact search runs out: on both landings of a random
1000-point outline at 3 % on the ideal model the chains give 39 operations in 0.1 s, where
the plan that tells the states apart one pair at a time (:mod:`feederkit.planning.pairwise`)
takes 69 in 6 s.

References
----------
Goldberg, K. Y. (1993). Orienting polygonal parts without sensors. Algorithmica 10.
Akella, S. and Mason, M. T. (1999). Using partial sensor information to orient parts.
The International Journal of Robotics Research 18(10), sections 4 and 8.
"""

from __future__ import annotations

from feederkit.machine import OverlapRange, members
from feederkit.planning.andor import part_chains
from feederkit.planning.budget import Deadline
from feederkit.planning.problem import Problem
from feederkit.planning.tree import Leaf, Step, build_dag, root_step


def sequential_plan(problem: Problem, root_branches, deadline: Deadline) -> Step | None:
    """The plan that collapses each part by its backchaining chain in turn (module
    docstring), built under ``deadline`` (Timeout); None when it does not apply (not the
    ideal model, a margin floor, fewer than two parts, a part that is not one push function
    with its symmetry as goal) or when the readings after the chains do not leave goals.

    ``root_branches`` are the reading branches of the first alignment.
    """
    if not problem.machine.deterministic or problem.min_margin > 0.0:
        return None
    chains = part_chains(problem)
    covered = 0
    for part, _local, _chain in chains:
        covered |= part
    if len(chains) < 2 or covered != problem.full:
        return None

    def local(mask: int, index: dict[int, int]) -> int:
        out = 0
        for i in members(mask):
            out |= 1 << index[i]
        return out

    def open_part(mask: int):
        """The first part (in a fixed order) whose states in ``mask`` are not one class."""
        for part, index, chain in chains:
            sub = mask & part
            if sub & (sub - 1) and not problem.is_goal(sub):
                return part, index, chain
        return None

    def expand(mask: int):
        if problem.is_goal(mask):
            return Leaf(mask)
        found = open_part(mask)
        if found is None:
            raise _Stuck  # one class of each part, not yet told apart
        part, index, chain = found
        k = chain.length(local(mask & part, index))  # type: ignore[attr-defined]
        cell = next(
            (
                c  # the widest first
                for c in problem.choices.cells(mask, False)
                if chain.length(local(c[2] & part, index)) < k  # type: ignore[attr-defined]
            ),
            None,
        )
        if cell is None:
            raise _Stuck  # the part's next rotations lie only in cells too narrow to use
        img = cell[2]
        last = open_part(img) is None
        return OverlapRange(*cell), [
            (b, b.mask if last or problem.is_goal(b.mask) else img)
            for b in problem.readings.image_branches(img)
        ]

    keys = {b.mask: b.mask if problem.is_goal(b.mask) else problem.full for b in root_branches}
    try:
        made = build_dag(list(dict.fromkeys(keys.values())), expand, deadline)
    except _Stuck:
        return None
    return root_step(((b, made[keys[b.mask]]) for b in root_branches), deadline)


class _Stuck(Exception):
    """The chains leave a set whose parts are one class each but not a goal."""
