"""The plan that tells the states apart one pair at a time (``feederkit.planning.pairwise``):
run from every start and every reading by test_planners' executor it is a plan, never
shorter than the independent exhaustive planner's optimum (test_planners_bruteforce, through
test_beam's cases) on one part, nor than the planner's on mixes, without a sensor and over
both landings; and the fallback answers with it when the
exact search and the beams find nothing."""

from __future__ import annotations

import math
import random

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_beam import _case
from test_planners import check_plan

from feederkit.errors import PlanningError
from feederkit.landing.model import landings_of_outline
from feederkit.machine import build_machine
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning import api, fallback
from feederkit.planning.api import goal_relation, plan
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.options import PlanningOptions
from feederkit.planning.pairwise import applies, pairwise_plan
from feederkit.planning.problem import Problem
from feederkit.planning.stats import tree_length
from feederkit.planning.tree import PlanResult
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty


def _pairwise(machine) -> PlanResult:
    problem = Problem(machine, "exact", 0.0, goal_relation(machine, Deadline()))
    root = pairwise_plan(problem, problem.readings.branches(problem.full), Deadline(60.0))
    assert root is not None
    length = tree_length(root)
    return PlanResult(machine, root, length, math.nan, math.inf, False, 1)


def _convex(seed: int, n: int, name: str):
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    radii = [rng.uniform(0.85, 1.0) for _ in angles]
    pts = [(30 * r * math.cos(t), 20 * r * math.sin(t)) for r, t in zip(radii, angles, strict=True)]
    return make_part(make_outline(name, pts))


@settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(st.integers(0, 10**9), st.integers(3, 10), st.floats(0.002, 0.08))
def test_one_part_gets_a_plan_never_shorter_than_the_optimum(seed, n, rel):
    machine, optimum = _case(seed, n, rel)  # the exhaustive planner's optimum
    result = _pairwise(machine)
    assert check_plan(result) == result.length >= optimum


@pytest.mark.parametrize("seed", range(3))
def test_one_part_without_a_sensor_gets_a_plan(seed):
    machine = build_machine([push_function(_convex(seed, 9, "blind"))], NoSensor(), IDEAL)
    result = _pairwise(machine)
    assert check_plan(result) == result.length >= plan(machine).length


@pytest.mark.parametrize(("count", "rel"), [(2, 0.01), (3, 0.03), (5, 0.05), (8, 0.02), (12, 0.05)])
def test_a_mix_gets_a_plan_never_shorter_than_the_optimum(count, rel):
    parts = [_convex(100 + k, random.Random(k).randint(5, 9), f"p{k}") for k in range(count)]
    pfs = [push_function(p) for p in parts]
    machine = build_machine(pfs, ToleranceSensor(rel * 60.0), IDEAL)
    result = _pairwise(machine)
    assert check_plan(result) == result.length >= plan(machine).length


@pytest.mark.parametrize("seed", range(4))
def test_a_part_over_both_landings_gets_a_plan(seed):
    # An outline and its mirror image: every state of one reads like one of the other.
    part = _convex(seed, 40, "both")
    pfs = [push_function(x.part) for x in landings_of_outline(part)]
    machine = build_machine(pfs, ToleranceSensor(0.02 * 60.0), IDEAL)
    result = _pairwise(machine)
    assert check_plan(result) == result.length >= plan(machine).length


def test_it_applies_on_the_ideal_model_with_exact_readings_only():
    pf = push_function(_convex(1, 8, "p"))
    ideal = build_machine([pf], ToleranceSensor(0.5), IDEAL)
    assert applies(Problem(ideal, "exact", 0.0, goal_relation(ideal, Deadline())))
    assert not applies(Problem(ideal, "components", 0.0, goal_relation(ideal, Deadline())))
    assert not applies(Problem(ideal, "exact", 1.0, goal_relation(ideal, Deadline())))
    rough = build_machine([pf], ToleranceSensor(0.5), Uncertainty())
    problem = Problem(rough, "exact", 0.0, goal_relation(rough, Deadline()))
    assert not applies(problem)
    assert pairwise_plan(problem, problem.readings.branches(problem.full), Deadline()) is None


def test_it_stops_at_its_deadline():
    part = _convex(3, 60, "both")
    pfs = [push_function(x.part) for x in landings_of_outline(part)]
    machine = build_machine(pfs, ToleranceSensor(0.01 * 60.0), IDEAL)
    problem = Problem(machine, "exact", 0.0, goal_relation(machine, Deadline()))
    with pytest.raises(Timeout):
        pairwise_plan(problem, problem.readings.branches(problem.full), Deadline(0.0))


def test_the_fallback_answers_with_it_when_nothing_else_finds_a_plan(monkeypatch):
    part = _convex(2, 40, "both")
    pfs = [push_function(x.part) for x in landings_of_outline(part)]
    machine = build_machine(pfs, ToleranceSensor(0.02 * 60.0), IDEAL)
    optimum = plan(machine).length

    def out_of_time(*_args, **_kwargs):
        raise Timeout("time")

    # The exact search runs out at once and the beams find nothing: the pairwise plan is
    # the plan in hand, and the depth-first search only looks for something shorter.
    monkeypatch.setattr(api, "longest_root", out_of_time)
    monkeypatch.setattr(fallback, "beam_plan", lambda *_args, **_kwargs: None)
    monkeypatch.setattr(fallback, "sequential_plan", lambda *_args: None)
    made = []
    real = fallback.pairwise_plan

    def spy(*args):
        made.append(real(*args))
        return made[-1]

    monkeypatch.setattr(fallback, "pairwise_plan", spy)
    result = plan(machine, PlanningOptions(time_limit_s=30.0))
    assert made and made[0] is not None
    assert not result.optimal
    assert check_plan(result) == result.length
    assert optimum <= result.length <= tree_length(made[0])
    # Without it, and with a depth-first search that finds nothing, no plan at all.
    monkeypatch.setattr(fallback, "pairwise_plan", lambda *_args: None)
    monkeypatch.setattr(api.WorstCase, "within", lambda *_args: False)
    with pytest.raises(PlanningError, match="no plan found"):
        plan(machine, PlanningOptions(time_limit_s=5.0))
