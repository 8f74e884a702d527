"""Refuted sets held by larger ones (``feederkit.planning.refuted``, ``WorstCase.within``).

Lengths are monotone under subsets without a margin floor, so the AND/OR search refutes a set
that holds a set it refuted at the same depth without opening it. Here the index is checked
against a plain scan, the search's lengths (with every refutation kept across many queries)
against the tests' own exhaustive search, and the shortcut itself: a set holding a refuted set
is refuted without its actions being made; a beam, whose failures are no proofs, and a margin
floor, under which lengths are not monotone, keep no index.
"""

from __future__ import annotations

import math
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shared import brute_lengths, small_mix

from feederkit.machine import build_machine
from feederkit.planning.andor import WorstCase
from feederkit.planning.beam import BeamSearch
from feederkit.planning.problem import Problem
from feederkit.planning.refuted import RefutedSets
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL


@settings(max_examples=60, deadline=None)
@given(
    n=st.sampled_from([5, 64, 65, 150]),
    seed=st.integers(0, 10**6),
)
def test_the_index_answers_as_a_plain_scan(n, seed):
    rng = random.Random(seed)
    index = RefutedSets(n)
    kept: list[tuple[int, int]] = []
    for _ in range(rng.randint(0, 300)):  # past the first block of rows
        mask = rng.getrandbits(n) & rng.getrandbits(n) & rng.getrandbits(n)
        lb = rng.randint(1, 6)
        index.add(mask, lb)
        kept.append((mask, lb))
    assert len(index) == len(kept)
    for _ in range(20):
        query = rng.getrandbits(n) | rng.getrandbits(n)
        need = rng.randint(1, 7)
        plain = max((lb for m, lb in kept if m & query == m and lb >= need), default=None)
        assert index.bound(query, need) == plain


@settings(max_examples=60, deadline=None)
@given(
    n=st.sampled_from([5, 64, 65, 150]),
    seed=st.integers(0, 10**6),
)
def test_the_index_asked_again_as_it_grows_answers_as_a_plain_scan(n, seed):
    # The searches ask the same sets again, at other bounds, between additions: the index
    # remembers what it found a set holds nothing of and scans only the rows added since.
    rng = random.Random(seed)
    index = RefutedSets(n)
    kept: list[tuple[int, int]] = []
    asked = [rng.getrandbits(n) | rng.getrandbits(n) for _ in range(12)]
    for _ in range(400):
        if rng.random() < 0.35:
            mask = rng.getrandbits(n) & rng.getrandbits(n) & rng.getrandbits(n)
            if rng.random() < 0.3:
                mask &= rng.choice(asked)  # a set some asked set holds
            lb = rng.randint(1, 6)
            index.add(mask, lb)
            kept.append((mask, lb))
        else:
            query, need = rng.choice(asked), rng.randint(1, 7)
            plain = max((lb for m, lb in kept if m & query == m and lb >= need), default=None)
            assert index.bound(query, need) == plain


@pytest.mark.parametrize(("count", "seed", "tol"), [(3, 200, 4.0), (4, 200, 4.0), (4, 7, 2.0)])
def test_lengths_with_refutations_kept_across_queries_are_the_exhaustive_searchs(count, seed, tol):
    machine = build_machine(small_mix(count, seed), ToleranceSensor(tol), IDEAL)
    length, _children = brute_lengths(machine, tol)
    w = WorstCase(Problem(machine))
    rng = random.Random(seed)
    masks = [rng.getrandbits(machine.n) | rng.getrandbits(machine.n) for _ in range(60)]
    for mask in sorted(masks, key=int.bit_count):  # small sets first: later ones hold them
        want = length(mask)
        if want is None:
            continue
        assert w.length(mask) == want
        if want >= 1:
            assert not w.within(mask, want - 1)
    assert len(w._refuted) > 0


def test_a_set_holding_a_refuted_set_is_refuted_unopened(monkeypatch):
    machine = build_machine(small_mix(4, 200), ToleranceSensor(4.0), IDEAL)
    problem = Problem(machine)
    w = WorstCase(problem)
    assert w.length(problem.full) >= 2
    hard = [m for m, lb in w.lb.items() if lb >= 2 and m != problem.full]
    assert hard
    refuted = min(hard, key=int.bit_count)
    k = w.lb[refuted] - 1
    outside = [i for i in range(machine.n) if not refuted >> i & 1]
    bigger = next(refuted | 1 << i for i in outside if w._known(refuted | 1 << i, k) is None)
    opened: list[int] = []
    real = w.actions_of
    monkeypatch.setattr(w, "actions_of", lambda m: opened.append(m) or real(m))
    assert not w.within(bigger, k)
    assert opened == [] and w.lb[bigger] > k


def test_no_index_where_failures_are_not_proofs_or_lengths_not_monotone():
    machine = build_machine(small_mix(3, 200), ToleranceSensor(4.0), IDEAL)
    assert WorstCase(Problem(machine))._refuted is not None
    assert BeamSearch(Problem(machine), 2)._refuted is None
    assert WorstCase(Problem(machine, min_margin=1.0))._refuted is None


def test_the_index_stops_growing_at_its_cap(monkeypatch):
    import feederkit.planning.refuted as refuted

    monkeypatch.setattr(refuted, "MAX_ROWS", 300)
    index = RefutedSets(10)
    for i in range(400):
        index.add(1 << (i % 10), 2)
    assert len(index) == 300 and index.bound(0b1, 2) == 2.0


def test_margin_probes_refute_a_set_holding_a_refuted_set_without_a_search(monkeypatch):
    from test_tie_breaks import _max_min, _proven

    machine = build_machine(small_mix(5), ToleranceSensor(2.0), IDEAL)
    refiner, every, k = _proven(machine)
    memo: dict = {}
    for r in every:  # probes above each root's largest margin: each is refuted
        best = _max_min(refiner.p, r, k, memo)
        if math.isfinite(best):
            assert not refiner.keeps(r, k, best + 1.0)
    refuted = [(m, j, x) for (m, j), x in refiner._lt.items() if math.isfinite(x)]
    assert refuted
    n = machine.n
    searched: list[int] = []
    real = refiner._keeping_plan
    monkeypatch.setattr(refiner, "_keeping_plan", lambda m, *a: searched.append(m) or real(m, *a))
    held = 0
    for mask, j, x in refuted:
        for i in range(n):
            bigger = mask | 1 << i
            if bigger == mask or (bigger, j) in refiner._lt or refiner._short(bigger, j):
                continue
            searched.clear()
            assert not refiner.keeps(bigger, j, x)
            assert _max_min(refiner.p, bigger, j, memo) < x  # the exhaustive answer
            held += bigger not in searched
    assert held > 0
