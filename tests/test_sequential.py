"""The parts' backchaining chains in turn (``feederkit.planning.sequential``) on the ideal
model: every plan it makes is a plan (run from every start and every reading by the test
executor of test_planners), never shorter than the exact planner's optimum and never longer
than one alignment plus the parts' backchaining lengths; it declines where the readings
after the chains leave parts to tell apart, and the fallback answers with it where the
exact search runs out."""

from __future__ import annotations

import pytest
from test_planners import check_plan
from test_strong_plans import random_pf

from feederkit.landing.model import landings_of_outline
from feederkit.machine import build_machine
from feederkit.mechanics import push_function
from feederkit.planning import api, fallback
from feederkit.planning.andor import part_chains
from feederkit.planning.api import _result, plan
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.sequential import sequential_plan
from feederkit.planning.stats import tree_length
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty


def _both_landings(seed: int, tolerance: float | None, uncertainty=IDEAL):
    pf = random_pf(seed)
    pfs = [push_function(x.part) for x in landings_of_outline(pf.part)]
    sensor = NoSensor() if tolerance is None else ToleranceSensor(tolerance)
    return build_machine(pfs, sensor, uncertainty)


def _sequential(machine):
    problem = Problem(machine)
    return problem, sequential_plan(problem, problem.readings.branches(problem.full), Deadline())


def _chain_sum(problem: Problem) -> int:
    """The parts' backchaining lengths from all their states, added up."""
    return sum(
        int(chain.length((1 << len(local)) - 1)) for _p, local, chain in part_chains(problem)
    )


@pytest.mark.parametrize("seed", range(20))
@pytest.mark.parametrize("tolerance", [None, 0.05, 0.5])
def test_its_plans_are_plans_between_the_optimum_and_the_chains_sum(seed, tolerance):
    machine = _both_landings(seed, tolerance)
    if machine.n < 2 or len({s.part for s in machine.states}) < 2:
        pytest.skip("one landing")
    problem, root = _sequential(machine)
    if root is None:
        return  # declined: checked below on cases known to decline
    result = _result(machine, root, False, None, 1, "worst", "exact")
    assert check_plan(result) == result.length == tree_length(root)
    assert plan(machine).length <= result.length <= 1 + _chain_sum(problem)


@pytest.mark.parametrize(
    ("seed", "tolerance", "length"), [(0, None, 6), (1, 0.05, 7), (2, None, 3)]
)
def test_it_plans_where_the_last_classes_read_apart_or_are_inseparable(seed, tolerance, length):
    _problem, root = _sequential(_both_landings(seed, tolerance))
    assert root is not None and tree_length(root) == length


@pytest.mark.parametrize(("seed", "tolerance"), [(0, 0.5), (3, 0.05), (7, 0.5)])
def test_it_declines_where_the_last_classes_must_still_be_told_apart(seed, tolerance):
    problem, root = _sequential(_both_landings(seed, tolerance))
    assert root is None
    assert len(part_chains(problem)) == 2  # two parts with chains: declined for the ending


def test_it_needs_the_ideal_model_and_several_parts():
    assert _sequential(_both_landings(0, None, Uncertainty(1.0)))[1] is None
    assert _sequential(build_machine([random_pf(0)], NoSensor(), IDEAL))[1] is None


def test_it_stops_at_its_deadline():
    problem = Problem(_both_landings(1, None))
    with pytest.raises(Timeout):
        sequential_plan(problem, problem.readings.branches(problem.full), Deadline(0.0))


def test_the_fallback_answers_with_it_before_the_pairwise_plan(monkeypatch):
    machine = _both_landings(1, None)
    optimum = plan(machine).length
    _problem, chained = _sequential(machine)
    assert chained is not None

    def out_of_time(*_args, **_kwargs):
        raise Timeout("time")

    def never(*_args, **_kwargs):
        pytest.fail("the pairwise plan was built with a plan in hand")

    monkeypatch.setattr(api, "longest_root", out_of_time)
    monkeypatch.setattr(fallback, "beam_plan", lambda *_args, **_kwargs: None)
    monkeypatch.setattr(fallback, "pairwise_plan", never)
    result = plan(machine, PlanningOptions(time_limit_s=30.0))
    assert check_plan(result) == result.length
    assert optimum <= result.length <= tree_length(chained)
