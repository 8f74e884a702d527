"""Choosing among shortest plans (docs/planning.md, "Which plan among the shortest").

The largest smallest margin is decided by feasibility probes ("a plan within k keeping
every margin >= m", ``Refiner.keeps``) on the maximal reading branches; here it is checked
against the plain max-min recursion over every action and every branch set. The stages
run under a budget of work bounded by the length proof's (``api.TIE_SHARE``,
``api.TIE_GRACE_POLLS``; the expected stage ``api.EXPECTED_SHARE`` of it), so a machine
gives the same plan however fast the computer; out of it the plan keeps the proven length,
the root branches the expected stage built, and says which tie-breaks are exact and why not.
"""

from __future__ import annotations

import math
import random
import time

import numpy as np
import pytest
from test_deadline import near_round, small_mix
from test_planners import check_plan, random_convex

import feederkit.planning.api as api
import feederkit.planning.refine as refine
from feederkit.angles import norm360
from feederkit.machine import build_machine, members, search_space
from feederkit.planning.budget import Deadline, Timeout, WorkBudget
from feederkit.planning.choices import _widest_cells
from feederkit.planning.methods import longest_root, make_oracle
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.refine import Refiner, child_masses
from feederkit.planning.reindex import by_diameter
from feederkit.planning.tree import TIES_CHAIN, TIES_EXACT, TIES_MARGIN, TIES_NONE, Leaf
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty


def _machines():
    yield "5-part mix at 2 mm", build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL)
    yield "4-part mix at 1 mm", build_machine(small_mix(4), ToleranceSensor(1.0), IDEAL)
    for seed in (1, 3, 4):
        pf = random_convex(seed, 9)
        m = build_machine([pf], ToleranceSensor(0.02 * pf.part.size), IDEAL)
        yield f"random 9-gon #{seed} at 2%", m


MACHINES = list(_machines())


def _proven(machine):
    """A refiner whose root lengths are proven, the root branches and their budget."""
    problem = Problem(by_diameter(machine)[0])
    worst = make_oracle(problem, "auto", Deadline())
    every = sorted({b.mask for b in problem.readings.branches(problem.full)})
    roots = sorted(maximal_sets(every))
    k = longest_root(problem, worst, roots, "auto", None)
    return Refiner(problem, worst), every, k


def _max_min(problem: Problem, mask: int, k: int, memo: dict) -> float:
    """The largest smallest margin within ``k``: every action, every branch set."""
    if problem.is_goal(mask):
        return math.inf
    if k <= 0:
        return -math.inf
    hit = memo.get((mask, k))
    if hit is None:
        hit = -math.inf
        for act in problem.choices.exact_actions(mask):
            v = act.action.margin
            for c in act.children:
                v = min(v, _max_min(problem, c, k - 1, memo))
            hit = max(hit, v)
        memo[(mask, k)] = hit
    return hit


@pytest.mark.parametrize(("name", "machine"), MACHINES, ids=[n for n, _ in MACHINES])
def test_the_largest_margin_is_the_max_min_over_every_branch(name, machine):
    refiner, every, k = _proven(machine)
    memo: dict = {}
    want = {r: _max_min(refiner.p, r, k, memo) for r in every}
    for r in every:
        assert refiner.margin(r, k) == want[r], name
    assert refiner.largest_floor(every, k) == min(want.values())
    # Told that every root has a plan (the length proof's), the stage leaps from 0 at once,
    # on a fresh memo, and finds the same margin.
    fresh = Refiner(refiner.p, refiner.w)
    assert fresh.largest_floor(every, k, planned=True) == min(want.values())


