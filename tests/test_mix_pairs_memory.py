"""A catalog's pair analysis holds little: compact candidate pairs, shared witness parts,
action ranges dropped after a part's last pair (the 50,000-part catalog over landings,
benchmarks/bench_catalog_landings.py)."""

from __future__ import annotations

import numpy as np
from test_mix_pairs import _crowded_catalog

from feederkit.mix.analyze import analyze_mix
from feederkit.mix.pairs import (
    CandidatePairs,
    PairWitness,
    candidate_pairs,
    unrecognizable_pairs,
)
from feederkit.mix.signatures import signature
from feederkit.sensors import NoSensor, ToleranceSensor


def test_candidate_pairs_are_sorted_and_iterate_across_chunks():
    rng = np.random.default_rng(3)
    count = 3 * CandidatePairs._CHUNK + 17
    a = rng.integers(0, 5000, count)
    b = a + rng.integers(1, 5000, count)
    pairs = CandidatePairs(a, b)
    expected = sorted(zip(a.tolist(), b.tolist(), strict=True))
    assert len(pairs) == count
    assert list(pairs) == expected
    assert pairs[0] == expected[0] and pairs[-1] == expected[-1]
    assert pairs[5:9] == expected[5:9]
    assert all(type(x) is int for x in pairs[len(pairs) // 2])
    assert pairs == expected and pairs == CandidatePairs(a, b)


def test_sensorless_candidates_are_every_pair():
    pfs = _crowded_catalog(7, 1)
    every = [(i, j) for i in range(7) for j in range(i + 1, 7)]
    assert list(candidate_pairs(pfs, NoSensor())) == every


def test_witnesses_share_their_tuples_and_reasons():
    pfs = _crowded_catalog(60, 7)
    sensor = ToleranceSensor(1.5)
    out = unrecognizable_pairs(pfs, sensor)
    assert len(out) >= 20  # the look-alikes are there: the test can fail
    assert not hasattr(out[0], "__dict__")  # slotted
    by_value: dict[tuple[int, ...], tuple[int, ...]] = {}
    for w in out:
        for t in (w.states_a, w.states_b):
            assert by_value.setdefault(t, t) is t  # equal tuples are one object
    tolerance = [w.reason for w in out if w.kind == "tolerance"]
    assert tolerance and all(r is tolerance[0] for r in tolerance)


def test_given_signatures_and_candidates_give_the_same_answer():
    pfs = _crowded_catalog(60, 5)
    sensor = ToleranceSensor(0.3)
    plain = unrecognizable_pairs(pfs, sensor)
    sigs = [signature(pf) for pf in pfs]
    given = unrecognizable_pairs(pfs, sensor, list(candidate_pairs(pfs, sensor)), signatures=sigs)
    assert [w.to_dict() for w in given] == [w.to_dict() for w in plain]
    assert [w.kind for w in given] == [w.kind for w in plain]
    analysis = analyze_mix(pfs, sensor)
    assert [w.to_dict() for w in analysis.pairs] == [w.to_dict() for w in plain]
    assert isinstance(analysis.pairs[0], PairWitness)
