"""The plan length as a step function of the tolerance (feederkit.design.steps).

Checked against a plan at every interval between breakpoints (no divide and conquer), and
against the tests' independent exhaustive planner (``mix_oracle``) inside each interval; the
monotonicity the search relies on (a plan for a larger tolerance works for a smaller one) is
checked by verifying a plan made for one tolerance under a smaller one.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from mix_oracle import MixOracle, OraclePart
from test_design_critical import random_pf

from feederkit.design.critical import MixCritical, interval_probe, mix_critical_tolerance
from feederkit.design.steps import (
    Evaluation,
    LengthOracle,
    length_steps,
    mix_breakpoints,
    optimal_length,
    plan_evaluation,
)
from feederkit.errors import CheckFailed
from feederkit.landing.model import landings_of_outline
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.make import make_plan
from feederkit.plans.strong import verify_strong
from feederkit.plans.verify import verify_plan
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import Uncertainty


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
    breaks = mix_breakpoints(pfs)
    steps = length_steps(pfs, None)
    for s in steps[:-1]:
        # Just below the right end: at it the two diameters that meet there read alike.
        probe = interval_probe(breaks, breaks.index(s.hi))
        assert s.hi * (1 - 1e-5) < probe < s.hi
        ev = plan_evaluation(pfs, probe)
        assert ev.length == s.length and abs(ev.expected - s.expected) < 1e-9
        assert 1.0 <= s.expected <= s.length


def test_a_step_ending_at_a_critical_tolerance_has_the_length_inside_it():
    """A part's two landings read the same two diameters, so one reading cannot tell up from
    down: two operations at every tolerance that tells them apart. At the pair's critical
    tolerance itself the machine's reading intervals (snapped outward by a hair) already
    meet, the landings are inseparable and one operation does: the step must not take that
    length (it once said 1 up to the critical tolerance)."""
    pts = [[14.528, 2.257], [5.55, 14.017], [-6.248, 15.482], [12.94, -14.047], [11.916, -11.234]]
    part = make_part(make_outline("r08", pts))
    pfs = [push_function(x.part) for x in landings_of_outline(part)]
    steps = length_steps(pfs, None)
    first = steps[0]
    assert first.recognizable and first.length == 2
    for e in (first.hi / 2.0, first.hi * (1 - 1e-4)):
        assert optimal_length(pfs, e) == 2
    assert optimal_length(pfs, first.hi) == 1  # the boundary itself: the landings lumped


def test_a_disagreeing_verified_plan_is_a_failed_check():
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


@pytest.mark.parametrize("seed", range(4))
def test_the_length_oracle_is_the_planners_length_at_every_interval(seed):
    # The oracle reuses one machine for every tolerance and skips the plan tree; its
    # lengths must be the whole planner's, and "fits in L" must mean exactly "L >= length".
    pfs = small_mix(400 + seed, parts=3 if seed % 2 else 2)
    oracle = LengthOracle(pfs)
    breaks = mix_breakpoints(pfs)
    for k in range(len(breaks) + 1):
        e = interval_probe(breaks, k)
        length = optimal_length(pfs, e)
        assert oracle.length(e) == length, e
        assert oracle.within(e, length) and not oracle.within(e, length - 1), e


class StepOracle(LengthOracle):
    """A monotone length with steps at given tolerances (no planning), counting questions."""

    def __init__(self, pfs, rises):
        super().__init__(pfs)
        self.rises = sorted(rises)
        self.asked = 0

    def true_length(self, tolerance):
        return 1 + sum(1 for r in self.rises if r < tolerance)

    def length(self, tolerance):
        self.asked += 1
        return self.true_length(tolerance)

    def within(self, tolerance, length):
        self.asked += 1
        return self.true_length(tolerance) <= length


@pytest.mark.parametrize("seed", range(3))
def test_the_search_finds_every_step_with_a_few_questions_per_step(seed):
    # Hundreds of intervals, a few steps at random places (two may be adjacent): the
    # search must end each step exactly there, asking O(log intervals) per step.
    rng = np.random.default_rng(600 + seed)
    pfs = [random_pf(rng, f"q{seed}p{i}") for i in range(8)]
    breaks = mix_breakpoints(pfs)
    assert len(breaks) > 300
    picks = sorted(rng.choice(len(breaks), size=4, replace=False))
    picks[1] = picks[0] + 1
    oracle = StepOracle(pfs, [breaks[k] for k in picks])

    def evaluate(e):
        n = oracle.true_length(e)
        return Evaluation(n, float(n))

    steps = length_steps(pfs, None, oracle=oracle, evaluate=evaluate, critical=MixCritical(()))
    assert [s.hi for s in steps] == [*oracle.rises, None]
    assert [s.length for s in steps] == [1, 2, 3, 4, 5]
    assert oracle.asked <= len(steps) * (2 * math.ceil(math.log2(len(breaks))) + 2)
    assert oracle.asked < len(breaks) / 4


def test_an_oracle_that_breaks_monotonicity_is_a_failed_check():
    # Lengths that fall with the tolerance contradict the argument the search rests on:
    # the verified plans must catch it, never a table built on it.
    pfs = small_mix(8)

    class Falling(LengthOracle):
        def length(self, tolerance):
            return 9

        def within(self, tolerance, length):
            return length >= 9

    with pytest.raises(CheckFailed):
        length_steps(pfs, None, oracle=Falling(pfs))


def _verifies_under(data, uncertainty):
    """Whether every start, outcome and reading of the plan file reaches its result: the
    stated length may be stale (made for another sensor), so any length up to it will do."""
    stated = data["stats"]["length"]
    for length in range(1, stated + 1):
        data["stats"]["length"] = length
        try:
            verify_strong(data, uncertainty)
        except CheckFailed as exc:
            if "worst path under the declared uncertainty" in str(exc):
                continue
            raise
        return True
    return False


@pytest.mark.parametrize("seed", [500, 503, 505, 507])
def test_a_strong_plan_for_a_larger_tolerance_works_for_a_smaller_one(seed):
    # The monotonicity argument under a declared rotation error: the physical states'
    # reading intervals shrink with the tolerance, the outcome sets do not change. (Mixes
    # with a strong plan at the larger tolerance; 502, for one, has none.)
    pfs = small_mix(seed)
    uncertainty = Uncertainty(rotation_error_deg=1.0)
    breaks = mix_breakpoints(pfs)
    big = breaks[len(breaks) // 2]
    made = make_plan(pfs, ToleranceSensor(big), uncertainty=uncertainty, certify=False)
    for small in (breaks[0], big / 3.0):
        data = copy.deepcopy(made.plan)
        data["sensor"] = ToleranceSensor(small).to_dict()
        assert _verifies_under(data, uncertainty), small