@pytest.mark.parametrize(("name", "machine"), MACHINES, ids=[n for n, _ in MACHINES])
def test_keeps_answers_whether_a_margin_can_be_kept(name, machine):
    refiner, every, k = _proven(machine)
    memo: dict = {}
    rng = random.Random(5)
    exact = {r: _max_min(refiner.p, r, k, memo) for r in every}
    values = sorted({v for v in exact.values() if math.isfinite(v)})
    probes = rng.sample(values, min(4, len(values))) + [rng.uniform(0.0, 60.0) for _ in range(3)]
    probes += [v + 1e-6 for v in probes[:2]]
    for x in probes:
        fresh = Refiner(refiner.p, refiner.w)  # its own margin memo
        for r in every:
            want = exact[r] >= x
            assert refiner.keeps(r, k, x) == want, (name, r, x)  # one memo for every probe
            assert refiner.keeps(r, k, x, strict=True) == (exact[r] > x), (name, r, x)
            assert fresh.keeps(r, k, x) == want, (name, r, x)


CASE = build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL)
"""A mix whose first shortest plan keeps a smaller margin than the best one."""


def _exact_plan():
    return api.plan(CASE)


def test_with_no_time_for_ties_the_plan_keeps_the_proven_length(monkeypatch):
    exact = _exact_plan()
    monkeypatch.setattr(api, "TIE_GRACE_POLLS", -1)
    monkeypatch.setattr(api, "TIE_SHARE", 0.0)
    quick = api.plan(CASE)
    check_plan(quick)
    assert quick.optimal and quick.length == exact.length
    assert quick.min_margin < exact.min_margin  # the first plan, not the widest
    assert quick.tie_breaks == TIES_NONE
    assert exact.tie_breaks == TIES_EXACT


def test_out_of_time_in_the_expected_stage_the_margin_stays_exact(monkeypatch):
    exact = _exact_plan()

    def out_of_time(self, *args, **kwargs):
        raise Timeout("time")

    monkeypatch.setattr(Refiner, "expected", out_of_time)
    partial = api.plan(CASE)
    check_plan(partial)
    assert partial.optimal and partial.length == exact.length
    assert partial.min_margin == exact.min_margin
    assert partial.expected_length > exact.expected_length + 1e-6
    assert partial.tie_breaks == TIES_MARGIN


def test_the_tie_budget_counts_polls_not_seconds():
    budget = WorkBudget(Deadline(), 3)
    budget.check()
    time.sleep(0.05)  # time passing is no work
    budget.check()
    budget.check()
    with pytest.raises(Timeout):
        budget.check()
    assert budget.limited and budget.polls == 4


def test_the_tie_budget_keeps_the_outer_deadline():
    budget = WorkBudget(Deadline(1e-6), 10**9)
    time.sleep(1e-3)
    with pytest.raises(Timeout):
        budget.check()


def _tie_polls(monkeypatch) -> tuple[int, int]:
    """The length proof's polls and the tie-breaking stages' polls of planning ``CASE``."""
    seen: list[WorkBudget] = []

    class Recording(WorkBudget):
        def __init__(self, outer: Deadline, polls: float) -> None:
            super().__init__(outer, polls)
            seen.append(self)
            self.proof = outer.polls

    with monkeypatch.context() as m:
        m.setattr(api, "WorkBudget", Recording)
        api.plan(build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL))
    margin, expected = seen  # the stages' budget, then the expected stage's share of it
    return margin.proof, margin.polls + expected.polls


def test_a_plan_cut_short_in_its_tie_breaks_is_the_same_on_a_slow_computer(monkeypatch):
    # Give the stages half the polls they need: the expected stage is cut short. Burning CPU
    # at every poll (a slow or busy computer) must not change where it stops.
    proof, needed = _tie_polls(monkeypatch)
    assert needed > 20
    monkeypatch.setattr(api, "TIE_SHARE", 0.0)
    monkeypatch.setattr(api, "TIE_GRACE_POLLS", needed // 2)
    fast = api.plan(build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL))
    check = WorkBudget.check

    def slow_check(self) -> None:
        end = time.process_time() + 2e-4
        while time.process_time() < end:
            pass
        check(self)

    monkeypatch.setattr(WorkBudget, "check", slow_check)
    slow = api.plan(build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL))
    assert fast.tie_breaks != TIES_EXACT
    assert (slow.tie_breaks, slow.min_margin, slow.expected_length) == (
        fast.tie_breaks,
        fast.min_margin,
        fast.expected_length,
    )
    assert slow.root == fast.root


