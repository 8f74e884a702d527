"""Whether a strong plan exists, decided by pairs (``solvable.unsolvable_by_pairs``).

A subset of a solvable set is solvable, so a root reading set holding a pair of states that
no strong plan orients has no strong plan: the pairs' sets are few and small, where the
roots' own reachable sets can be too many to explore in time. Checked against the exact
least fixpoint over the roots' sets (``solvable.unsolvable``), and the planner's answer when
its length search cannot finish. Before the pairs' searches, the pairs nature can keep
apart (``machine.inseparable.kept_apart``) answer at once: checked against a plain fixpoint
written here and against the exact answer.
"""

from __future__ import annotations

import math
import random

import pytest
from shared import outcome_mask, rotation_mids, small_mix
from test_strong_plans import random_pf

from feederkit.machine import build_machine
from feederkit.machine.inseparable import kept_apart
from feederkit.planning import api, fallback, solvable
from feederkit.planning.api import plan, strong_plan_exists
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.solvable import NoStrongPlan, solve, unsolvable, unsolvable_by_pairs
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import Uncertainty

CASES = [(1.0, 0.1), (2.0, 0.2), (4.0, None), (3.0, 0.4)]
"""(rotation error in deg, sensor tolerance in mm or None for no sensor)."""


def _two_parts(seed: int, rotation: float, tolerance: float | None):
    sensor = NoSensor() if tolerance is None else ToleranceSensor(tolerance)
    pfs = [random_pf(8000 + seed), random_pf(9000 + seed)]
    return build_machine(pfs, sensor, Uncertainty(rotation))


def _roots(problem: Problem) -> list[int]:
    return sorted(maximal_sets(b.mask for b in problem.readings.branches(problem.full)))


@pytest.mark.parametrize("seed", range(0, 40, 2))
@pytest.mark.parametrize(("rotation", "tolerance"), CASES)
def test_roots_the_pairs_refuse_have_no_strong_plan(seed, rotation, tolerance):
    problem = Problem(_two_parts(seed, rotation, tolerance))
    roots = _roots(problem)
    by_pairs = unsolvable_by_pairs(problem, roots)
    assert by_pairs is not None
    assert set(by_pairs) <= set(unsolvable(problem, roots))  # sound: never a solvable root


@pytest.mark.parametrize(("rotation", "tolerance"), CASES)
def test_a_pair_no_strong_plan_orients_is_found(rotation, tolerance):
    # Seed 18: a pair of the two parts' states that every action leaves reading alike.
    problem = Problem(_two_parts(18, rotation, tolerance))
    roots = _roots(problem)
    assert unsolvable_by_pairs(problem, roots) == unsolvable(problem, roots) != []


def test_the_planner_says_no_strong_plan_when_its_search_cannot_finish(monkeypatch):
    # The length search is made to run out at once; without the pair test the answer was
    # "no plan found within the time limit", now it is that no strong plan exists.
    machine = _two_parts(18, 1.0, 0.1)

    def out_of_time(*args, **kwargs):
        raise api.Timeout("time")

    monkeypatch.setattr(api, "longest_root", out_of_time)
    monkeypatch.setattr(fallback, "beam_plan", lambda *args, **kwargs: None)
    monkeypatch.setattr(api, "kept_roots", lambda *args, **kwargs: [])  # the test below
    options = PlanningOptions(time_limit_s=30.0, lumping="none")
    with pytest.raises(NoStrongPlan, match="no strong plan exists"):
        plan(machine, options)
    assert not strong_plan_exists(machine, options)


def test_the_planner_says_no_strong_plan_before_searching_when_nature_keeps_a_pair(monkeypatch):
    # Seed 18 keeps a pair apart: the planner answers before its length search (which on a
    # 50-part mix at 5 % ran 30 s before it gave up).
    machine = _two_parts(18, 1.0, 0.1)
    monkeypatch.setattr(api, "longest_root", lambda *a, **k: pytest.fail("a search was run"))
    with pytest.raises(NoStrongPlan, match="no strong plan exists"):
        plan(machine, PlanningOptions(time_limit_s=30.0, lumping="none"))


@pytest.mark.parametrize("seed", range(0, 40, 2))
def test_the_roots_kept_pairs_name_have_no_strong_plan(seed):
    problem = Problem(_two_parts(seed, 1.0, 0.1))
    roots = _roots(problem)
    kept = kept_apart(problem.machine, solvable.candidate_pairs(problem))
    got = solvable.kept_roots(problem, roots)
    assert got == solvable.holding_kept_pairs(roots, kept)
    assert set(got) <= set(unsolvable(problem, roots))


def _all_pairs(problem: Problem, roots: list[int]) -> list[int]:
    pairs = set()
    for r in roots:
        idx = [k for k in range(problem.n) if r >> k & 1]
        pairs.update(
            (1 << a) | (1 << b)
            for i, a in enumerate(idx)
            for b in idx[i + 1 :]
            if not problem.is_goal((1 << a) | (1 << b))
        )
    return sorted(pairs)


