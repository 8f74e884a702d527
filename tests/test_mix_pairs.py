"""Distinguishability of pairs of parts (section 8.4), decided exactly, with witnesses."""

from __future__ import annotations

import contextlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_mix_planner import random_part

from feederkit.errors import InputError
from feederkit.machine import build_machine, inseparable
from feederkit.mechanics.push import push_function
from feederkit.mix.lookalike import build_lookalike
from feederkit.mix.pairs import (
    PairWitness,
    candidate_pairs,
    distinguishable,
    inseparable_cross_pairs,
    unrecognizable_pairs,
)
from feederkit.mix.signatures import same_push_diameter_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL

sensors = st.one_of(
    st.floats(0.01, 8.0).map(ToleranceSensor),
    st.tuples(st.floats(0.5, 6.0), st.floats(0.0, 2.0)).map(lambda t: LedSensor(*t)),
    st.just(NoSensor()),
)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10**6), st.integers(0, 10**6), sensors)
def test_cross_pairs_are_the_product_machines_inseparable_pairs(sa, sb, sensor):
    a, b = push_function(random_part(sa, "a")), push_function(random_part(sb, "b"))
    machine = build_machine([a, b], sensor, uncertainty=IDEAL)
    ins = inseparable(machine)
    expected = sorted(
        (i, j - a.n) for i in range(a.n) for j in range(a.n, machine.n) if ins[i] >> j & 1
    )
    assert inseparable_cross_pairs(a, b, sensor) == expected
    witness = distinguishable(a, b, sensor)
    assert (witness is None) == (not expected)
    if witness is not None:
        assert list(witness.pairs) == expected
        # One inseparable pair reaches every state of both parts.
        assert set(witness.states_a) == set(range(a.n))
        assert set(witness.states_b) == set(range(b.n))


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10**6), st.integers(0, 10**6))
def test_theorem_9_different_push_diameter_functions_and_several_diameters(sa, sb):
    """No noise (tiny tolerance): different push-diameter functions, |D| > 1 => distinguishable."""
    a, b = push_function(random_part(sa, "a")), push_function(random_part(sb, "b"))
    diameters = {round(s.diameter, 9) for pf in (a, b) for s in pf.states}
    if same_push_diameter_function(a, b) is None and len(diameters) > 1:
        assert distinguishable(a, b, ToleranceSensor(1e-9)) is None


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10**6), st.integers(0, 5))
def test_theorem_9_holds_for_push_lookalikes(seed, k):
    """Same push function, different diameters (Theorem 4): told apart without noise."""
    part = random_part(seed, "a")
    look = build_lookalike(part, "push", k).part
    a, b = push_function(part), push_function(look)
    if same_push_diameter_function(a, b) is None:
        assert distinguishable(a, b, ToleranceSensor(1e-9)) is None


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10**6), st.integers(0, 5), st.floats(1e-6, 5.0))
def test_push_diameter_lookalikes_are_unrecognizable_by_lemma_8(seed, k, tol):
    part = random_part(seed, "a")
    look = build_lookalike(part, "push-diameter", k).part
    w = distinguishable(push_function(part), push_function(look), ToleranceSensor(tol))
    assert w is not None
    assert w.kind == "same-push-diameter"
    assert "Lemma 8" in w.reason
    assert w.part_a == "a" and w.part_b == look.name


def test_lemma_10_distinguishability_is_not_transitive():
    """A and C share a push-diameter function; B is told apart from each, A and C are not."""
    pa = random_part(3, "A")
    pc = build_lookalike(pa, "push-diameter", 1).part
    pb = random_part(4, "B")
    a, b, c = push_function(pa), push_function(pb), push_function(pc)
    sensor = ToleranceSensor(0.01)
    assert distinguishable(a, b, sensor) is None
    assert distinguishable(b, c, sensor) is None
    assert distinguishable(a, c, sensor) is not None
    pairs = unrecognizable_pairs([a, b, c], sensor)
    assert [(w.part_a, w.part_b) for w in pairs] == [("A", pc.name)]


def test_noise_makes_unrecognizability_non_transitive():
    """Same push function, diameters scaled by 1, 1.03, 1.06, tolerance 2% of the largest: A and
    B cannot be told apart, nor B and C, but A and C can: report pairs, not classes."""
    base = random_part(5, "A")

    def scaled(name, k):
        pts = [(k * x, k * y) for x, y in base.hull]
        com = (k * base.com[0], k * base.com[1])
        return push_function(make_part(make_outline(name, pts, com=com)))

    a, b, c = scaled("A", 1.0), scaled("B", 1.03), scaled("C", 1.06)
    sensor = ToleranceSensor(0.02 * max(s.diameter for s in a.states))
    ab, bc, ac = (distinguishable(x, y, sensor) for x, y in ((a, b), (b, c), (a, c)))
    assert ab is not None and bc is not None
    assert ac is None
    assert ab.kind == "tolerance" and "read alike" in ab.reason and "±" in ab.reason
    pairs = unrecognizable_pairs([a, b, c], sensor)
    assert [(w.part_a, w.part_b) for w in pairs] == [("A", "B"), ("B", "C")]