def test_the_tie_budget_does_not_depend_on_what_an_earlier_plan_cached(monkeypatch):
    # A second plan of the same machine object finds its tables built: the length proof
    # must poll as often, or the tie budget (and so the plan) would change.
    machine = build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL)
    seen: list[int] = []

    class Recording(WorkBudget):
        def __init__(self, outer: Deadline, polls: float) -> None:
            super().__init__(outer, polls)
            seen.append(outer.polls)

    monkeypatch.setattr(api, "WorkBudget", Recording)
    first = api.plan(machine)
    second = api.plan(machine)
    assert seen[0] == seen[1] > 0
    assert first.root == second.root


def test_targets_from_the_cell_table_are_the_machines_successors():
    m = build_machine(small_mix(6), ToleranceSensor(1.0), IDEAL)
    space = search_space(m)
    assert space.cell_table is not None
    rng = random.Random(2)
    starts = sorted({x for s in m.starts for x in s})
    for _ in range(500):
        mask = rng.getrandbits(m.n) or 1
        r = rng.choice([rng.uniform(0.0, 360.0), rng.choice(starts), 0.0])
        assert space.targets_at(mask, r) == [m.successor(i, r) for i in members(mask)]


@pytest.mark.parametrize("rotation_error", [0.0, 1.0])
def test_cells_from_the_cell_table_are_the_boundary_cells(rotation_error, monkeypatch):
    unc = IDEAL if rotation_error == 0.0 else Uncertainty(rotation_error_deg=rotation_error)
    m = build_machine(small_mix(6), ToleranceSensor(1.0), unc)
    space = search_space(m)
    assert (space.cell_table if m.deterministic else space.set_cell_table) is not None
    rng = random.Random(3)
    masks = [rng.getrandbits(m.n) or 1 for _ in range(200)]
    fast = Problem(m).choices
    got = [(fast.cells(x, False), fast.cells(x, True)) for x in masks]
    # The same cells from the machine's boundaries (Choices.fixed_cells), one per image.
    monkeypatch.setattr(search_space(m), "cells_and_images", lambda mask: None)
    slow = Problem(m).choices
    assert got == [(slow.cells(x, False), slow.cells(x, True)) for x in masks]


def _widest_per_image_by_hand(lo, hi, imgs):
    """Per image the cell of the largest width (in whole 1e-9 deg), then the smallest
    representative rotation in [0, 360) (its middle), the first of equals; widest first, then
    the smaller rotation."""
    best = {}
    for a, z, img in zip(lo, hi, imgs, strict=True):
        key = (-round((z - a) * 1e9), norm360((a + z) / 2.0))
        if img not in best or key < best[img][0]:
            best[img] = (key, (a, z, img))
    return [cell for _key, cell in sorted(best.values(), key=lambda e: e[0])]


def test_the_widest_cell_of_each_image_by_array_sorts():
    # choices._widest_cells against a loop over the cells: widths that tie (and differ by
    # less than the width quantum), middles past 360 and just below it, repeated images.
    rng = random.Random(5)
    for _ in range(3000):
        step = rng.choice([0.5, 1.0, 5.0, 30.0])
        start = rng.choice([0.0, -0.5, 359.5, 360.0 - 5e-13, rng.uniform(0.0, 360.0)])
        jitter = [0.0, 0.0, 3e-10, -3e-10, 6e-10]
        pts = sorted(
            {start + step * rng.randrange(int(360 / step)) + rng.choice(jitter) for _ in range(12)}
        )
        lo = np.array(pts)
        hi = np.append(lo[1:], lo[0] + 360.0)
        imgs = [rng.randint(1, rng.randint(1, 5)) for _ in pts]
        want = _widest_per_image_by_hand(lo.tolist(), hi.tolist(), imgs)
        assert _widest_cells(lo, hi, imgs) == want
    assert _widest_cells(np.array([]), np.array([]), []) == []