def _every_pair_refused(problem: Problem, roots: list[int]) -> bool:
    """The plain check: some pair inside some root has no strong plan (solve over all)."""
    pairs = _all_pairs(problem, roots)
    value = solvable.solve(problem, pairs)
    assert value is not None
    return any(value[p] == math.inf for p in pairs)


def _counted_solve(monkeypatch) -> list[int]:
    """How many sets each call of solvable.solve starts from, as it is called."""
    calls: list[int] = []
    real = solvable.solve

    def counted(*args, **kwargs):
        calls.append(len(args[1]))
        return real(*args, **kwargs)

    monkeypatch.setattr(solvable, "solve", counted)
    return calls


@pytest.mark.parametrize("seed", range(12, 24, 2))
@pytest.mark.parametrize(("rotation", "tolerance"), CASES)
def test_the_neighbours_first_give_the_verdict_of_every_pair(
    seed, rotation, tolerance, monkeypatch
):
    # The diameter neighbours are asked first; when one of their pairs is refused, the
    # other pairs are never asked (one solve), else every pair is (a second, larger one).
    problem = Problem(_two_parts(seed, rotation, tolerance))
    roots = _roots(problem)
    want = _every_pair_refused(problem, roots)
    exact = set(unsolvable(problem, roots))
    calls = _counted_solve(monkeypatch)
    # The pairs' searches alone: no pair is taken as kept apart beforehand.
    monkeypatch.setattr(solvable, "kept_apart", lambda *_a: set())
    got = unsolvable_by_pairs(problem, roots)
    assert got is not None and bool(got) == want
    assert set(got) <= exact  # sound: never a solvable root
    assert len(calls) in (1, 2)
    if len(calls) == 1:
        assert got  # the neighbours decided it
    else:
        assert calls[1] >= calls[0]


def _kept_apart_by_definition(machine, goal) -> set[tuple[int, int]]:
    """The greatest relation of pairs that can read alike, are not a goal, and for every
    rotation (one per cell of all the machine's action boundaries) have some outcome of each
    making a different pair again in it: repeated until nothing changes."""
    n = machine.n
    mids = rotation_mids(machine)

    def out(i, a):
        t = outcome_mask(machine, i, a)
        return [k for k in range(n) if t >> k & 1]

    sensor = machine.sensor
    rel = {
        (i, j)
        for i in range(n)
        for j in range(i + 1, n)
        if not goal[i] >> j & 1
        and sensor.can_read_alike(machine.states[i].sensed, machine.states[j].sensed)
    }
    while True:
        keep = {
            (i, j)
            for i, j in rel
            if all(
                any(x != y and (min(x, y), max(x, y)) in rel for x in out(i, a) for y in out(j, a))
                for a in mids
            )
        }
        if keep == rel:
            return rel
        rel = keep


@pytest.mark.parametrize("seed", range(0, 40, 3))
@pytest.mark.parametrize(("rotation", "tolerance"), CASES)
def test_the_kept_pairs_are_the_greatest_such_relation_and_refuse_only_unsolvable_roots(
    seed, rotation, tolerance
):
    problem = Problem(_two_parts(seed, rotation, tolerance))
    machine = problem.machine
    got = kept_apart(machine, solvable.candidate_pairs(problem))
    assert got == _kept_apart_by_definition(machine, problem.insep)
    roots = _roots(problem)
    held = {r for r in roots if any(r >> i & 1 and r >> j & 1 for i, j in got)}
    assert set(solvable.holding_kept_pairs(roots, got)) == held
    assert held <= set(unsolvable(problem, roots))  # sound: never a solvable root


def test_kept_pairs_answer_before_any_search(monkeypatch):
    # Seed 18: a pair of the two parts' states nature keeps apart under 1 degree.
    problem = Problem(_two_parts(18, 1.0, 0.1))
    roots = _roots(problem)
    kept = kept_apart(problem.machine, solvable.candidate_pairs(problem))
    assert kept
    monkeypatch.setattr(solvable, "solve", lambda *_a, **_k: pytest.fail("a search was run"))
    got = unsolvable_by_pairs(problem, roots)
    assert got and all(any(r >> i & 1 and r >> j & 1 for i, j in kept) for r in got)


def test_with_single_outcomes_no_pair_is_kept_apart():
    # The ideal model: a pair that neither merges nor reads apart is inseparable (a goal).
    machine = build_machine(
        [random_pf(8018), random_pf(9018)], ToleranceSensor(0.1), Uncertainty(0.0)
    )
    problem = Problem(machine)
    assert kept_apart(machine, solvable.candidate_pairs(problem)) == set()


