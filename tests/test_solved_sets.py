"""Sets inside sets a margin probe found a plan for (``feederkit.planning.solved``,
``Refiner._inside_kept``).

Without a margin floor a plan of a set orients every subset of it keeping its margins, so a
probe "keeps ``x`` within ``k``?" of a set inside a set already found to keep ``x`` within
``k`` answers yes at once. Here the index is checked against a plain scan, the largest
margins with the shortcut taken against the tests' own max-min over every action and
reading branch, the plans made with it by running them from every start and reading, and a
margin floor keeps no index.
"""

from __future__ import annotations

import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shared import small_mix
from test_planners import check_plan
from test_tie_breaks import _max_min, _proven

from feederkit.machine import build_machine
from feederkit.planning.api import plan
from feederkit.planning.budget import Deadline
from feederkit.planning.methods import longest_root, make_oracle
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.refine import Refiner
from feederkit.planning.reindex import by_diameter
from feederkit.planning.solved import MAX_TRIES, SolvedSets
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL


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


def _spied(refiner):
    hits = []
    real = refiner._inside_kept

    def spy(mask, k, x, strict):
        out = real(mask, k, x, strict)
        if out:
            hits.append(mask)
        return out

    refiner._inside_kept = spy
    return hits


@pytest.mark.parametrize(("count", "tol"), [(6, 3.0), (8, 2.0), (8, 3.0)])
def test_margins_with_the_shortcut_are_the_max_min_over_every_branch(count, tol):
    machine = build_machine(small_mix(count, 100), ToleranceSensor(tol), IDEAL)
    refiner, every, k = _proven(machine)
    hits = _spied(refiner)
    memo: dict = {}
    for r in every:
        assert refiner.margin(r, k) == _max_min(refiner.p, r, k, memo)
    assert hits  # the shortcut was taken
    for (mask, j), lo in refiner._lo.items():  # every recorded floor is kept by some plan
        assert lo <= _max_min(refiner.p, mask, j, memo)


def test_a_plan_made_with_the_shortcut_runs_from_every_start_and_reading(monkeypatch):
    machine = build_machine(small_mix(8, 100), ToleranceSensor(3.0), IDEAL)
    hits = []
    real = Refiner._inside_kept

    def spy(self, mask, k, x, strict):
        out = real(self, mask, k, x, strict)
        hits.append(out)
        return out

    monkeypatch.setattr(Refiner, "_inside_kept", spy)
    result = plan(machine)
    assert any(hits) and result.tie_breaks == "exact"
    assert check_plan(result) == result.length
    refiner, every, k = _proven(machine)
    assert result.min_margin == pytest.approx(refiner.largest_floor(every, k), abs=1e-6)


def test_no_index_under_a_margin_floor():
    # Margins are not monotone under subsets once a floor drops ranges: neither the probes
    # nor the length search of a floored problem keep an index (each with its own oracle).
    machine = build_machine(small_mix(8, 100), ToleranceSensor(3.0), IDEAL)
    plain, every, k = _proven(machine)
    plain.margin(every[-1], k)
    assert plain._kept_sets  # without a floor the probes keep one
    problem = Problem(by_diameter(machine)[0], min_margin=0.5)
    worst = make_oracle(problem, "auto", Deadline())
    every = sorted({b.mask for b in problem.readings.branches(problem.full)})
    k = longest_root(problem, worst, sorted(maximal_sets(every)), "auto", None)
    floored = Refiner(problem, worst)
    floored.margin(every[-1], k)
    assert floored._kept_sets == {}
    assert worst._solved is None