@pytest.mark.parametrize("rotation_error", [0.0, 1.0])
def test_the_cell_at_a_rotation_is_the_fixed_cell_holding_it(rotation_error):
    # Choices.cell_at finds a set's cell around a rotation from the members' boundaries
    # alone (Refiner.follow's subsets); it must be the very cell of the set's cell table.
    unc = IDEAL if rotation_error == 0.0 else Uncertainty(rotation_error_deg=rotation_error)
    m = build_machine(small_mix(8), ToleranceSensor(1.0), unc)
    choices = Problem(m).choices
    rng = random.Random(6)
    for _ in range(600):
        mask = rng.getrandbits(m.n) or 1
        lo, hi, img = rng.choice(choices.fixed_cells(mask))
        x = lo + rng.uniform(0.01, 0.99) * (hi - lo)
        assert choices.cell_at(mask, x % 360.0) == (lo, hi, img)
    # On a member's boundary there is no cell to hold it.
    assert choices.cell_at((1 << m.n) - 1, m.starts[0][0]) is None


def test_open_probabilities_from_neighbours_are_the_whole_images():
    # Readings.open_probability works per (previous, state, next) triple; the sensor's
    # closed form over the whole image must give the same floats.
    m = by_diameter(build_machine(small_mix(6), ToleranceSensor(1.5), IDEAL))[0]
    problem = Problem(m)
    readings = problem.readings
    sensor = m.sensor
    rng = random.Random(4)
    checked = 0
    for _ in range(300):
        image = rng.getrandbits(m.n) & rng.getrandbits(m.n) or 1 << rng.randrange(m.n)
        got = readings.open_probability(image)
        idx = members(image)
        if any(problem.insep[i] & image for i in idx):
            assert got is None
            continue
        whole = sensor.shared_reading_probability([m.states[i].sensed for i in idx])
        assert got == dict(zip(idx, whole, strict=True))
        checked += 1
    assert checked > 100


def _fewest_expected(problem, mask, masses, k, floor, memo) -> float:
    """The fewest expected operations within ``k`` keeping ``floor``: every action, every
    branch set, the margins by the max-min recursion (no feasibility probes)."""
    if problem.is_goal(mask):
        return 0.0
    if k <= 0:
        return math.inf
    best = math.inf
    for act in problem.choices.exact_actions(mask):
        if act.action.margin < floor:
            continue
        if any(_max_min(problem, c, k - 1, memo) < floor for c in act.children):
            continue
        val = 1.0
        for b, pb, ms in child_masses(problem, mask, masses, act):
            if pb > 0.0:
                val += pb * _fewest_expected(problem, b.mask, ms, k - 1, floor, memo)
        best = min(best, val)
    return best


DEEPER = [("6-part mix at 3 mm", build_machine(small_mix(6), ToleranceSensor(3.0), IDEAL))]
"""Root branches of three further operations: the expected stage recurses below its
two-operation shortcut."""


@pytest.mark.parametrize(
    ("name", "machine"), MACHINES + DEEPER, ids=[n for n, _ in MACHINES + DEEPER]
)
def test_the_expected_stage_is_the_fewest_expected_operations_keeping_the_floor(name, machine):
    refiner, every, k = _proven(machine)
    refiner.floor = refiner.largest_floor(every, k)
    problem = refiner.p
    start = tuple(s.weight for s in problem.machine.states)
    branches = tuple(problem.readings.branches(problem.full))
    children = child_masses(problem, problem.full, start, None, branches)
    # The branches that need every operation (the deepest searches), at most four of them.
    deep = [c for c in children if not refiner.w.within(c[0].mask, k - 1)][:4]
    assert deep
    memo: dict = {}
    for b, _pb, ms in deep:
        want = _fewest_expected(problem, b.mask, ms, k, refiner.floor, memo)
        assert refiner.expected(b.mask, ms, k)[0][0] == pytest.approx(want, abs=1e-9), name


