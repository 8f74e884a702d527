"""Conditional plans over the push-align machine: the planners' output.

A :class:`Step` is one push-align operation: rotate by ``action`` (none at the root, the
first alignment from an unknown orientation), align, read, follow the branch whose closed
reading interval holds the reading. A :class:`Leaf` is an oriented set of states (every pair
inseparable); all its states are correct answers.
"""

from __future__ import annotations

from dataclasses import dataclass

from feederkit.machine import Branch, PushAlignMachine, SetAction


@dataclass(frozen=True)
class Leaf:
    """An oriented set of machine states (a goal)."""

    mask: int


@dataclass(frozen=True)
class Step:
    """One push-align operation and its branches on the reading.

    ``action`` is None at the root; ``branches`` pair each reading branch (its ``mask`` is
    the set of states consistent with the reading) with the subtree that follows.
    """

    action: SetAction | None
    branches: tuple[tuple[Branch, Step | Leaf], ...]


PlanTree = Step | Leaf


@dataclass(frozen=True)
class PlanResult:
    """A plan and its statistics.

    ``length`` is the worst-case number of push-align operations, the first alignment
    counted (design.md). ``expected_length`` assumes a uniformly random initial orientation
    (each first state weighted by its resting range). ``min_margin`` is the smallest
    half-width of the plan's actions (inf when it has none). ``optimal`` says the length
    (or the expected length, for that objective) is proven minimal; ``lower_bound`` is a
    proven lower bound on the optimum.
    """

    machine: PushAlignMachine
    root: Step
    length: int
    expected_length: float
    min_margin: float
    optimal: bool
    lower_bound: int
    objective: str = "worst"
    grouping: str = "exact"