@pytest.mark.parametrize("seed", [19, 29, 36, 3, 7, 11, 23, 31])
@pytest.mark.parametrize("grouping", ["exact", "components"])
def test_kept_roots_are_sound_under_either_grouping(seed, grouping):
    """Under the components rule every pair not inseparable is a candidate, also pairs that
    never read alike; nature keeping such a pair apart proves nothing (a reading separates
    it once no third state bridges them). Seeds 19, 29, 36 gave roots called hopeless that
    have plans (36: a 3-operation plan orienting both parts on both sides, refused)."""
    rng = random.Random(seed)
    pfs = small_mix(rng.randint(1, 3), 300 + 7 * seed)
    tol = rng.choice([0.3, 1.0, 2.0, 4.0, 8.0])
    machine = build_machine(pfs, ToleranceSensor(tol), Uncertainty(rng.choice([1.0, 3.0, 6.0])))
    if machine.deterministic:
        pytest.skip("no outcome sets at this seed")
    problem = Problem(machine, grouping, 0.0)
    roots = _roots(problem)
    value = solve(problem, roots, None, 200_000)
    assert value is not None
    assert all(value[r] == math.inf for r in solvable.kept_roots(problem, roots))


def test_the_kept_check_gets_its_share_after_a_slow_goal_relation(monkeypatch):
    # The goal relation takes longer than a tenth of the limit (as on a 100-part mix at 5 %
    # under 1 degree): the kept pairs still answer before any search.
    import time

    machine = _two_parts(18, 1.0, 0.1)
    slow = api.goal_relation

    def goal_relation(*args, **kwargs):
        time.sleep(0.4)  # more than KEPT_SHARE of the 2-second limit
        return slow(*args, **kwargs)

    monkeypatch.setattr(api, "goal_relation", goal_relation)
    monkeypatch.setattr(api, "longest_root", lambda *a, **k: pytest.fail("a search was run"))
    with pytest.raises(NoStrongPlan, match="no strong plan exists"):
        plan(machine, PlanningOptions(time_limit_s=2.0, lumping="none"))


def test_the_fallback_does_not_ask_the_kept_pairs_again(monkeypatch):
    problem = Problem(_two_parts(3, 1.0, 0.1))
    roots = _roots(problem)
    expected = unsolvable_by_pairs(problem, roots)
    if solvable.kept_roots(problem, roots):
        pytest.skip("this seed keeps a pair apart")
    monkeypatch.setattr(solvable, "kept_roots", lambda *a, **k: pytest.fail("asked again"))
    assert unsolvable_by_pairs(problem, roots, kept_known=True) == expected


MIXED_PAIRS = [8, 9, 13, 18, 20]
"""Seeds whose pairs have plans of 1 to 4 operations and, some, none (under 4 degrees)."""


@pytest.mark.parametrize("seed", MIXED_PAIRS)
@pytest.mark.parametrize(("rotation", "tolerance"), CASES)
@pytest.mark.parametrize("depth", [1, 2, 4])
def test_the_pairs_left_unsettled_are_those_without_a_short_plan(
    seed, rotation, tolerance, depth, monkeypatch
):
    # Against the plain fixpoint over every pair (solve): the depth-first search per pair
    # sets aside exactly the pairs with a plan of at most SETTLE_DEPTH operations.
    problem = Problem(_two_parts(seed, rotation, tolerance))
    pairs = _all_pairs(problem, _roots(problem))
    value = solve(problem, pairs)
    assert value is not None
    monkeypatch.setattr(solvable, "SETTLE_DEPTH", depth)
    want = [q for q in pairs if value[q] > depth]
    assert solvable._unsettled(problem, pairs, None) == want


@pytest.mark.parametrize("seed", MIXED_PAIRS)
@pytest.mark.parametrize(("rotation", "tolerance"), CASES)
def test_the_pairs_verdict_is_the_same_by_either_way(seed, rotation, tolerance, monkeypatch):
    # SETS_PER_PAIR 0: the pairs with a short plan are always set aside first (those of a
    # single operation, so that pairs of 2-4 and none are left for the exploration).
    monkeypatch.setattr(solvable, "SETTLE_DEPTH", 1)
    problem = Problem(_two_parts(seed, rotation, tolerance))
    pairs = _all_pairs(problem, _roots(problem))
    value = solve(problem, pairs)
    assert value is not None
    calls = _counted_solve(monkeypatch)
    monkeypatch.setattr(solvable, "SETS_PER_PAIR", 0)
    got = solvable.unsolvable_pairs(problem, pairs)
    assert got == [q for q in pairs if value[q] == math.inf]
    # The quick exploration gave up at once; only the unsettled pairs were explored after.
    unsettled = sum(value[q] > solvable.SETTLE_DEPTH for q in pairs)
    assert calls == [len(pairs)] + ([unsettled] if unsettled else [])