def test_a_command_says_when_the_choice_among_shortest_plans_was_cut(monkeypatch):
    # make_plan warns when the tie-breaks stopped early: before the largest margin (the
    # plan may hold less rotation error than another of the same length) or after it.
    from feederkit.plans.make import make_plan

    pfs = small_mix(5)
    options = PlanningOptions(time_limit_s=60.0)
    exact = make_plan(pfs, ToleranceSensor(2.0), options, uncertainty=IDEAL)
    assert not any("choice among shortest plans" in w for w in exact.warnings)
    monkeypatch.setattr(api, "TIE_GRACE_POLLS", -1)
    monkeypatch.setattr(api, "TIE_SHARE", 0.0)
    quick = make_plan(pfs, ToleranceSensor(2.0), options, uncertainty=IDEAL)
    assert quick.result.tie_breaks == TIES_NONE
    (line,) = [w for w in quick.warnings if "choice among shortest plans" in w]
    assert "not proven the largest" in line and "\n" not in line
    # The tie-breaking budget cut it, not the clock: more time would not help.
    assert quick.result.ties_cut_by == "work"
    assert "more time does not change it" in line and "--time-limit" not in line
    monkeypatch.undo()

    def out_of_time(self, *args, **kwargs):
        raise Timeout("time")

    monkeypatch.setattr(Refiner, "expected", out_of_time)
    partial = make_plan(pfs, ToleranceSensor(2.0), options, uncertainty=IDEAL)
    assert partial.result.tie_breaks == TIES_MARGIN
    assert partial.result.ties_cut_by == "time"
    (line,) = [w for w in partial.warnings if "choice among shortest plans" in w]
    assert "not the fewest expected operations" in line
    assert "allow more time with --time-limit S" in line
    assert exact.result.ties_cut_by is None


def test_the_backchaining_plan_is_no_tie_break_cut_short():
    # Readings that carry nothing: the backchaining chain is the answer, no warning.
    from feederkit.plans.make import make_plan

    pf = near_round(64, 0.01)  # 35 states, all reading alike at 3 %
    made = make_plan([pf], ToleranceSensor(0.03 * pf.part.size), uncertainty=IDEAL)
    assert made.result.tie_breaks == TIES_CHAIN
    assert not any("choice among shortest plans" in w for w in made.warnings)


def _calls_while_following(monkeypatch, name: str) -> list[bool]:
    """Per call of ``Refiner.<name>``, whether it came from inside ``Refiner.follow``."""
    calls: list[bool] = []
    following = [False]
    follow, method = Refiner.follow, getattr(Refiner, name)

    def watched(self, *args):
        was, following[0] = following[0], True
        try:
            return follow(self, *args)
        finally:
            following[0] = was

    def counted(self, *args):
        calls.append(following[0])
        return method(self, *args)

    monkeypatch.setattr(Refiner, "follow", watched)
    monkeypatch.setattr(Refiner, name, counted)
    return calls


@pytest.mark.parametrize(("count", "tolerance"), [(5, 2.0), (8, 1.0), (6, 3.0)])
def test_ties_cut_after_the_margin_follow_the_probes_plans_without_a_search(
    monkeypatch, count, tolerance
):
    # When the expected-operations stage runs out, the tree follows the plans the margin
    # probes found (Refiner.follow): a set inside one a probe decided takes that set's
    # rotation, with no new search (on a 240-state mix the search behind "the first allowed
    # action" took 118 of 192 CPU seconds and 8 GB). It keeps the largest margin and the
    # proven length, and it executes from every start (check_plan).
    machine = build_machine(small_mix(count), ToleranceSensor(tolerance), IDEAL)
    exact = api.plan(machine)

    def cut(self, *args):
        raise Timeout("time")

    searches = _calls_while_following(monkeypatch, "_keeping_plan")
    monkeypatch.setattr(Refiner, "expected", cut)
    fresh = build_machine(small_mix(count), ToleranceSensor(tolerance), IDEAL)
    got = api.plan(fresh)
    assert got.tie_breaks == TIES_MARGIN and got.optimal
    assert got.length == exact.length
    assert math.isclose(got.min_margin, exact.min_margin, rel_tol=0.0, abs_tol=1e-9)
    assert any(searches) is False and len(searches) > 0
    assert check_plan(got) <= got.length


