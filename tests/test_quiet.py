"""Readings that carry nothing on several parts (``feederkit.planning.quiet``): the lengths
agree with the tests' own brute-force search over reading branches, every plan made is a
plan (run from every start and every reading by the executor of test_planners), a beam
is never shorter than the length and exact when no level was cut, a search cut short records a bound
no greater than the length, and the time-limited plan of both landings of a near-round part
is a plan above that bound."""

from __future__ import annotations

import math
import random

import pytest
from shared import brute_lengths, small_mix
from test_planners import check_plan
from test_strong_plans import random_pf
from test_tie_breaks import _max_min

from feederkit.landing.model import landings_of_outline
from feederkit.machine import build_machine
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning import api, fallback, quiet
from feederkit.planning.andor import WorstCase
from feederkit.planning.api import _result, plan
from feederkit.planning.budget import Deadline, Timeout, WorkBudget
from feederkit.planning.methods import longest_root, make_oracle
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem, maximal_sets
from feederkit.planning.quiet import (
    MARGIN_STEP_DEG,
    QuietWorst,
    beam_chain,
    chain_plan,
    widening_chains,
    widest_chain,
)
from feederkit.planning.sequential import sequential_plan
from feederkit.planning.stats import tree_length
from feederkit.planning.tree import TIES_CHAIN, TIES_NONE
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL


def _coarse(pfs):
    """The machine of ``pfs`` under a sensor whose one reading fits every diameter, and the
    tolerance (each state's diameter read within it)."""
    ds = [s.diameter for s in build_machine(pfs, ToleranceSensor(0.05), IDEAL).states]
    tol = (max(ds) - min(ds)) / 2.0 + 0.01
    return build_machine(pfs, ToleranceSensor(tol), IDEAL), tol


def _cases():
    # mix3-700's part bound (2) is below its length (3): A* itself must prove it.
    for count, seed in ((2, 100), (2, 200), (3, 300), (4, 200), (3, 700)):
        yield f"mix{count}-{seed}", small_mix(count, seed)
    for seed in (8, 9, 15, 28):  # both landings, each state with one exact diameter
        yield (
            f"landings-{seed}",
            [push_function(x.part) for x in landings_of_outline(random_pf(seed).part)],
        )


CASES = dict(_cases())


def _roots(problem: Problem) -> tuple[list[int], tuple]:
    branches = problem.readings.branches(problem.full)
    return sorted(maximal_sets(sorted({b.mask for b in branches}))), branches


def _case(name: str):
    """A case's coarse machine, its problem, roots and root branches, and the tests' own
    length of a set (brute force)."""
    machine, tol = _coarse(CASES[name])
    problem = Problem(machine)
    roots, branches = _roots(problem)
    exact, _children = brute_lengths(machine, tol)
    return machine, problem, roots, branches, exact


@pytest.mark.parametrize("name", CASES)
def test_lengths_agree_with_the_brute_force_search_and_the_plan_is_a_chain(name):
    machine, tol = _coarse(CASES[name])
    assert all(s.diameter_range is None for s in machine.states)
    assert isinstance(make_oracle(Problem(machine), "auto", Deadline()), QuietWorst)
    length, _children = brute_lengths(machine, tol)
    own = length(machine.all_states)
    assert own is not None
    result = plan(machine)
    assert result.optimal and result.length == 1 + own
    assert result.tie_breaks == TIES_CHAIN
    assert check_plan(result) == result.length


@pytest.mark.parametrize("name", CASES)
def test_within_answers_as_the_brute_force_search(name):
    _machine, problem, roots, _branches, exact = _case(name)
    for k in range(7):
        worst = QuietWorst(problem)
        assert [worst.within(r, k) for r in roots] == [exact(r) <= k for r in roots]


@pytest.mark.parametrize("name", CASES)
def test_every_subsets_length_agrees_with_the_brute_force_search(name):
    machine, tol = _coarse(CASES[name])
    exact, _children = brute_lengths(machine, tol)
    rng = random.Random(name)
    worst = QuietWorst(Problem(machine))
    for _ in range(40):
        mask = rng.randrange(1, 1 << machine.n)
        own = exact(mask)
        if own is not None:
            assert worst.part_bound(mask) <= own
            assert worst.length(mask) == own


def test_the_oracle_is_a_quiet_one_only_where_every_length_is_sensorless():
    machine, _tol = _coarse(CASES["mix3-700"])
    deadline = Deadline()
    assert isinstance(make_oracle(Problem(machine), "auto", deadline), QuietWorst)
    for problem in (
        Problem(machine, min_margin=0.5),  # margins: the AND/OR search's exact view
        Problem(machine, distinct_maps=True),  # the expected objective's actions
        Problem(build_machine(CASES["mix3-700"], NoSensor(), IDEAL)),  # no sensor at all
        Problem(build_machine(CASES["mix3-700"], ToleranceSensor(0.05), IDEAL)),  # readings
    ):
        worst = make_oracle(problem, "auto", deadline)
        assert type(worst) is WorstCase


