"""The plan length as a step function of the tolerance (feederkit.design.steps).

Checked against a plan at every interval between breakpoints (no divide and conquer), and
against the tests' independent exhaustive planner (``mix_oracle``) inside each interval; the
monotonicity the search relies on (a plan for a larger tolerance works for a smaller one) is
checked by verifying a plan made for one tolerance under a smaller one.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from mix_oracle import MixOracle, OraclePart
from test_design_critical import random_pf

from feederkit.design.critical import interval_probe, mix_critical_tolerance
from feederkit.design.steps import (
    Evaluation,
    length_steps,
    mix_breakpoints,
    optimal_length,
    plan_evaluation,
)
from feederkit.plans.make import make_plan
from feederkit.plans.verify import verify_plan
from feederkit.sensors import ToleranceSensor


def small_mix(seed: int, parts: int = 2):
    """A random mix of few states (so a plan at every breakpoint is quick)."""
    rng = np.random.default_rng(seed)
    while True:
        pfs = [random_pf(rng, f"s{seed}p{i}") for i in range(parts)]
        if sum(pf.n for pf in pfs) <= 7:
            return pfs


def step_of(steps, e):
    return next(s for s in steps if s.lo < e and (s.hi is None or e <= s.hi))


@pytest.mark.parametrize("seed", range(6))
def test_steps_match_a_plan_at_every_interval(seed):
    pfs = small_mix(seed)
    breaks = mix_breakpoints(pfs)
    steps = length_steps(pfs, None)
    assert steps[0].lo == 0.0 and steps[-1].hi is None
    for left, right in zip(steps, steps[1:], strict=False):
        assert left.hi == right.lo and left.hi in breaks
    lengths = [optimal_length(pfs, interval_probe(breaks, k)) for k in range(len(breaks) + 1)]
    for k, length in enumerate(lengths):
        assert step_of(steps, interval_probe(breaks, k)).length == length
    # Monotone while the mix is recognizable (the goal is fixed); the steps there increase.
    x = mix_critical_tolerance(pfs).critical_tolerance
    assert x is not None
    ok = [length for k, length in enumerate(lengths) if interval_probe(breaks, k) <= x]
    assert ok == sorted(ok) and len(ok) < len(lengths)
    shown = [s for s in steps if s.recognizable]
    assert shown and shown[-1].hi == x and not steps[-1].recognizable
    assert all(a.length < b.length for a, b in zip(shown, shown[1:], strict=False))


def test_past_the_critical_tolerance_a_plan_may_get_shorter():
    # Once the parts are inseparable the plan need not tell them apart (seen on these
    # mixes), so the length is not monotone over every tolerance.
    shorter = 0
    for seed in (1, 2, 5):
        steps = length_steps(small_mix(seed), None)
        shorter += steps[-1].length < max(s.length for s in steps)
        assert not steps[-1].recognizable
    assert shorter >= 1


@pytest.mark.parametrize("seed", range(3))
def test_steps_match_the_independent_planner_inside_each_interval(seed):
    pfs = small_mix(100 + seed)
    breaks = mix_breakpoints(pfs)
    steps = length_steps(pfs, None)
    oracle_parts = [OraclePart(list(pf.part.hull), pf.part.com) for pf in pfs]
    inside = [(a + b) / 2.0 for a, b in zip((0.0, *breaks), breaks, strict=False)]
    inside.append(2.0 * breaks[-1])
    for e in inside:
        assert MixOracle(oracle_parts, e).length() == step_of(steps, e).length, e


@pytest.mark.parametrize("seed", range(4))
def test_a_plan_for_a_larger_tolerance_works_for_a_smaller_one(seed):
    pfs = small_mix(200 + seed)
    breaks = mix_breakpoints(pfs)
    big = breaks[len(breaks) // 2]
    made = make_plan(pfs, ToleranceSensor(big))
    for small in (breaks[0], breaks[len(breaks) // 4], big / 3.0):
        data = copy.deepcopy(made.plan)
        data["sensor"] = ToleranceSensor(small).to_dict()
        report = verify_plan(data)
        # Every start and reading still ends right; only the file's own statistics (its
        # stated length and expected length, made for the larger tolerance) may be stale.
        assert not report.failures, report.first_problem()
        assert all("length" in p for p in report.problems), report.problems


def test_the_table_stops_at_the_requested_tolerance_and_keeps_whole_steps():
    pfs = small_mix(3)
    breaks = mix_breakpoints(pfs)
    cut = (breaks[2] + breaks[3]) / 2.0
    steps = length_steps(pfs, cut)
    assert steps[-1].hi == breaks[3]  # rounded up to its interval's end
    full = length_steps(pfs, None)
    assert steps[-1].length == step_of(full, cut).length


def test_each_step_reports_the_verified_plan_at_its_right_end():
    pfs = small_mix(5)
    steps = length_steps(pfs, None)
    for s in steps[:-1]:
        ev = plan_evaluation(pfs, s.hi)
        assert ev.length == s.length and abs(ev.expected - s.expected) < 1e-9
        assert 1.0 <= s.expected <= s.length


def test_a_disagreeing_verified_plan_is_a_failed_check():
    from feederkit.errors import CheckFailed

    pfs = small_mix(6)

    with pytest.raises(CheckFailed):
        length_steps(pfs, None, evaluate=lambda e: Evaluation(99, 1.0))


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(10))
def test_three_part_steps_match_the_independent_planner(seed):
    rng = np.random.default_rng(300 + seed)
    while True:
        pfs = [random_pf(rng, f"t{seed}p{i}") for i in range(3)]
        if sum(pf.n for pf in pfs) <= 9:
            break
    breaks = mix_breakpoints(pfs)
    steps = length_steps(pfs, None)
    oracle_parts = [OraclePart(list(pf.part.hull), pf.part.com) for pf in pfs]
    inside = [(a + b) / 2.0 for a, b in zip((0.0, *breaks), breaks, strict=False)]
    for e in inside[:: max(1, len(inside) // 12)]:
        assert MixOracle(oracle_parts, e).length() == step_of(steps, e).length, e


def test_the_critical_tolerance_ends_a_recognizable_step_and_names_its_plan():
    """The pair's critical tolerance (from the pair's diameters) and the mix's breakpoints
    (from the machine's snapped ones) differ in the last digits: the table must still stop at
    the critical tolerance, and the answer quote the recognizable step's plan."""
    from pathlib import Path

    from feederkit.design.sensor import design_tolerance
    from feederkit.mechanics.push import push_function
    from feederkit.outline import load_outline_json
    from feederkit.part import make_part

    root = Path(__file__).resolve().parents[1] / "catalog"
    names = ["isosceles-right-triangle", "octagon", "rectangle-2x1"]
    pfs = [push_function(make_part(load_outline_json(root / f"{n}.json"))) for n in names]
    design = design_tolerance(pfs)
    x = design.critical_tolerance
    assert x is not None
    last = design.steps[-1]
    assert last.recognizable and last.hi == pytest.approx(x, rel=1e-9)
    step = design.step_at(x)
    assert step is last
    assert f"expected {last.expected:.4g}" in design.answer()
