"""The hardest pair's lower bound of the AND/OR search (``WorstCase.pair_bound``).

A plan of a set orients each of its pairs, so the largest length over the set's pairs
bounds the set's length from below. Here each pair's length and each set's length come from
the tests' own exhaustive search (every cell's middle, the read-alike sets of the states'
reading intervals); the bound must never exceed a set's length, must equal its hardest pair's
length, is searched only for the pairs a set asks about, and for sets other than those whose
length is searched only once the search is deep (``PAIR_BOUND_DEPTH``).
"""

from __future__ import annotations

import random

import pytest
from shared import brute_lengths, small_mix

import feederkit.planning.andor as andor
from feederkit.machine import build_machine
from feederkit.planning.andor import WorstCase
from feederkit.planning.methods import longest_root
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL


@pytest.mark.parametrize(("count", "seed", "tol"), [(3, 200, 4.0), (4, 200, 4.0), (2, 200, 8.0)])
def test_the_pair_bound_is_the_hardest_pairs_length_and_never_above_the_sets(count, seed, tol):
    machine = build_machine(small_mix(count, seed), ToleranceSensor(tol), IDEAL)
    length, children = brute_lengths(machine, tol)
    w = WorstCase(Problem(machine))
    rng = random.Random(count)
    masks = [rng.getrandbits(machine.n) or 1 for _ in range(40)]
    assert all(w.pair_bound(m) == 0 for m in masks)  # not before a deep search
    w._deep = True  # as after a length search of PAIR_BOUND_DEPTH
    asked = set()
    seen = []
    for mask in masks[:25]:
        sub = mask & rng.getrandbits(machine.n)
        for m in (mask, sub):
            if m & (m - 1) == 0:
                continue
            idx = [i for i in range(machine.n) if m >> i & 1]
            asked |= {(i, j) for k, i in enumerate(idx) for j in idx[k + 1 :]}
            pairs = [
                max(length(c) for c in children((1 << i) | (1 << j)))
                for k, i in enumerate(idx)
                for j in idx[k + 1 :]
            ]
            got = w.pair_bound(m)
            seen.append(got)
            assert got == max(pairs)
            whole = length(m)
            assert whole is None or got <= whole
    assert max(seen) >= 2  # some pair needs more than one operation
    table = w._pairs.table
    searched = {
        (i, j) for i in range(machine.n) for j in range(i + 1, machine.n) if table[i][j] >= 0
    }
    assert searched == asked  # a pair's length is searched only when a set asks


def test_a_shallow_length_search_searches_only_its_roots_pairs(monkeypatch):
    machine = build_machine(small_mix(6), ToleranceSensor(1.0), IDEAL)  # length 3
    problem = Problem(machine)
    w = WorstCase(problem)
    roots = sorted(maximal_sets({b.mask for b in problem.readings.branches(problem.full)}))
    longest = longest_root(problem, w, roots, "auto")
    assert longest < andor.PAIR_BOUND_DEPTH and not w._deep
    n = machine.n
    table = w._pairs.table
    searched = {(i, j) for i in range(n) for j in range(i + 1, n) if table[i][j] >= 0}
    inside = {(i, j) for i, j in searched if any(r >> i & 1 and r >> j & 1 for r in roots)}
    assert searched and searched == inside  # each root's own bound, no other set's
    assert w.pair_bound(problem.full) == 0  # not a root: no bound in a shallow search
    # A deeper budget turns the bound on for every set: the same lengths.
    monkeypatch.setattr(andor, "PAIR_BOUND_DEPTH", 1)
    deep = WorstCase(Problem(machine))
    assert longest_root(problem, deep, roots, "auto") == longest
    assert deep._deep and deep.pair_bound(problem.full) >= 1