@pytest.mark.parametrize("width", [1, 4, 10_000])
@pytest.mark.parametrize("name", CASES)
def test_a_beam_finds_a_plan_no_shorter_than_the_length_and_the_length_uncut(name, width):
    machine, problem, roots, branches, exact = _case(name)
    worst = QuietWorst(problem)
    for r in roots:
        k, cut = beam_chain(worst, r, width, Deadline())
        assert k is not None and k >= exact(r)
        assert cut or k == exact(r)
        if width == 10_000:
            assert not cut
    root = chain_plan(problem, worst, roots, branches, Deadline())
    result = _result(machine, root, False, None, 1, "worst", "none")
    assert check_plan(result) == result.length == tree_length(root)
    assert result.length >= 1 + max(exact(r) for r in roots)


@pytest.mark.parametrize("name", CASES)
def test_the_widening_beams_end_at_the_length_and_their_plan_is_a_plan(name):
    machine, problem, roots, branches, exact = _case(name)
    worst = QuietWorst(problem)
    assert widening_chains(worst, roots, Deadline()) == max(exact(r) for r in roots)
    result = _result(
        machine,
        chain_plan(problem, worst, roots, branches, Deadline()),
        False,
        None,
        1,
        "worst",
        "none",
    )
    assert check_plan(result) == result.length == 1 + max(exact(r) for r in roots)


@pytest.mark.parametrize("polls", [1, 3, 10])
@pytest.mark.parametrize("name", CASES)
def test_a_search_cut_short_records_a_bound_no_greater_than_the_length(name, polls):
    machine, tol = _coarse(CASES[name])
    problem = Problem(machine)
    (root,), _branches = _roots(problem)
    exact, _children = brute_lengths(machine, tol)
    worst = QuietWorst(problem, WorkBudget(Deadline(), polls))
    try:
        assert worst.length(root) == exact(root)
    except Timeout:
        assert worst.part_bound(root) <= worst.lb[root] <= exact(root)


def _near_round_both_landings(tolerance_pct: float):
    """Both landings of a 64-gon with 1 % radial noise: its diameters read alike at 3 %."""
    pts = []
    for k in range(64):
        a, f = 2 * math.pi * k / 64, 1 + 0.01 * math.sin(7.3 * k * k + 1.1)
        pts.append((10 * f * math.cos(a), 10 * f * math.sin(a)))
    part = make_part(make_outline("round-64", pts))
    pfs = [push_function(x.part) for x in landings_of_outline(part)]
    size = max(pf.part.size for pf in pfs)
    return build_machine(pfs, ToleranceSensor(tolerance_pct / 100.0 * size), IDEAL)


@pytest.mark.slow
def test_a_time_limited_plan_of_both_landings_is_a_plan_above_the_parts_bound():
    machine = _near_round_both_landings(3.0)
    problem = Problem(machine)
    worst = make_oracle(problem, "auto", Deadline())
    assert isinstance(worst, QuietWorst)
    (root,), _branches = _roots(problem)
    result = plan(machine, PlanningOptions(time_limit_s=4.0))
    assert not result.optimal
    # Each part's backchaining length bounds the set's (the readings carry nothing).
    assert result.lower_bound >= 1 + worst.part_bound(root)
    assert result.lower_bound < result.length == check_plan(result)
    # The beams over sets beat the parts' chains in turn (43 operations here).
    chains = sequential_plan(problem, problem.readings.branches(problem.full), Deadline())
    assert chains is not None and result.length < tree_length(chains)


def test_a_search_cut_short_proves_more_than_the_parts_bound_where_it_can():
    machine, tol = _coarse(CASES["mix3-700"])
    problem = Problem(machine)
    (root,), _branches = _roots(problem)
    exact, _children = brute_lengths(machine, tol)
    assert QuietWorst(problem).part_bound(root) < exact(root)
    recorded = []
    for polls in range(1, 8):
        worst = QuietWorst(problem, WorkBudget(Deadline(), polls), arcs=False)
        with pytest.raises(Timeout):
            worst.length(root)
        recorded.append(worst.lb[root])
    assert max(recorded) == exact(root)
    # And a search with a budget of operations stops as soon as the bound passes it.
    worst = QuietWorst(problem, arcs=False)
    assert not worst.within(root, exact(root) - 1)
    assert worst.lb[root] == exact(root) and root not in worst.exact


def _cut_short(name: str):
    """The machine of a case, its problem, roots and branches, and a QuietWorst whose length
    search ran out after one poll (as the fallback receives it)."""
    machine, tol = _coarse(CASES[name])
    problem = Problem(machine)
    roots, branches = _roots(problem)
    worst = QuietWorst(problem, WorkBudget(Deadline(), 1), arcs=False)
    with pytest.raises(Timeout):
        longest_root(problem, worst, roots, "auto")
    return machine, tol, problem, roots, branches, worst


