"""Which exact algorithm answers "how many operations does this set need?".

- ``andor``: AND/OR search over sets (section 6.1), :class:`WorstCase`;
- ``bottom-up``: the bottom-to-top dynamic programme (section 6.4);
- ``bfs``: breadth-first search over sets, sensorless (section 4);
- ``backchain``: Goldberg's backchaining, sensorless one-part push machines (section 4);
- ``auto``: backchaining where it applies (one part, no margin floor, the ideal model, and
  sensorless or with readings that carry no information: :func:`readings_carry_nothing`);
  with several parts and such readings, A* over sets (:mod:`feederkit.planning.quiet`,
  the plan's length only); else AND/OR search.

Under uncertainty (outcome sets) every method but backchaining searches sets of states with
the union image and the bisimulation goal, so each finds the minimum worst-case length of a
strong plan. Backchaining does not apply: its arcs assume an exact, monotone push function.

Every method yields the same lengths; the tie-breaking stages then query the oracle.
"""

from __future__ import annotations

from feederkit.errors import InputError
from feederkit.machine import Grouping, search_space
from feederkit.planning.andor import Deadline, WorstCase
from feederkit.planning.bottomup import bottom_up_lengths
from feederkit.planning.problem import Problem
from feederkit.planning.quiet import QuietWorst
from feederkit.planning.sensorless import Backchain, BackchainWorst, bfs_length, push_circle


def readings_carry_nothing(problem: Problem) -> bool:
    """Whether one reading is consistent with every state (a reading set holds them all).

    Then the readings never tell a plan anything nature cannot withhold: whatever set a
    plan holds, nature may answer that reading, so every set needs as many operations as
    without a sensor (Goldberg's sensorless length is a lower bound), and the sensorless
    plan reaches it. A coarse sensor on a near-round part is the typical case.

    >>> from feederkit.machine import build_machine
    >>> from feederkit.mechanics import push_function
    >>> from feederkit.outline import make_outline
    >>> from feederkit.part import make_part
    >>> from feederkit.planning.api import goal_relation
    >>> from feederkit.planning.budget import Deadline
    >>> from feederkit.planning.options import Grouping
    >>> from feederkit.sensors import ToleranceSensor
    >>> from feederkit.uncertainty import IDEAL
    >>> box = push_function(make_part(make_outline("box", [(0, 0), (10, 0), (10, 6), (0, 6)])))
    >>> def carry_nothing(tolerance):
    ...     m = build_machine([box], ToleranceSensor(tolerance), IDEAL)
    ...     problem = Problem(m, Grouping.EXACT, 0.0, goal_relation(m, Deadline()))
    ...     return readings_carry_nothing(problem)
    >>> carry_nothing(0.5), carry_nothing(3.0)  # widths 6 and 10 read alike from 2 mm on
    (False, True)
    """
    full = problem.full
    # Exact reading branching whatever the plan's grouping: a component holding every state
    # says nothing about one reading (its subsets' components may split), a reading set does.
    exact = search_space(problem.machine).branches(full, Grouping.EXACT)
    return any(b.mask == full for b in exact)


def make_oracle(problem: Problem, method: str, deadline: Deadline) -> WorstCase:
    """The worst-case length oracle for ``method`` (backchaining when it applies)."""
    if method in ("auto", "backchain"):
        circle = None
        quiet = problem.min_margin == 0.0 and (
            problem.sensorless or readings_carry_nothing(problem)
        )
        if quiet:
            circle = push_circle(problem.machine, problem.insep)
        if circle is not None:
            return BackchainWorst(problem, Backchain(circle), deadline)
        if method == "backchain":
            raise InputError(
                "backchaining needs a sensorless one-part push machine and no margin floor"
            )
        if (
            quiet
            and not problem.sensorless
            and problem.machine.deterministic
            and not problem.distinct_maps
        ):
            # Several parts, readings that carry nothing: every set's length is its
            # sensorless length (feederkit.planning.quiet).
            return QuietWorst(problem, deadline)
    return WorstCase(problem, deadline)


def longest_root(
    problem: Problem, worst: WorstCase, roots: list[int], method: str, limit: int | None = None
) -> int:
    """The largest minimum worst-case number of operations after the first alignment over
    the root branch masks: a plan's length is one more (section 6.1).

    Only the largest matters, so the AND/OR search proves it hardest first (the largest
    root) and then asks of every other root only whether it fits within the largest so
    far (``within``), deepening where one does not: a root that fits is proven by the
    first action that works, without refuting every shorter budget as iterative deepening
    of each root would. Lengths found by another algorithm are recorded in ``worst`` as
    exact values. ``limit`` caps the AND/OR search (ValueError beyond it).
    """
    if method == "bfs":
        out = {r: bfs_length(problem, r, worst.deadline) for r in roots}
    elif method == "bottom-up":
        out = bottom_up_lengths(problem, roots, worst.deadline)
    else:
        best = 0
        for r in sorted(roots, key=int.bit_count, reverse=True):
            if best and worst.within(r, best):
                continue
            best = worst.length(r, limit)
        return best
    worst.exact.update(out)
    return max(out.values(), default=0)
