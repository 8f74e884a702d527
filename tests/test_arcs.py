"""The arc search (feederkit.planning.arcs): exact chain lengths of several parts' sets whose
readings carry nothing, against the tests' own search over every rotation and reading."""

from __future__ import annotations

import random

import pytest
from shared import brute_lengths
from test_quiet import CASES, _coarse, _roots

from feederkit.planning import arcs
from feederkit.planning.andor import part_chains
from feederkit.planning.arcs import arc_space
from feederkit.planning.budget import Deadline, Timeout, WorkBudget
from feederkit.planning.problem import Problem
from feederkit.planning.quiet import QuietWorst


def _sets(machine, count: int, seed: str) -> list[int]:
    """The whole set and ``count`` random subsets of two or more states."""
    rng = random.Random(seed)
    out = [machine.all_states]
    while len(out) <= count:
        mask = rng.getrandbits(machine.n) & machine.all_states
        if mask.bit_count() >= 2:
            out.append(mask)
    return out


def _follow(worst: QuietWorst, mask: int) -> int:
    """The number of steps the recorded chain of ``mask`` takes to a goal (each step the
    chosen action's image, which must have a chosen action itself or be a goal)."""
    steps = 0
    while not worst.p.is_goal(mask):
        mask = worst.choice[mask][1].action.image
        steps += 1
    return steps


@pytest.mark.parametrize("name", CASES)
def test_the_arc_search_gives_every_sets_exact_length_and_a_chain_of_it(name):
    machine, tol = _coarse(CASES[name])
    problem = Problem(machine)
    assert arc_space(problem, part_chains(problem)) is not None  # it applies here
    exact, _children = brute_lengths(machine, tol)
    for mask in _sets(machine, 25, name):
        worst = QuietWorst(problem)
        got = worst.sensorless_length(mask)
        assert got == exact(mask), hex(mask)
        assert got == QuietWorst(problem, arcs=False).sensorless_length(mask)
        assert worst.arc_space() is not None  # its chain was followed on the machine
        if got:
            assert worst.exact[mask] == got and _follow(worst, mask) == got


@pytest.mark.parametrize("name", ["mix3-700", "mix3-300", "landings-8"])
def test_the_arc_search_within_a_cap_refutes_and_records_the_bound(name):
    machine, tol = _coarse(CASES[name])
    problem = Problem(machine)
    (root, *_), _branches = _roots(problem)
    exact, _children = brute_lengths(machine, tol)
    want = exact(root)
    worst = QuietWorst(problem)
    assert worst.sensorless_length(root, want - 1) == want  # cap + 1: more than the cap
    assert worst.lb[root] == want and root not in worst.exact
    assert not worst.within(root, want - 1) and worst.within(root, want)


def test_an_arc_search_cut_short_records_what_it_proved(monkeypatch):
    monkeypatch.setattr(arcs, "POLL_STATES", 1)
    machine, tol = _coarse(CASES["mix3-700"])
    problem = Problem(machine)
    (root,), _branches = _roots(problem)
    exact, _children = brute_lengths(machine, tol)
    recorded = []
    for polls in range(1, 40):
        worst = QuietWorst(problem, WorkBudget(Deadline(), polls))
        try:
            got = worst.length(root)
        except Timeout:
            recorded.append(worst.lb.get(root, 1))
            continue
        assert got == exact(root)
        break
    else:
        pytest.fail("the search never finished")
    assert recorded and all(b <= exact(root) for b in recorded)
    assert recorded == sorted(recorded)


def test_the_arc_search_does_not_apply_under_a_margin_floor():
    machine, _tol = _coarse(CASES["landings-8"])
    problem = Problem(machine)
    assert arc_space(problem, part_chains(problem)) is not None
    assert arc_space(problem.with_margin(0.5), part_chains(problem)) is None
    assert arc_space(problem, []) is None
