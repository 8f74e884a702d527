"""Sets inside sets the AND/OR search solved (``WorstCase.inside_solved``) and the plans that
follow them (``fallback._choice_plan``).

Without a margin floor a plan of a set orients every subset of it, so the length search and
the beams take a set inside a solved one as solved, with the larger set's action. Here the
lengths with that shortcut are checked against the same search without it, and a plan built
from a beam's choices that holds such actions is run from every start and reading: a
borrowed action's node is the smaller set's own (its own range and image), so every branch
of every node is taken by some state (the plan-file verifier rejects a result that nothing
reaches) and the tree is as long as its longest run.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shared import small_mix
from test_beam import _problem
from test_planners import check_plan
from test_quiet import _coarse

from feederkit.angles import norm360
from feederkit.machine import build_machine, successor
from feederkit.planning.andor import WorstCase
from feederkit.planning.api import _result
from feederkit.planning.beam import SMALL_DEPTH, SMALL_SET, BeamSearch, _lengths
from feederkit.planning.budget import Deadline
from feederkit.planning.fallback import _choice_plan
from feederkit.planning.quiet import QuietWorst
from feederkit.planning.tree import Leaf
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL


def _spied(search) -> list[int]:
    hits: list[int] = []
    real = search.inside_solved

    def spy(mask: int, k: int) -> bool:
        out = real(mask, k)
        if out:
            hits.append(mask)
        return out

    search.inside_solved = spy
    return hits


@settings(max_examples=25, deadline=None)
@given(count=st.integers(3, 9), seed=st.integers(0, 10**4), tol=st.sampled_from([1.0, 2.0, 3.0]))
def test_lengths_with_sets_inside_solved_ones_are_the_search_without(count, seed, tol):
    machine = build_machine(small_mix(count, seed), ToleranceSensor(tol), IDEAL)
    problem, _branches, roots = _problem(machine)
    with_index = WorstCase(problem)
    plain = WorstCase(problem)
    plain._solved = None
    for r in roots:
        assert with_index.length(r) == plain.length(r)


def _unreached(result) -> int:
    """How many (node, branch) pairs of the plan no start and reading takes (the ideal
    model, a tolerance sensor: a state takes a branch whose interval holds one of its
    readings)."""
    machine = result.machine
    e = machine.sensor.tolerance
    taken: set[tuple[int, int]] = set()
    every: set[tuple[int, int]] = set()
    seen: set[tuple[int, int]] = set()
    todo = [(result.root, s) for s in range(machine.n)]
    while todo:
        node, state = todo.pop()
        if isinstance(node, Leaf) or (id(node), state) in seen:
            continue
        seen.add((id(node), state))
        if node.action is not None:
            state = successor(machine, state, node.action.representative)
        d = machine.states[state].diameter
        for j, (b, sub) in enumerate(node.branches):
            every.add((id(node), j))
            if b.lo is None or max(b.lo, d - e) < min(b.hi, d + e):
                taken.add((id(node), j))
                todo.append((sub, state))
    return len(every - taken)


@pytest.mark.parametrize(("count", "tol", "width"), [(6, 3.0, 1), (8, 3.0, 1), (10, 3.0, 1)])
def test_a_beam_plan_through_borrowed_actions_takes_every_branch(count, tol, width):
    machine = build_machine(small_mix(count, 100), ToleranceSensor(tol), IDEAL)
    problem, branches, roots = _problem(machine)
    beam = BeamSearch(problem, width)
    hits = _spied(beam)
    lengths = next(x for t in range(1, 40) if (x := _lengths(beam, roots, t)) is not None)

    def moved_alike(mask: int) -> bool:
        sa = beam.choice[mask][1].action
        cell = problem.choices.cell_at(mask, norm360((sa.lo + sa.hi) / 2.0))
        return cell is not None and cell[2] == sa.image

    # Some set took a larger set's action whose image is larger than its own.
    assert any(not moved_alike(m) for m in hits)
    root = _choice_plan(problem, beam.choice, roots, branches, Deadline())
    result = _result(machine, root, False, None, 1, "worst", "exact")
    assert check_plan(result) == result.length <= 1 + max(lengths)
    assert _unreached(result) == 0
    assert _goals_going_on(problem, result.root) == 0  # an oriented branch ends in a leaf


def _goals_going_on(problem, root) -> int:
    """How many reading branches past the first alignment are goals (the reading orients
    the part) and yet go on with another operation."""
    seen: set[int] = set()
    todo = [root]
    out = 0
    while todo:
        node = todo.pop()
        if isinstance(node, Leaf) or id(node) in seen:
            continue
        seen.add(id(node))
        for b, sub in node.branches:
            if node.action is not None and problem.is_goal(b.mask) and not isinstance(sub, Leaf):
                out += 1
            todo.append(sub)
    return out


def test_a_quiet_search_borrows_no_action():
    # Its plans are chains (quiet.chain_plan) that follow each image's own action: no
    # entry of its choices is another set's.
    machine, _tol = _coarse(small_mix(3, 700))  # one reading fits every state
    problem, _branches, roots = _problem(machine)
    assert WorstCase(problem)._solved is not None
    worst = QuietWorst(problem)
    for r in roots:
        for k in range(1, 8):
            worst.within(r, k)
    assert worst.choice
    assert len({id(e) for e in worst.choice.values()}) == len(worst.choice)
    assert all(
        worst.p.choices.cell_at(m, norm360((e[1].action.lo + e[1].action.hi) / 2.0))[2]
        == e[1].action.image
        for m, e in worst.choice.items()
    )


def test_a_small_set_inside_a_solved_one_is_not_given_up_in_a_beam(monkeypatch):
    # Under uncertainty a beam takes a small set with no plan within SMALL_DEPTH to have
    # none; one inside a set solved within the budget is solved first.
    machine = build_machine(small_mix(4, 100), ToleranceSensor(3.0))
    assert not machine.deterministic
    problem, _branches, _roots = _problem(machine)
    beam = BeamSearch(problem, 4)
    big = next(m for m in problem.choices.cells(problem.full) if m[2].bit_count() > SMALL_SET)
    act = problem.choices.act(problem.full, big, exact=True)
    lender = big[2]
    beam.choice[lender] = (SMALL_DEPTH + 5, act)
    beam.ub[lender] = SMALL_DEPTH + 5
    beam._solved.add(lender)
    small = lender & -lender | (lender & (lender - 1)) & -(lender & (lender - 1))
    assert small.bit_count() == 2 and not problem.is_goal(small)
    monkeypatch.setattr(beam, "within", lambda mask, k: False)  # none within SMALL_DEPTH
    assert beam._known(small, SMALL_DEPTH + 5) is True
    assert small not in beam.never and not beam.gave_up