@pytest.mark.parametrize(("count", "tolerance"), [(5, 2.0), (8, 1.0), (6, 3.0)])
def test_ties_cut_before_any_margin_follow_the_length_proofs_plans_without_a_search(
    monkeypatch, count, tolerance
):
    # When the margin stage runs out before its first probe, no probe recorded a plan: the
    # tree follows the length proof's (WorstCase.choice), a root branch the proof did not
    # prove (it is not maximal) that of a maximal one holding it, with no new search (on a
    # 98-state mix "the first allowed action" of every root branch took 105 CPU seconds,
    # the proof 9). It keeps the proven length and executes from every start.
    machine = build_machine(small_mix(count), ToleranceSensor(tolerance), IDEAL)
    exact = api.plan(machine)

    def cut(self, *args):
        raise Timeout("work")

    searched = _calls_while_following(monkeypatch, "choose_worst")
    monkeypatch.setattr(Refiner, "keeps", cut)
    got = api.plan(build_machine(small_mix(count), ToleranceSensor(tolerance), IDEAL))
    assert got.tie_breaks == TIES_NONE and got.optimal
    assert got.length == exact.length
    assert searched == []
    assert check_plan(got) <= got.length


@pytest.mark.parametrize(("count", "tolerance"), [(5, 2.0), (6, 3.0)])
def test_ties_cut_after_the_margin_under_uncertainty_give_a_verified_strong_plan(
    monkeypatch, count, tolerance
):
    # The same tree under a rotation error of 1 degree: make_plan verifies it for every
    # outcome before it is returned (a plan that fails raises).
    from feederkit.plans.make import make_plan

    pfs = small_mix(count)
    exact = make_plan(pfs, ToleranceSensor(tolerance), uncertainty=Uncertainty()).result

    def cut(self, *args):
        raise Timeout("time")

    monkeypatch.setattr(Refiner, "expected", cut)
    made = make_plan(pfs, ToleranceSensor(tolerance), uncertainty=Uncertainty())
    got = made.result
    assert got.tie_breaks == TIES_MARGIN and made.report.ok
    assert got.length == exact.length
    assert math.isclose(got.min_margin, exact.min_margin, rel_tol=0.0, abs_tol=1e-9)


def test_the_expected_stage_gets_its_own_share_of_the_tie_budget(monkeypatch):
    # The margin stage comes first; the expected-operations stage may poll at most
    # EXPECTED_SHARE times the proof's polls plus the grace, of what the margin stage left.
    seen: list[tuple[int, float]] = []

    class Recording(WorkBudget):
        def __init__(self, outer: Deadline, polls: float) -> None:
            super().__init__(outer, polls)
            seen.append((outer.polls, polls))

    monkeypatch.setattr(api, "WorkBudget", Recording)
    monkeypatch.setattr(api, "TIE_GRACE_POLLS", 5)
    monkeypatch.setattr(api, "TIE_SHARE", 1e6)
    monkeypatch.setattr(api, "EXPECTED_SHARE", 0.5)
    got = api.plan(build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL))
    (proof, whole), (_, share) = seen
    assert whole == 1e6 * proof + 5
    assert share == 0.5 * proof + 5
    assert got.tie_breaks == TIES_MARGIN  # 5 polls do not finish it
    assert got.ties_cut_by == "work"
    assert check_plan(got) <= got.length


def test_the_expected_stages_budget_counts_the_bounds_it_computes(monkeypatch):
    # Its work is the bounds (a pass over a set's members per range), many per set: polled
    # once per set only, a budget of polls let it compute any number of them.
    budgets: list[WorkBudget] = []

    class Recording(WorkBudget):
        def __init__(self, outer: Deadline, polls: float) -> None:
            super().__init__(outer, polls)
            budgets.append(self)

    bounds = []
    real = Refiner._open_mass

    def counted(self, *args):
        bounds.append(self.deadline)
        return real(self, *args)

    monkeypatch.setattr(api, "WorkBudget", Recording)
    monkeypatch.setattr(Refiner, "_open_mass", counted)
    monkeypatch.setattr(refine, "BOUNDS_PER_POLL", 1)
    got = api.plan(build_machine(small_mix(8), ToleranceSensor(2.0), IDEAL))
    assert got.tie_breaks == TIES_EXACT
    expected_stage = budgets[-1]
    made = sum(1 for d in bounds if d is expected_stage)
    assert made > 100
    assert expected_stage.polls >= made  # a poll per bound, and one per set besides


