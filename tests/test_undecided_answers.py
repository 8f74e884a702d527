"""What ``plan`` says when a limit cuts it short under uncertainty: never a claim it has not
proven (docs/planning.md, "Near-symmetric states under uncertainty" and "Time and memory
limits").

A machine with no strong plan to its inseparable goal may still have one to the lumped goal
(near-symmetric states listed together); when the limit passes before lumping is decided,
or before the search of the inseparable goal finds any plan, the answer is "no plan found",
and a lower bound proven for the inseparable goal is stated for that goal only.
"""

from __future__ import annotations

import pytest
from test_lumping import near_rectangle

import feederkit.planning.api as api
from feederkit.cli.common import time_limit_note
from feederkit.errors import PlanningError
from feederkit.machine import build_machine
from feederkit.planning.andor import WorstCase
from feederkit.planning.api import goal_relation
from feederkit.planning.budget import Deadline
from feederkit.planning.fallback import fallback
from feederkit.planning.lumping import LumpingTry, try_lumping
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.solvable import NoStrongPlan
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import Uncertainty


def rectangle(sensor=None):
    return build_machine([near_rectangle()], sensor or NoSensor(), Uncertainty())


def test_lumping_says_what_cut_it_short():
    m = rectangle()
    assert try_lumping(m).cut_by is None
    assert try_lumping(m, max_sets=0).cut_by == "sets"
    passed = Deadline(end=0.0)  # long past
    tried = try_lumping(m, deadline=passed)
    assert tried.goal is None and not tried.decided and tried.cut_by == "time"


@pytest.mark.parametrize("reason", ["time", "memory"])
def test_lumping_cut_short_by_a_limit_is_no_plan_found_not_no_strong_plan(monkeypatch, reason):
    """The rectangle has a plan to its lumped goal (test_lumping): out of time or memory
    before lumping is decided, ``plan`` must not say that no strong plan exists."""
    m = rectangle()
    assert api.plan(m).lumped_pairs  # with room: a lumped plan
    cut = LumpingTry(None, decided=False, cut_by=reason)
    monkeypatch.setattr(api, "try_lumping", lambda *a, **k: cut)
    options = PlanningOptions(time_limit_s=30.0, memory_limit_mb=100_000.0)
    with pytest.raises(PlanningError) as info:
        api.plan(m, options)
    assert not isinstance(info.value, NoStrongPlan)
    limit = "the time limit of 30 s" if reason == "time" else "the memory limit of 100000 MB"
    assert str(info.value).startswith(f"no plan found within {limit}: ")
    assert "near-symmetric" in str(info.value)


def test_lumping_that_runs_out_of_sets_keeps_no_strong_plan(monkeypatch):
    """Not a limit of the run: the machine's own size (the message names the search)."""
    m = rectangle()
    cut = LumpingTry(None, decided=False, cut_by="sets")
    monkeypatch.setattr(api, "try_lumping", lambda *a, **k: cut)
    with pytest.raises(NoStrongPlan):
        api.plan(m)


def _fallback_of(machine, apart: bool) -> str:
    """The message of the fallback with no time at all (nothing it tries can finish)."""
    problem = Problem(machine, "exact", 0.0, goal_relation(machine, Deadline()))
    root_branches = problem.readings.branches(problem.full)
    roots = sorted(maximal_sets(b.mask for b in root_branches))
    worst = WorstCase(problem, Deadline())
    for r in roots:
        worst.lb[r] = 3  # as if the search had proven it
    options = PlanningOptions(time_limit_s=1.0)
    with pytest.raises(PlanningError) as info:
        fallback(problem, worst, roots, root_branches, Deadline(end=0.0), options, "time", apart)
    return str(info.value)


def test_a_bound_of_the_inseparable_goal_is_stated_for_that_goal_when_lumping_may_follow():
    m = rectangle(ToleranceSensor(0.2))
    assert _fallback_of(m, apart=False) == (
        "no plan found within the time limit of 1 s (a plan needs at least 4 operations)"
    )
    assert _fallback_of(m, apart=True) == (
        "no plan found within the time limit of 1 s (one whose results list no states together "
        "needs at least 4 operations)"
    )


def test_the_time_limit_note_names_the_objective_its_bound_is_not_about():
    worst = {"optimal": False, "length": 5, "lower_bound": 4, "objective": "worst"}
    assert time_limit_note(worst, 2.0) == (
        "the search under the time limit of 2 s stopped short: this plan has 5 operations "
        "and is not proven shortest; a plan needs at least 4 (allow more time with "
        "--time-limit S)"
    )
    # A plan as long as its worst-case bound is not proven best for the expected objective.
    expected = {"optimal": False, "length": 4, "lower_bound": 4, "objective": "expected"}
    assert time_limit_note(expected, 1.0) == (
        "the search under the time limit of 1 s stopped short: this plan (4 operations) is "
        "not proven best for the expected objective; every plan needs at least 4 operations "
        "in the worst case (allow more time with --time-limit S)"
    )
    assert time_limit_note({**expected, "optimal": True}, 1.0) is None
    assert time_limit_note(expected, None) is None
