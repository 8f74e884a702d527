"""The optimal plan length as a step function of the sensor tolerance, with exact breakpoints.

A plan's length depends on the sensor only through which states read alike (and, with exact
branching, through the order of the reading intervals' ends, which changes at the same
places): for a tolerance ``e`` the relation is ``|d_i - d_j| < 2e`` over the mix's states
(:mod:`feederkit.design.critical`). So the length is constant on each interval
``(b_k, b_{k+1}]`` between consecutive breakpoints ``b = |d_i - d_j| / 2`` of the machine's
diameters, and it is monotone: a plan for a larger tolerance also works for a smaller one
(every reading it can then give is one it could give before), as long as the goal stays
the same, which it does up to the mix's critical tolerance. The step function is found
with one binary search per distinct length, not one plan per breakpoint: a range of
intervals whose two ends have equal length is constant throughout.

The expected number of operations changes continuously inside an interval (reading
probabilities depend on ``e``); each step reports it at the interval's right end, its
largest (least accurate) tolerance. Plans are for the ideal model (no rotation error).
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from feederkit.design.critical import (
    MixCritical,
    breakpoints_of,
    interval_probe,
    mix_critical_tolerance,
)
from feederkit.errors import CheckFailed
from feederkit.machine import build_machine
from feederkit.mechanics.push import PushFunction
from feederkit.planning.api import plan
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL


@dataclass(frozen=True)
class LengthStep:
    """Tolerances in ``(lo, hi]`` (mm; ``hi`` None: unbounded) all give plans of ``length``.

    ``expected``: the expected number of operations of the optimal plan at ``hi`` (at twice
    ``lo`` when unbounded). ``recognizable``: whether the mix is recognizable there (else
    the plan's results lump parts that no plan can tell apart at these tolerances).
    """

    lo: float
    hi: float | None
    length: int
    expected: float
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
    """The optimal plan's worst-case and expected number of operations at one tolerance."""

    length: int
    expected: float


def mix_breakpoints(pfs: Sequence[PushFunction]) -> tuple[float, ...]:
    """Where the read-alike relation of the mix's states changes (the machine's diameters)."""
    diameters = [s.diameter for s in build_machine(list(pfs), uncertainty=IDEAL).states]
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


def plan_evaluation(pfs: Sequence[PushFunction], tolerance: float) -> Evaluation:
    """Length and expected length of the verified optimal plan at ``tolerance`` mm (no
    certificate: the table needs neither its rotation error nor its shape tolerance)."""
    sensor = ToleranceSensor(tolerance)
    result = make_plan(list(pfs), sensor, uncertainty=IDEAL, certify=False).result
    return Evaluation(result.length, result.expected_length)


def optimal_length(pfs: Sequence[PushFunction], tolerance: float) -> int:
    """The proven minimum worst-case length at ``tolerance`` mm, from the planner alone.

    The search's probes need only the length; the steps' own plans are made and verified
    by :func:`plan_evaluation`.
    """
    return plan(build_machine(list(pfs), ToleranceSensor(tolerance), uncertainty=IDEAL)).length


def length_steps(
    pfs: Sequence[PushFunction],
    up_to: float | None,
    length_at: Callable[[float], int] | None = None,
    evaluate: Callable[[float], Evaluation] | None = None,
    critical: MixCritical | None = None,
) -> tuple[LengthStep, ...]:
    """The plan length's steps over tolerances ``(0, up_to]`` (None: every interval).

    ``up_to`` is rounded up to the end of its interval, so the last step is whole.
    ``length_at`` gives the optimal length at one tolerance (default
    :func:`optimal_length`), called about ``log2(#breakpoints)`` times per distinct length;
    ``evaluate`` makes each step's verified plan at its right end (default
    :func:`plan_evaluation`) and must agree with ``length_at``. ``critical``: the mix's
    pairs' critical tolerances, if already known.

    The length is monotone only while the goal stays the same: past a pair's critical
    tolerance its parts become inseparable, the plan need no longer tell them apart and
    may get shorter. The intervals are therefore searched in segments between the pairs'
    critical tolerances, and steps never span two segments.
    """
    breaks = mix_breakpoints(pfs)
    length_at = length_at or (lambda e: optimal_length(pfs, e))
    evaluate = evaluate or (lambda e: plan_evaluation(pfs, e))
    critical = critical or mix_critical_tolerance(pfs)
    last = len(breaks) if up_to is None else _first_at_or_above(breaks, up_to)
    # Interval k is recognizable for a pair iff its right end is at most the pair's critical.
    changes = {
        _first_at_or_above(breaks, p.critical_tolerance) + 1
        for p in critical.pairs
        if p.critical_tolerance is not None and not math.isinf(p.critical_tolerance)
    }
    starts = sorted({0} | {c for c in changes if 0 < c <= last})
    mix_x = critical.critical_tolerance
    recognizable_below = (
        0 if mix_x is None else len(breaks) + 1 if math.isinf(mix_x) else
        _first_at_or_above(breaks, mix_x) + 1
    )  # fmt: skip
    memo: dict[int, int] = {}
    verified: dict[int, Evaluation] = {}

    def made(k: int) -> Evaluation:
        if k not in verified:
            verified[k] = evaluate(interval_probe(breaks, k))
            memo.setdefault(k, verified[k].length)
        return verified[k]

    def at(k: int) -> int:
        if k not in memo:
            memo[k] = length_at(interval_probe(breaks, k))
        return memo[k]

    def split(i: int, j: int, runs: list[tuple[int, int]]) -> None:
        """Constant runs of intervals i..j (monotone lengths), by divide and conquer."""
        if at(i) == at(j):
            runs.append((i, j))
        elif j == i + 1:
            runs.extend([(i, i), (j, j)])
        else:
            mid = (i + j) // 2
            split(i, mid, runs)
            split(mid, j, runs)

    steps = []
    for first, end in zip(starts, [*starts[1:], last + 1], strict=True):
        j_last = end - 1
        made(j_last)  # a segment's last interval always ends a step (often the costliest plan)
        runs: list[tuple[int, int]] = []
        split(first, j_last, runs)
        merged: list[list[int]] = []
        for i, j in sorted(runs):
            if merged and at(merged[-1][1]) == at(i) and merged[-1][1] >= i - 1:
                merged[-1][1] = max(merged[-1][1], j)
            else:
                merged.append([i, j])
        for i, j in merged:
            ev = made(j)
            if ev.length != at(j):
                raise CheckFailed(
                    f"the verified plan at {interval_probe(breaks, j):g} mm has length "
                    f"{ev.length}, the planner's proven minimum is {at(j)}"
                )
            lo = 0.0 if i == 0 else breaks[i - 1]
            hi = breaks[j] if j < len(breaks) else None
            steps.append(LengthStep(lo, hi, ev.length, ev.expected, j < recognizable_below))
    return tuple(steps)