def test_root_branches_chosen_before_the_expected_stage_ran_out_keep_their_subtrees(
    monkeypatch,
):
    # The expected stage builds the tree one root branch after the other; when it runs out,
    # the branches already built keep their subtrees and the rest follow the margin probes.
    machine = build_machine(small_mix(6), ToleranceSensor(3.0), IDEAL)
    exact = api.plan(machine)
    followed = _cut_after(monkeypatch, 0)
    # The first root branch whose probe-followed subtree is not the expected stage's.
    first = next(
        i
        for i, (b, c) in enumerate(exact.root.branches)
        if not isinstance(c, Leaf) and followed.root.branches[i] != (b, c)
    )
    partial = _cut_after(monkeypatch, first + 1)
    for got in (followed, partial):
        assert got.tie_breaks == TIES_MARGIN and got.optimal
        assert got.length == exact.length
        assert math.isclose(got.min_margin, exact.min_margin, rel_tol=0.0, abs_tol=1e-9)
        assert check_plan(got) <= got.length
    assert partial.root.branches[: first + 1] == exact.root.branches[: first + 1]
    assert exact.expected_length <= partial.expected_length + 1e-9
    assert partial.expected_length < followed.expected_length - 1e-9


def _cut_after(monkeypatch, roots: int):
    """The plan of the 6-part mix at 3 mm whose expected stage builds the subtrees of
    ``roots`` root branches, then runs out."""
    with monkeypatch.context() as m:
        _run_out_after(m, roots)
        return api.plan(build_machine(small_mix(6), ToleranceSensor(3.0), IDEAL))


def _run_out_after(patch, roots: int) -> None:
    """Make the expected stage's tree builder run out after ``roots`` root branches."""
    build = Refiner.build
    left, depth = [roots], [0]

    def counted(self, *args):
        if depth[0] == 0:
            if left[0] <= 0:
                raise Timeout("time")
            left[0] -= 1
        depth[0] += 1
        try:
            return build(self, *args)
        finally:
            depth[0] -= 1

    patch.setattr(Refiner, "build", counted)


def test_the_expected_objective_cut_short_is_not_optimal(monkeypatch):
    # Only the worst objective keeps the root branches its last stage built: a plan of the
    # expected objective cut short is the shortest tree, and not claimed optimal.
    machine = build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL)
    best = api.plan(machine, PlanningOptions(objective="expected"))
    assert best.optimal

    def cut(self, *args):
        raise Timeout("time")

    monkeypatch.setattr(Refiner, "expected", cut)
    got = api.plan(
        build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL),
        PlanningOptions(objective="expected"),
    )
    assert not got.optimal and got.tie_breaks == TIES_NONE
    assert check_plan(got) <= got.length


def test_root_branches_kept_under_uncertainty_give_a_verified_strong_plan(monkeypatch):
    # The same partial tree under a rotation error of 1 degree: make_plan verifies it for
    # every outcome before it is returned (a plan that fails raises).
    from feederkit.plans.make import make_plan

    pfs = small_mix(6)
    exact = make_plan(pfs, ToleranceSensor(3.0), uncertainty=Uncertainty()).result
    _run_out_after(monkeypatch, 2)
    made = make_plan(pfs, ToleranceSensor(3.0), uncertainty=Uncertainty())
    got = made.result
    assert got.tie_breaks == TIES_MARGIN and made.report.ok
    assert got.length == exact.length
    assert math.isclose(got.min_margin, exact.min_margin, rel_tol=0.0, abs_tol=1e-9)