def test_two_squares_with_different_coms_read_as_one_diameter():
    """Section 8.4: same size, COMs apart: the sensor tells nothing; not recognizable."""

    def square(name, com):
        return push_function(
            make_part(make_outline(name, [[0, 0], [5, 0], [5, 5], [0, 5]], com=com))
        )

    a, b = square("A", (2.5, 2.5)), square("B", (2.0, 2.9))
    w = distinguishable(a, b, ToleranceSensor(0.05))
    assert w is not None and w.kind == "single-diameter"
    assert "single diameter value" in w.reason
    assert distinguishable(a, b, NoSensor()).kind == "sensorless"


def test_parts_of_different_diameters_that_read_alike_are_said_to_read_alike():
    """A review's mix: diameters 2.0-2.87 mm under a ±0.4368 mm sensor were given "a single
    diameter value", which sent a reader looking for a symmetry; the reason says the sensor
    reads them alike, and names the sensor."""
    quad = push_function(make_part(make_outline("q", [[0, 0], [3, 0], [2.5, 2], [0.5, 1.6]])))
    down = [[-x, y] for x, y in [[0, 0], [3, 0], [2.5, 2], [0.5, 1.6]]]
    bar = push_function(make_part(make_outline("q-down", down)))  # its other side
    diameters = [s.diameter for s in quad.states]
    assert max(diameters) - min(diameters) > 0.5
    w = distinguishable(quad, bar, ToleranceSensor(0.5))
    assert w is not None and w.kind == "single-diameter"
    assert w.reason.startswith("every state of both parts reads alike to the sensor")
    assert "±0.5 mm" in w.reason


def test_witness_to_dict_has_exactly_the_agreed_keys():
    pa = random_part(21, "A")
    pc = build_lookalike(pa, "push-diameter", 0).part
    w = distinguishable(push_function(pa), push_function(pc), ToleranceSensor(0.1))
    assert isinstance(w, PairWitness)
    d = w.to_dict()
    assert set(d) == {"part_a", "part_b", "states_a", "states_b", "reason", "kind"}
    assert d["kind"] == w.kind
    assert d["part_a"] == "A" and d["part_b"] == pc.name
    assert len(d["states_a"]) == len(d["states_b"]) == push_function(pa).n
    assert all(isinstance(x, int) for x in d["states_a"] + d["states_b"])


@settings(max_examples=8, deadline=None)
@given(st.integers(0, 10**6), st.floats(0.05, 3.0))
def test_candidate_pairs_keep_every_unrecognizable_pair(seed, tol):
    rng = np.random.default_rng(seed)
    parts = [random_part(int(s), f"p{k}") for k, s in enumerate(rng.integers(0, 10**6, 25))]
    parts += [build_lookalike(parts[k], "push-diameter", k).part for k in range(3)]
    pfs = [push_function(p) for p in parts]
    sensor = ToleranceSensor(tol)
    brute = {
        (i, j)
        for i in range(len(pfs))
        for j in range(i + 1, len(pfs))
        if inseparable_cross_pairs(pfs[i], pfs[j], sensor)
    }
    cand = set(candidate_pairs(pfs, sensor))
    assert brute <= cand
    assert {(w.index_a, w.index_b) for w in unrecognizable_pairs(pfs, sensor)} == brute
    assert len(cand) < len(pfs) * (len(pfs) - 1) // 2


def _crowded_catalog(count: int, seed: int):
    """Parts made to look alike: random 3- to 6-gons, each with copies whose vertices move by
    up to 0.001-0.5 mm, plus push and push-diameter look-alikes (Theorems 4 and 6)."""
    rng = np.random.default_rng(seed)
    parts = []
    k = 0
    while len(parts) < count:
        base = random_part(int(rng.integers(0, 10**6)), f"b{k}")
        parts.append(base)
        for jitter in (1e-3, 0.05, 0.5):
            verts = np.asarray(base.outline.vertices)
            pts = verts + rng.uniform(-jitter, jitter, verts.shape)
            with contextlib.suppress(InputError):
                parts.append(make_part(make_outline(f"b{k}-{jitter:g}", pts.tolist()), base.com))
        parts.append(build_lookalike(base, "push-diameter", rng).part)
        parts.append(build_lookalike(base, "push", rng).part)
        k += 1
    return [push_function(p) for p in parts[:count]]


@pytest.mark.parametrize(
    "sensor", [ToleranceSensor(0.3), ToleranceSensor(1.5), LedSensor(1.0, 0.2)], ids=str
)
def test_grouped_candidates_give_exactly_the_all_pairs_answer(sensor):
    pfs = _crowded_catalog(90, 7)
    every = [(i, j) for i in range(len(pfs)) for j in range(i + 1, len(pfs))]
    brute = unrecognizable_pairs(pfs, sensor, every)
    grouped = unrecognizable_pairs(pfs, sensor)
    assert [w.to_dict() for w in grouped] == [w.to_dict() for w in brute]
    assert len(brute) >= 30  # the look-alikes are there: the test can fail
    assert len(candidate_pairs(pfs, sensor)) < len(every) // 10


@pytest.mark.slow
def test_grouped_candidates_on_a_few_hundred_parts():
    pfs = _crowded_catalog(400, 11)
    sensor = ToleranceSensor(0.5)
    every = [(i, j) for i in range(len(pfs)) for j in range(i + 1, len(pfs))]
    brute = unrecognizable_pairs(pfs, sensor, every)
    assert [w.to_dict() for w in unrecognizable_pairs(pfs, sensor)] == [w.to_dict() for w in brute]