def _never(*_args, **_kwargs):
    raise AssertionError("the AND/OR beams over reading sets ran on a quiet machine")


@pytest.mark.parametrize("stop", ["time", "memory"])
@pytest.mark.parametrize("name", ["mix3-700", "landings-8"])
def test_the_fallback_plans_by_sets_and_never_by_reading_sets(monkeypatch, name, stop):
    machine, tol, problem, roots, branches, worst = _cut_short(name)
    exact, _children = brute_lengths(machine, tol)
    monkeypatch.setattr(fallback, "beam_plan", _never)
    options = PlanningOptions(time_limit_s=20.0)
    root, optimal, _length, lower, _ties, _cut = fallback.fallback(
        problem, worst, roots, branches, Deadline(20.0), options, stop
    )
    result = _result(machine, root, optimal, None, lower, "worst", "none")
    assert lower <= 1 + exact(roots[0]) <= result.length == check_plan(result)


@pytest.mark.parametrize("name", ["mix3-700", "mix3-300", "landings-8"])
def test_the_fallbacks_search_at_the_bound_makes_its_chain(monkeypatch, name):
    # Every other plan out of the way: the A* at the bound finds the shortest, and its
    # choices (images', copied from the cut search) make the chain.
    machine, tol, problem, roots, branches, worst = _cut_short(name)
    exact, _children = brute_lengths(machine, tol)
    for plan_maker in ("widening_chains", "sequential_plan", "pairwise_plan", "sensorless_plan"):
        monkeypatch.setattr(fallback, plan_maker, lambda *_a, **_k: None)
    monkeypatch.setattr(fallback, "beam_plan", _never)
    options = PlanningOptions(time_limit_s=20.0)
    root, _optimal, _length, lower, _ties, _cut = fallback.fallback(
        problem, worst, roots, branches, Deadline(20.0), options, "time"
    )
    result = _result(machine, root, False, None, lower, "worst", "none")
    assert result.length == 1 + exact(roots[0]) == check_plan(result)
    assert lower == result.length  # A* at the bound proved it too


@pytest.mark.parametrize("name", CASES)
def test_the_widest_chain_keeps_the_largest_margin_within_the_step(name):
    machine, problem, roots, _branches, exact = _case(name)
    longest = max(exact(r) for r in roots)
    memo: dict = {}
    # The largest smallest margin over every plan (every action, every reading branch): a
    # reading that fits every state leaves the whole image, so a chain keeps as much.
    want = min(_max_min(problem, r, longest, memo) for r in roots)
    found = widest_chain(QuietWorst(problem), roots, longest, 0.0, Deadline())
    assert found.search is not None and found.cut_by is None
    assert want - MARGIN_STEP_DEG <= found.margin <= want
    # And the plan: its length proven, its smallest margin the largest within the step
    # (the chain the bisection kept, or the first path's when that was already as wide).
    result = plan(machine)
    assert result.length == 1 + longest == check_plan(result)
    assert result.tie_breaks == TIES_CHAIN and result.ties_cut_by is None
    assert want - MARGIN_STEP_DEG <= result.min_margin <= want


def test_a_margin_bisection_cut_short_says_so_and_keeps_a_proven_plan(monkeypatch):
    # mix3-300: the first shortest path keeps far less than the widest chain.
    machine, problem, roots, _branches, exact = _case("mix3-300")
    longest = max(exact(r) for r in roots)
    want = min(_max_min(problem, r, longest, {}) for r in roots)
    first = plan(machine, PlanningOptions())
    monkeypatch.setattr(api, "TIE_GRACE_POLLS", 0)
    monkeypatch.setattr(api, "TIE_SHARE", 0.0)
    cut = plan(machine)
    assert cut.optimal and cut.length == first.length == check_plan(cut)
    assert cut.tie_breaks == TIES_NONE and cut.ties_cut_by == "work"
    assert cut.min_margin < want - MARGIN_STEP_DEG <= first.min_margin


@pytest.mark.parametrize("name", CASES)
def test_the_parts_lengths_of_many_sets_at_once_are_those_of_one_at_a_time(monkeypatch, name):
    monkeypatch.setattr(quiet, "VECTOR_MIN", 0)  # every batch by arrays
    machine, _tol = _coarse(CASES[name])
    problem = Problem(machine)
    rng = random.Random(name)
    masks = [rng.getrandbits(machine.n) for _ in range(300)]
    masks += [1 << i | 1 << j for i in range(machine.n) for j in range(i)]  # every pair
    one = QuietWorst(problem)
    many = QuietWorst(problem)
    many.part_lengths_of(masks)
    assert all(m in many._lengths for m in masks)
    assert [many.part_lengths(m) for m in masks] == [one.part_lengths(m) for m in masks]
    assert any(one.part_lengths(m)[0] > 0 for m in masks)
