"""Sets inside solved sets (``feederkit.planning.solved``, ``WorstCase.inside_solved``).

Without a margin floor a plan of a set orients every subset of it, so the AND/OR search and
the beams take a set inside a set they solved within a budget as solved within it, with the
larger set's action. Here the index is checked against a plain scan, the exact search's
lengths (the shortcut taken) against the tests' own exhaustive search, the plans a beam
builds with it (the shortcut taken) by running them from every start, every outcome of a
1-degree rotation error and every reading, and a margin floor keeps no index.
"""

from __future__ import annotations

import random

from hypothesis import given, settings
from hypothesis import strategies as st
from shared import brute_lengths, small_mix
from test_beam import _problem

from feederkit.machine import build_machine, members
from feederkit.planning.andor import WorstCase
from feederkit.planning.beam import BeamSearch, _lengths
from feederkit.planning.budget import Deadline
from feederkit.planning.fallback import _choice_plan
from feederkit.planning.problem import Problem
from feederkit.planning.solved import MAX_TRIES, SolvedSets
from feederkit.planning.tree import Leaf
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty


@settings(max_examples=60, deadline=None)
@given(n=st.sampled_from([5, 64, 65, 150]), seed=st.integers(0, 10**6))
def test_the_index_answers_as_a_plain_scan(n, seed):
    rng = random.Random(seed)
    index = SolvedSets(n)
    kept: list[int] = []
    for _ in range(rng.randint(0, 200)):
        mask = rng.getrandbits(n) | rng.getrandbits(n)
        index.add(mask)
        if mask not in kept:
            kept.append(mask)
    assert len(index) == len(kept)
    for _ in range(20):
        query = rng.getrandbits(n) & rng.getrandbits(n) & rng.getrandbits(n)
        if rng.random() < 0.5 and kept:
            query &= rng.choice(kept)  # inside some kept set
        holding = [m for m in kept if query & m == query] if query else []
        found = index.holder(query, lambda m: True)
        assert found == (holding[-1] if holding else None)  # the latest kept first
        odd = [m for m in holding if m.bit_count() % 2]
        found = index.holder(query, lambda m: m.bit_count() % 2 == 1)
        if found is not None:
            assert found in odd
        elif odd:  # only the latest MAX_TRIES sets holding it are tried
            assert holding.index(odd[-1]) < len(holding) - MAX_TRIES


def test_the_index_stops_growing_at_its_cap(monkeypatch):
    import feederkit.planning.solved as solved

    monkeypatch.setattr(solved, "MAX_ROWS", 5)
    index = SolvedSets(10)
    for i in range(10):
        index.add(1 << i | 1)
    assert len(index) == 5
    assert index.holder(1 << 7, lambda m: True) is None
    assert index.holder(1 << 3, lambda m: True) == 0b1001


def _spied(search):
    hits = []
    real = search.inside_solved

    def spy(mask, k):
        out = real(mask, k)
        if out:
            hits.append(mask)
        return out

    search.inside_solved = spy
    return hits


def test_lengths_with_the_shortcut_are_the_exhaustive_searchs():
    machine = build_machine(small_mix(5, 100), ToleranceSensor(2.0), IDEAL)
    length, _children = brute_lengths(machine, 2.0)
    problem, _branches, roots = _problem(machine)
    w = WorstCase(problem)
    hits = _spied(w)
    rng = random.Random(5)
    masks = roots + [rng.getrandbits(machine.n) | rng.getrandbits(machine.n) for _ in range(60)]
    for mask in masks:
        want = length(mask)
        if want is None:
            continue
        assert w.length(mask) == want
        if want >= 1:
            assert not w.within(mask, want - 1)
    assert hits  # the shortcut was taken


def _run(machine, insep, node, state, ops, tol):
    """The longest run of ``node`` from ``state`` over every outcome and reading (asserting
    that each reading has a branch listing the state and each leaf lists only states
    inseparable from the true one)."""
    if isinstance(node, Leaf):
        assert node.mask >> state & 1
        assert all(j == state or insep[state] >> j & 1 for j in members(node.mask))
        return ops
    after = (
        [state]
        if node.action is None
        else members(machine.outcomes(state, node.action.representative))
    )
    longest = ops + 1
    for t in after:
        d = machine.states[t].sensed  # a diameter interval under a rotation error
        lo, hi = (d[0] - tol, d[1] + tol) if isinstance(d, tuple) else (d - tol, d + tol)
        mine = [(b, sub) for b, sub in node.branches if b.lo is None or (b.lo < hi and lo < b.hi)]
        assert mine and all(b.mask >> t & 1 for b, _sub in mine)
        covered = sorted((max(lo, b.lo), min(hi, b.hi)) for b, _sub in mine if b.lo is not None)
        if covered:  # every reading the state can give lies in some branch
            reach = lo
            for a, z in covered:
                assert a <= reach + 1e-9
                reach = max(reach, z)
            assert reach >= hi - 1e-9
        for _b, sub in mine:
            longest = max(longest, _run(machine, insep, sub, t, ops + 1, tol))
    return longest


def test_a_beams_plan_with_the_shortcut_runs_from_every_start_outcome_and_reading():
    tol = 3.0
    machine = build_machine(small_mix(8, 100), ToleranceSensor(tol), Uncertainty(1.0))
    problem, branches, roots = _problem(machine)
    beam = BeamSearch(problem, 4, Deadline())
    hits = _spied(beam)
    lengths = _lengths(beam, roots, 12)
    assert lengths is not None and hits
    root = _choice_plan(problem, beam.choice, roots, branches, Deadline())
    longest = max(_run(machine, problem.insep, root, s, 0, tol) for s in range(machine.n))
    assert longest <= 1 + max(lengths)


def test_no_index_under_a_margin_floor():
    machine = build_machine(small_mix(3, 200), ToleranceSensor(4.0), IDEAL)
    assert WorstCase(Problem(machine))._solved is not None
    assert BeamSearch(Problem(machine), 2)._solved is not None  # a plan is a plan
    assert WorstCase(Problem(machine, min_margin=1.0))._solved is None
