"""The length search alone (``planning.api.shortest_length``): the certificate's ideal length.

Checked against the tests' own exhaustive search and against ``plan``; out of its budget it
says nothing rather than a length it has not proven; under uncertainty it refuses; and a
certificate states it, not the length of a plan the time limit cut short.
"""

from __future__ import annotations

import pytest
from shared import brute_lengths, small_mix
from test_strong_plans import random_pf

from feederkit.errors import InputError
from feederkit.machine import build_machine
from feederkit.planning.api import plan, shortest_length
from feederkit.planning.budget import Deadline
from feederkit.planning.options import PlanningOptions
from feederkit.plans import certify
from feederkit.plans import make as make_module
from feederkit.plans.make import make_plan
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty


@pytest.mark.parametrize(("count", "seed", "tol"), [(2, 100, 2.0), (3, 200, 4.0), (4, 7, 2.0)])
def test_the_shortest_length_is_the_exhaustive_searchs(count, seed, tol):
    machine = build_machine(small_mix(count, seed), ToleranceSensor(tol), IDEAL)
    length, children = brute_lengths(machine, tol)
    full = (1 << machine.n) - 1
    want = 1 + max(length(c) for c in children(full))
    assert shortest_length(machine) == want == plan(machine).length


@pytest.mark.parametrize(
    "options",
    [PlanningOptions(), PlanningOptions(min_margin_deg=2.0), PlanningOptions(objective="expected")],
)
def test_the_shortest_length_is_the_length_plan_proves(options):
    for seed in (300, 301, 302):
        machine = build_machine([random_pf(seed)], NoSensor(), IDEAL)
        worst = plan(machine, PlanningOptions(min_margin_deg=options.min_margin_deg))
        assert shortest_length(machine, options) == worst.length


def test_a_margin_floor_no_plan_keeps_has_no_shortest_length():
    machine = build_machine(small_mix(3, 200), ToleranceSensor(4.0), IDEAL)
    assert shortest_length(machine, PlanningOptions(min_margin_deg=89.0)) is None


def test_out_of_its_budget_the_shortest_length_is_unknown():
    machine = build_machine(small_mix(3, 200), ToleranceSensor(4.0), IDEAL)
    assert shortest_length(machine, budget=Deadline(0.0)) is None


def test_under_uncertainty_the_shortest_length_alone_is_refused():
    machine = build_machine([random_pf(300)], NoSensor(), Uncertainty(1.0))
    with pytest.raises(InputError, match="ideal model"):
        shortest_length(machine)


def test_the_certificate_states_the_proven_ideal_length_not_a_cut_plans(monkeypatch):
    # The certificate's ideal length was the length of a whole plan made on the ideal model
    # under what was left of the limit; a plan the limit cut short is no optimum.
    unc = Uncertainty(1.0, 0.01)
    options = PlanningOptions(time_limit_s=30.0)
    made = make_plan([random_pf(7000)], ToleranceSensor(0.2), options, uncertainty=unc)
    ideal = build_machine([random_pf(7000)], ToleranceSensor(0.2), IDEAL)
    assert made.plan["stats"]["certificate"]["ideal_length"] == plan(ideal).length

    planned = []
    real = make_module.plan_machine

    def spied(machine, *args, **kwargs):
        planned.append(machine.deterministic)
        return real(machine, *args, **kwargs)

    monkeypatch.setattr(make_module, "plan_machine", spied)
    proven = make_plan([random_pf(7000)], ToleranceSensor(0.2), options, uncertainty=unc)
    assert planned == [False]  # the strong plan only: the ideal length is searched alone
    assert proven.plan["stats"]["certificate"]["ideal_length"] == plan(ideal).length
    monkeypatch.setattr(certify, "shortest_length", lambda machine, opts: None)
    unproven = make_plan([random_pf(7000)], ToleranceSensor(0.2), options, uncertainty=unc)
    assert unproven.plan["stats"]["certificate"]["ideal_length"] is None
