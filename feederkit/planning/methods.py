"""Which exact algorithm answers "how many operations does this set need?".

- ``andor``: AND/OR search over sets (section 6.1), :class:`WorstCase`;
- ``bottom-up``: the bottom-to-top dynamic programme (section 6.4);
- ``bfs``: breadth-first search over sets, sensorless (section 4);
- ``backchain``: Goldberg's backchaining, sensorless one-part push machines (section 4);
- ``auto``: backchaining where it applies (sensorless, one part, no margin floor, the ideal
  model), else AND/OR search.

Under uncertainty (outcome sets) every method but backchaining searches sets of states with
the union image and the bisimulation goal, so each finds the minimum worst-case length of a
strong plan. Backchaining does not apply: its arcs assume an exact, monotone push function.

Every method yields the same lengths; the tie-breaking stages then query the oracle.
"""

from __future__ import annotations

from feederkit.errors import InputError
from feederkit.planning.andor import Deadline, WorstCase
from feederkit.planning.bottomup import bottom_up_lengths
from feederkit.planning.problem import Problem
from feederkit.planning.sensorless import Backchain, BackchainWorst, bfs_length, push_circle


def make_oracle(problem: Problem, method: str, deadline: Deadline) -> WorstCase:
    """The worst-case length oracle for ``method`` (backchaining when it applies)."""
    if method in ("auto", "backchain"):
        circle = None
        if problem.sensorless and problem.min_margin == 0.0:
            circle = push_circle(problem.machine, problem.insep)
        if circle is not None:
            return BackchainWorst(problem, Backchain(circle), deadline)
        if method == "backchain":
            raise InputError(
                "backchaining needs a sensorless one-part push machine and no margin floor"
            )
    return WorstCase(problem, deadline)


def root_lengths(
    problem: Problem, worst: WorstCase, roots: list[int], method: str, limit: int | None = None
) -> dict[int, int]:
    """Minimum worst-case operations after the first alignment, per root branch mask.

    Lengths found by another algorithm are recorded in ``worst`` as exact values. ``limit``
    caps the AND/OR search (ValueError beyond it).
    """
    if method == "bfs":
        out = {r: bfs_length(problem, r, worst.deadline) for r in roots}
    elif method == "bottom-up":
        out = bottom_up_lengths(problem, roots, worst.deadline)
    else:
        return {r: worst.length(r, limit) for r in roots}
    for r, v in out.items():
        worst.exact[r] = v
    return out
