"""The widening beams (``feederkit.planning.beam``) against the independent exhaustive planner
of test_planners_bruteforce: every plan they find is a plan (run from every start and every
reading), never shorter than the optimum, and widened to the end they reach it."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from test_planners import check_plan
from test_planners_bruteforce import Degenerate, OwnPart, own_length, polygon

from feederkit.machine import PushAlignMachine, build_machine
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning import api, fallback
from feederkit.planning.andor import WorstCase
from feederkit.planning.api import _result, goal_relation, plan
from feederkit.planning.beam import (
    SMALL_SET,
    BeamSearch,
    _depth,
    _lengths,
    beam_plan,
    branch_key,
)
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.fallback import _choice_plan
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.stats import tree_length
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL


def _problem(machine):
    problem = Problem(machine, "exact", 0.0, goal_relation(machine, Deadline()))
    branches = problem.readings.branches(problem.full)
    roots = sorted(maximal_sets(sorted({b.mask for b in branches})))
    return problem, branches, roots


def _case(seed: int, n: int, rel: float):
    pts, com = polygon(seed, n)
    own = OwnPart(pts, com)
    assume(own.ok and own.n >= 2)
    size = max(max(p[i] for p in pts) - min(p[i] for p in pts) for i in (0, 1))
    tol = rel * size
    assume(min(abs(abs(a - b) - 2 * tol) for a in own.diam for b in own.diam) > 1e-6 * size)
    try:
        optimum = own_length(own, tol)
    except Degenerate:
        assume(False)
    pf = push_function(make_part(make_outline("random", pts), com))
    return build_machine([pf], ToleranceSensor(tol), uncertainty=IDEAL), optimum


@settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(st.integers(0, 10**9), st.integers(3, 10), st.floats(0.002, 0.08))
def test_the_first_beam_plan_is_a_plan_and_widening_reaches_the_optimum(seed, n, rel):
    machine, optimum = _case(seed, n, rel)
    problem, branches, roots = _problem(machine)
    # One narrow beam (one action per set, which may find none), stopped at its first plan:
    # a plan, never shorter than the optimum.
    first = BeamSearch(problem, 1)
    cap = 2 * machine.n + 1
    lengths = [next((k for k in range(1, cap + 1) if first.within(r, k)), None) for r in roots]
    if None not in lengths:
        root = _choice_plan(problem, first.choice, roots, branches, Deadline())
        result = _result(machine, root, False, None, 1, "worst", "exact")
        assert check_plan(result) == result.length <= 1 + max(lengths)
        assert result.length >= optimum
    # Widened until a beam is exhaustive: the optimum, and its tree has that length.
    found = beam_plan(problem, roots, None, Deadline(), cap)
    assert found is not None
    search, best = found
    assert 1 + best == optimum
    root = _choice_plan(problem, search.choice, roots, branches, Deadline())
    assert check_plan(_result(machine, root, False, None, 1, "worst", "exact")) == optimum
    # One node per witness: every set below the root follows a chosen set's own subplan.
    assert _distinct_steps(root) - 1 <= len(search.choice)


def _distinct_steps(root) -> int:
    """The distinct operations of a plan (each shared node once)."""
    seen, stack = set(), [root]
    while stack:
        node = stack.pop()
        if id(node) in seen or not hasattr(node, "branches"):
            continue
        seen.add(id(node))
        stack.extend(sub for _b, sub in node.branches)
    return len(seen)


def _random_part_machine(seed: int = 3, n: int = 10, rel: float = 0.08):
    pts, com = polygon(seed, n)
    pf = push_function(make_part(make_outline("random", pts), com))
    return build_machine([pf], ToleranceSensor(rel * pf.part.size), uncertainty=IDEAL)


def test_a_cheap_failure_probes_the_beam_twice_as_wide_at_the_same_target(monkeypatch):
    """Width 4 has no plan within 3 for this part, width 8 has one: with the bound at 3 the
    first plan is found there, not at a deeper target of the narrow beam; without polls for
    the probe the target grows as before."""
    from feederkit.planning import beam as beam_module

    machine = _random_part_machine(seed=61, n=14, rel=0.2)
    problem, branches, roots = _problem(machine)
    assert _lengths(BeamSearch(problem, 4, Deadline()), roots, 3) is None
    assert max(_lengths(BeamSearch(problem, 8, Deadline()), roots, 3)) == 3
    calls = []
    real = beam_module._lengths

    def spy(beam, roots_, target):
        out = real(beam, roots_, target)
        calls.append((beam.width, target, None if out is None else max(out)))
        return out

    monkeypatch.setattr(beam_module, "_lengths", spy)
    found = beam_plan(problem, roots, None, Deadline(), 2 * machine.n + 1, 3)
    assert calls == [(4, 3, None), (8, 3, 3)] and found[1] == 3
    root = _choice_plan(problem, found[0].choice, roots, branches, Deadline())
    assert check_plan(_result(machine, root, False, None, 1, "worst", "exact")) == 4
    calls.clear()
    monkeypatch.setattr(beam_module, "PROBE_POLLS", 0)
    beam_plan(problem, roots, None, Deadline(), 2 * machine.n + 1, 3)
    # The probe stops at its first poll (not recorded: it raised): the narrow beam goes on.
    assert calls[:2] == [(4, 3, None), (4, 4, 4)]


def _kept(problem, mask, width):
    """What a beam of ``width`` keeps of a set's actions: the ``width`` with the smallest
    branches (ties in the length view's order), every one of a small set."""
    every = problem.choices.actions(mask)
    return list(every) if mask.bit_count() <= SMALL_SET else sorted(every, key=branch_key)[:width]


def test_the_beam_keeps_the_actions_with_the_smallest_branches():
    problem, _branches, roots = _problem(_random_part_machine(seed=61, n=14, rel=0.2))
    mask = max(roots, key=int.bit_count)
    assert not problem.is_goal(mask) and mask.bit_count() > SMALL_SET
    every = problem.choices.actions(mask)
    beam = BeamSearch(problem, 2)
    kept = list(beam.actions_of(mask))
    assert len(kept) == min(2, len(every))
    assert [branch_key(a) for a in kept] == sorted(branch_key(a) for a in every)[: len(kept)]
    # The very actions of the length view, ties in its order, made from the cells alone.
    assert kept == _kept(problem, mask, 2)
    assert beam.cut == (len(every) > 2)


def _chains_machine() -> PushAlignMachine:
    """Two states 0 and 1 that one narrow range sends to a pair merged by the next action,
    and four wide ranges to pairs of four chains, each three pairs long before it merges (no
    sensor, the ideal model)."""
    from feederkit.angles import ActionRange
    from feederkit.machine import MachineState

    bounds = [(0.0, 80.0), (80.0, 160.0), (160.0, 240.0), (240.0, 320.0), (320.0, 360.0)]
    n = 4 + 4 * 6
    targets = [[0] * 5 for _ in range(n)]
    targets[0] = [4, 10, 16, 22, 2]  # the chains' first pairs, then the pair {2, 3}
    targets[1] = [5, 11, 17, 23, 3]
    targets[2] = targets[3] = [2] * 5
    for c in range(4):
        for k in range(3):
            a = 4 + 6 * c + 2 * k
            nxt = a + 2 if k < 2 else a  # the last pair of a chain merges into its first state
            targets[a] = [nxt] * 5
            targets[a + 1] = [nxt + 1 if k < 2 else a] * 5
    states = tuple(MachineState(0, i, 1.0, 1.0 / n) for i in range(n))
    maps = tuple(
        tuple(ActionRange(lo, hi, t) for (lo, hi), t in zip(bounds, row, strict=True))
        for row in targets
    )
    return PushAlignMachine(("chains",), states, maps, NoSensor())


def test_a_small_set_keeps_every_action_in_a_beam():
    # The pair's five actions all leave one pair, so the beam's order keeps the four widest,
    # the chains (four operations in all); only the narrow one orients it in two. A beam of
    # four that kept only the widest would find no plan within three operations.
    machine = _chains_machine()
    problem = Problem(machine, "exact", 0.0, goal_relation(machine, Deadline()))
    pair = 0b11
    assert WorstCase(problem).length(pair) == 2
    beam = BeamSearch(problem, 4)
    assert len(list(beam.actions_of(pair))) == 5 and not beam.cut
    assert beam.within(pair, 2)


def _chain_pair_machine(k: int, outcome_sets: bool) -> PushAlignMachine:
    """A pair {0, 1} that every rotation moves along a chain of ``k`` pairs, the last
    merging into one state that reads apart from the rest (so no set is quiet): its exact
    length is ``k``. ``outcome_sets``: under uncertainty (outcome sets)."""
    from feederkit.angles import ActionRange
    from feederkit.machine import MachineState, OutcomeRange

    n = 2 * k + 1
    bounds = [(0.0, 120.0), (120.0, 240.0), (240.0, 360.0)]
    targets = [2 * (i // 2 + 1) + i % 2 if i // 2 < k - 1 else n - 1 for i in range(n - 1)]
    targets.append(n - 1)
    states = tuple(MachineState(0, i, 10.0 if i < n - 1 else 20.0, 1.0 / n) for i in range(n))
    # Under uncertainty the first state of a pair may end in either state of the next pair:
    # the pair's image, and so its length, stay the same.
    wide = [
        (1 << t) | (1 << (t + 1)) if i % 2 == 0 and t < n - 1 else 1 << t
        for i, t in enumerate(targets)
    ]
    maps = tuple(
        tuple(
            OutcomeRange(lo, hi, wide[i]) if outcome_sets else ActionRange(lo, hi, t)
            for lo, hi in bounds
        )
        for i, t in enumerate(targets)
    )
    return PushAlignMachine(("chain",), states, maps, ToleranceSensor(1.0))


def test_a_small_set_with_no_plan_fails_a_deep_target_at_small_depth():
    # Under uncertainty, two pairs each rotation swaps, never merged (no inseparable
    # states): asked within 60 operations the beam tries them within SMALL_DEPTH only and
    # then takes them to have none (and is no longer exhaustive), instead of asking at every
    # budget down from 60. On the ideal model, and under uncertainty for a pair whose one
    # plan is longer than SMALL_DEPTH but proven so, a deep pair still gets its plan.
    from feederkit.machine import MachineState, OutcomeRange
    from feederkit.planning import beam as beam_module

    bounds = [(0.0, 120.0), (120.0, 240.0), (240.0, 360.0)]
    # Each pair goes to the other (state 0 to either state of the pair {2, 3} at first).
    targets = [[0b1100, 0b1000, 0b0100], [0b1000, 0b0100, 0b1000], [1, 2, 2], [2, 1, 1]]
    states = tuple(MachineState(0, i, 1.0, 0.25) for i in range(4))
    maps = tuple(
        tuple(OutcomeRange(lo, hi, t) for (lo, hi), t in zip(bounds, row, strict=True))
        for row in targets
    )
    machine = PushAlignMachine(("swaps",), states, maps, NoSensor())
    assert not machine.deterministic
    problem = Problem(machine, "exact", 0.0, (0,) * 4)
    polls = {}
    for depth in (beam_module.SMALL_DEPTH, 100):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(beam_module, "SMALL_DEPTH", depth)
            beam = BeamSearch(problem, 4, Deadline())
            beam._quiet = None  # no shortest-path shortcut: the AND/OR search meets the pair
            assert not beam.within(0b0011, 60)
            polls[depth] = beam.deadline.polls
            assert (0b0011 in beam.never) == beam.gave_up == (depth < 60)
    assert polls[beam_module.SMALL_DEPTH] * 3 < polls[100]
    chains = _chains_machine()
    solvable = Problem(chains, "exact", 0.0, goal_relation(chains, Deadline()))
    beam = BeamSearch(solvable, 4)
    assert beam.within(0b11, 60) and 0b11 not in beam.never
    k = beam_module.SMALL_DEPTH + 1
    ideal = _chain_pair_machine(k, outcome_sets=False)
    assert ideal.deterministic
    problem = Problem(ideal, "exact", 0.0, goal_relation(ideal, Deadline()))
    assert not problem.carries_no_information(0b11)
    assert WorstCase(problem).length(0b11) == k
    found = beam_plan(problem, [0b11], None, Deadline(), 2 * k)
    assert found is not None and found[1] == k
    uncertain = _chain_pair_machine(k, outcome_sets=True)
    assert not uncertain.deterministic
    problem = Problem(uncertain, "exact", 0.0, goal_relation(uncertain, Deadline()))
    exact = WorstCase(problem)
    assert not exact.within(0b11, k - 1) and 0b11 not in exact.ub  # a bound, no plan
    found = beam_plan(problem, [0b11], exact, Deadline(), 2 * k)  # seeded with the bound
    assert found is not None and found[1] == k


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10**6), st.integers(6, 12), st.floats(0.005, 0.1))
def test_the_beams_ranking_keeps_what_sorting_every_action_keeps(seed, n, rel):
    machine = _random_part_machine(seed, n, rel)
    problem, _branches, roots = _problem(machine)
    for width in (1, 3, 8):
        beam = BeamSearch(problem, width)
        for mask in roots:
            if problem.is_goal(mask):
                continue
            assert list(beam.actions_of(mask)) == _kept(problem, mask, width)


def test_until_a_plan_the_beams_deepen_by_growing_steps(monkeypatch):
    # Before the first plan the targets are the bound, then 1, 2, 4, ... more than the last,
    # each cheap failure of the first width followed by one probe twice as wide at the same
    # target; after it each target is one less than the best plan so far; a plan found
    # within a target is never longer than it, and its tree is as long as the lengths say.
    from feederkit.planning import beam as beam_module

    machine = _random_part_machine(seed=1, n=10, rel=0.2)  # a plan of 6 in the first beam
    problem, branches, roots = _problem(machine)
    calls = []
    real = beam_module._lengths

    def spy(beam, roots_, target):
        out = real(beam, roots_, target)
        calls.append((target, out, beam.width))
        return out

    monkeypatch.setattr(beam_module, "_lengths", spy)
    found = beam_plan(problem, roots, None, Deadline(), 2 * machine.n + 1)
    assert found is not None
    firsts = [(w, t) for t, _out, w in calls[: next(i for i, c in enumerate(calls) if c[1]) + 1]]
    w = beam_module.FIRST_WIDTH
    assert firsts == [(w, 1), (2 * w, 1), (w, 2), (2 * w, 2), (w, 4), (2 * w, 4), (w, 8)]
    best = None
    for target, out, _width in calls:
        if best is not None:
            assert target <= best - 1
        if out is not None:
            assert max(out) <= target
            best = max(out)
    assert found[1] == best
    root = _choice_plan(problem, found[0].choice, roots, branches, Deadline())
    assert tree_length(root) <= 1 + best
    assert check_plan(_result(machine, root, False, None, 1, "worst", "exact")) == tree_length(root)


def test_with_a_plan_in_hand_the_beams_start_just_below_it(monkeypatch):
    # A plan of cap + 1 in hand: the first target is the cap itself, then one less than the
    # best so far, never a target from the bound up (there a short target can fail only
    # after a long search, on the random 1000-point outline at 0.9 %).
    from feederkit.planning import beam as beam_module

    machine = _random_part_machine(seed=1, n=10, rel=0.2)
    problem, branches, roots = _problem(machine)
    cap = 12
    calls = []
    real = beam_module._lengths

    def spy(beam, roots_, target):
        out = real(beam, roots_, target)
        calls.append((target, out))
        return out

    monkeypatch.setattr(beam_module, "_lengths", spy)
    found = beam_plan(problem, roots, None, Deadline(), cap, 1, None, in_hand=True)
    assert found is not None and calls[0][0] == cap and calls[0][1] is not None
    best = max(calls[0][1])
    for target, out in calls[1:]:
        assert target <= best - 1
        if out is not None:
            best = max(out)
    assert found[1] == best
    root = _choice_plan(problem, found[0].choice, roots, branches, Deadline())
    assert check_plan(_result(machine, root, False, None, 1, "worst", "exact")) == tree_length(root)


def test_a_shallow_target_that_fails_slowly_leaves_time_for_the_deep_one(monkeypatch):
    # Until a first plan, a target below the cap gets SHALLOW_SHARE of the time left: here
    # every shallow search would run until its deadline, and the plan within the cap is
    # still found (without the share the first shallow target took the whole limit).
    import time

    from feederkit.planning import beam as beam_module

    machine = _random_part_machine(seed=1, n=10, rel=0.2)
    problem, branches, roots = _problem(machine)
    cap = 2 * machine.n + 1
    real = beam_module._lengths
    seen = []

    def slow_below_cap(beam, roots_, target):
        seen.append(target)
        if target < cap:
            while True:  # a search that fails only when its deadline stops it
                beam.deadline.check()
                time.sleep(0.005)
        return real(beam, roots_, target)

    monkeypatch.setattr(beam_module, "_lengths", slow_below_cap)
    found = beam_plan(problem, roots, None, Deadline(2.0), cap)
    assert found is not None and seen[0] < cap and cap in seen
    root = _choice_plan(problem, found[0].choice, roots, branches, Deadline())
    assert check_plan(_result(machine, root, False, None, 1, "worst", "exact")) == tree_length(root)


def test_a_passed_deadline_leaves_no_beam_plan():
    machine = _random_part_machine()
    problem, _branches, roots = _problem(machine)
    assert not all(problem.is_goal(r) for r in roots)
    assert beam_plan(problem, roots, None, Deadline(0.0), 2 * machine.n + 1) is None


def test_a_first_plan_may_take_until_its_own_deadline():
    # The beams' deadline has passed, the first plan's has not: one plan, and no search for
    # a shorter one (what a later deadline for the first plan alone allows).
    machine = _random_part_machine()
    problem, branches, roots = _problem(machine)
    cap = 2 * machine.n + 1
    found = beam_plan(problem, roots, None, Deadline(0.0), cap, 1, Deadline())
    assert found is not None
    search, best = found
    # The first beam's plan, found depth-first within the cap, not a shorter one.
    first = BeamSearch(problem, 4)
    assert all(first.within(r, cap) for r in roots)
    assert best == max(_depth(first, r, {}) for r in roots)
    root = _choice_plan(problem, search.choice, roots, branches, Deadline())
    assert check_plan(_result(machine, root, False, None, 1, "worst", "exact")) == 1 + best


def test_a_first_plan_past_the_beams_deadline_is_shortened_by_the_same_beam(monkeypatch):
    # The beams' deadline has passed and the first plan's has a limit: the first plan (8
    # operations after the first alignment, at a target of 8) is shortened one operation at
    # a time by the same beam within DESCENT_SHARE of what is left (7, 6, 5; 4 fails), and no
    # wider beam is tried past the beams' own deadline. With no share for the descent, the
    # first plan is the answer.
    from feederkit.planning import beam as beam_module

    machine = _random_part_machine(seed=1, n=10, rel=0.2)
    problem, branches, roots = _problem(machine)
    cap = 2 * machine.n + 1
    calls = []
    real = beam_module._lengths

    def spy(beam, roots_, target):
        out = real(beam, roots_, target)
        calls.append((target, None if out is None else max(out), beam.width))
        return out

    monkeypatch.setattr(beam_module, "_lengths", spy)
    found = beam_plan(problem, roots, None, Deadline(0.0), cap, 1, Deadline(60.0))
    first = next(i for i, c in enumerate(calls) if c[1] is not None)
    width = calls[first][2]
    assert calls[first][1] == 8
    assert [(t, n) for t, n, _w in calls[first + 1 :]] == [(7, 7), (6, 6), (5, 5), (4, None)]
    assert all(w == width for _t, _n, w in calls[first + 1 :])
    assert found is not None and found[1] == 5
    root = _choice_plan(problem, found[0].choice, roots, branches, Deadline())
    assert check_plan(_result(machine, root, False, None, 1, "worst", "exact")) == tree_length(root)
    assert tree_length(root) <= 1 + 5

    calls.clear()
    monkeypatch.setattr(beam_module, "DESCENT_SHARE", 0.0)
    found = beam_plan(problem, roots, None, Deadline(0.0), cap, 1, Deadline(60.0))
    assert found is not None and found[1] == 8


def test_with_a_plan_in_hand_a_wider_beam_gets_the_beams_own_deadline(monkeypatch):
    # The first plan comes well before the beams' deadline and the descent's is later still:
    # the shorter targets run under the descent's, but a wider beam tried after one fails
    # runs under the beams' own deadline, not past it.
    from feederkit.planning import beam as beam_module

    machine = _random_part_machine(seed=1, n=10, rel=0.2)
    problem, _branches, roots = _problem(machine)
    made = []
    found_at = []
    real_beam, real_lengths = beam_module._beam, beam_module._lengths

    def beam_spy(problem_, width, deadline_, seed, last):
        made.append((width, deadline_, bool(found_at)))
        return real_beam(problem_, width, deadline_, seed, last)

    def lengths_spy(beam, roots_, target):
        out = real_lengths(beam, roots_, target)
        if out is not None and not found_at:
            found_at.append(beam.width)
        return out

    monkeypatch.setattr(beam_module, "_beam", beam_spy)
    monkeypatch.setattr(beam_module, "_lengths", lengths_spy)
    own = Deadline(30.0)
    found = beam_plan(problem, roots, None, own, 2 * machine.n + 1, 1, Deadline(600.0))
    assert found is not None
    after = [(w, d) for w, d, late in made if late]
    assert after  # some wider beam was tried with the plan in hand
    assert all(d is own for _w, d in after)


def test_the_descent_takes_its_share_of_the_first_plans_deadline():
    import time

    from feederkit.planning.beam import DESCENT_SHARE, _descent

    passed = Deadline(0.0)
    assert _descent(passed, None) is passed
    assert _descent(passed, Deadline()) is passed  # no limit to take a share of
    later = Deadline(10.0)
    late = _descent(passed, later)
    expected = time.perf_counter() + DESCENT_SHARE * 10.0
    assert late.end is not None and abs(late.end - expected) < 0.5
    roomy = Deadline(100.0)
    assert _descent(roomy, later) is roomy  # the beams' own deadline is later still
    # A first plan near the beams' deadline: the descent still takes its share.
    near = _descent(Deadline(1.0), Deadline(60.0))
    expected = time.perf_counter() + DESCENT_SHARE * 60.0
    assert near.end is not None and abs(near.end - expected) < 0.5


def test_when_the_exact_search_runs_out_the_fallback_answers_with_a_beam_plan(monkeypatch):
    machine = _random_part_machine()
    exact = plan(machine)
    assert exact.length > 2

    def out_of_time(*_args, **_kwargs):
        raise Timeout("time")

    monkeypatch.setattr(api, "longest_root", out_of_time)
    # Without the backchaining plans and the pairs told apart one at a time (the plan that
    # follows the readings is often as short as the beams can find), the beams give the plan.
    for maker in ("sensorless_plan", "pairwise_plan"):
        monkeypatch.setattr(fallback, maker, lambda *_args, **_kwargs: None)
    calls = []
    real = fallback.beam_plan

    def spy(*args, **kwargs):
        out = real(*args, **kwargs)
        calls.append(out)
        return out

    monkeypatch.setattr(fallback, "beam_plan", spy)
    result = plan(machine, PlanningOptions(time_limit_s=60.0))
    assert calls and calls[0] is not None
    assert check_plan(result) == result.length >= exact.length
    assert result.lower_bound <= exact.length


def test_a_proven_length_whose_tree_ran_out_follows_the_proof_not_the_pairs(monkeypatch):
    # The exact search proves the length; every tree of the tie-breaks runs out. The
    # fallback's beams follow the proof's choices at once (a plan of the proven length);
    # the pairs told apart one at a time, a longer plan, are not made first.
    machine = _random_part_machine()
    exact = plan(machine)

    def no_tree(*_args, **_kwargs):
        raise Timeout("time")

    monkeypatch.setattr(api, "_build", no_tree)
    for maker in ("sensorless_plan", "sequential_plan"):  # no plan in hand before them
        monkeypatch.setattr(fallback, maker, lambda *_args, **_kwargs: None)
    made = []
    real = fallback.pairwise_plan

    def pairs(*args, **kwargs):
        made.append(True)
        return real(*args, **kwargs)

    monkeypatch.setattr(fallback, "pairwise_plan", pairs)
    result = plan(machine, PlanningOptions(time_limit_s=60.0))
    assert not made
    assert check_plan(result) == result.length == exact.length
    # Without the proof (the length search out of time at once), they are made first.
    monkeypatch.setattr(api, "longest_root", no_tree)
    other = plan(machine, PlanningOptions(time_limit_s=60.0))
    assert made and check_plan(other) == other.length >= exact.length


@pytest.mark.slow
def test_a_mix_the_exact_search_cannot_finish_gets_a_verified_plan(monkeypatch):
    # 20 random 6-10-gons at 5 % of 60 mm under 1 degree: the exact search proves a bound
    # of 5 but finds no plan in 60 s; before the beams the command answered with none. Here
    # the exact search under uncertainty is made to run out at once (how far it gets in a
    # share of the limit depends on the machine's load), so the fallback has the time.
    from pathlib import Path

    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from bench_planners import mix

    from feederkit.plans.make import make_plan
    from feederkit.uncertainty import Uncertainty

    real = api.longest_root

    def exact_runs_out(problem, *args, **kwargs):
        if not problem.machine.deterministic:
            raise Timeout("time")
        return real(problem, *args, **kwargs)

    monkeypatch.setattr(api, "longest_root", exact_runs_out)
    pfs = mix(20)
    sensor = ToleranceSensor(0.05 * max(pf.part.size for pf in pfs))
    made = make_plan(pfs, sensor, PlanningOptions(time_limit_s=40.0), uncertainty=Uncertainty())
    assert made.report.ok
    result = made.result
    assert result.lower_bound <= result.length <= 10  # 8 against 6 on the benchmark machine
    assert tree_length(result.root) == result.length


def test_a_plan_the_beams_found_but_could_not_build_proves_one_exists(monkeypatch):
    # Under uncertainty, with no plan in hand, the fallback asks whether any strong plan
    # exists (solvable.unsolvable_by_pairs, up to half the time left): not when the beams
    # found one whose tree ran out of time (the 50-part mix at 5 % under 1 degree lost 4.9 s
    # of 60 to it); the searches after them look for a shorter plan, and the answer says
    # one was found.
    from feederkit.planning.options import OutOfBudget
    from feederkit.uncertainty import Uncertainty

    pts, com = polygon(3, 10)
    pf = push_function(make_part(make_outline("random", pts), com))
    machine = build_machine([pf], ToleranceSensor(0.08 * pf.part.size), uncertainty=Uncertainty())
    assert not machine.deterministic

    def out_of_time(*_args, **_kwargs):
        raise Timeout("time")

    monkeypatch.setattr(api, "longest_root", out_of_time)
    for maker in ("sensorless_plan", "sequential_plan", "pairwise_plan"):
        monkeypatch.setattr(fallback, maker, lambda *_args, **_kwargs: None)
    builds: list[bool] = []

    def runs_out(*_args, **_kwargs):
        builds.append(True)
        raise Timeout("time")

    asked: list[bool] = []
    real_pairs = fallback.unsolvable_by_pairs

    def pairs(*args, **kwargs):
        asked.append(True)
        return real_pairs(*args, **kwargs)

    monkeypatch.setattr(fallback, "_choice_plan", runs_out)
    monkeypatch.setattr(fallback, "unsolvable_by_pairs", pairs)
    with pytest.raises(OutOfBudget, match="was found, but not built and verified in time"):
        plan(machine, PlanningOptions(time_limit_s=60.0))
    assert builds and not asked
