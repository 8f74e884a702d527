"""Exact critical tolerances (feederkit.design.critical) against an independent reference.

The reference bisects on floats with the exact pair test (definition 11, Theorem 9) and
knows nothing of breakpoints; the exact answer must be one of the breakpoints and agree with
it to the bisection's resolution. Monotonicity in the tolerance, which the binary search
relies on, is checked exhaustively over every interval between breakpoints.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from feederkit.design.critical import (
    interval_probe,
    last_true,
    mix_critical_tolerance,
    pair_breakpoints,
    pair_critical_tolerance,
)
from feederkit.errors import InputError
from feederkit.mechanics.push import push_function
from feederkit.mix.lookalike import build_lookalike
from feederkit.mix.pairs import distinguishable, unrecognizable_pairs
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL

REL = 1e-7
"""Relative resolution of the reference bisection."""


def random_pf(rng: np.random.Generator, name: str, size: tuple[float, float] = (20.0, 40.0)):
    """The push function of a random convex 3- to 7-gon with a random COM inside."""
    while True:
        k = int(rng.integers(3, 8))
        s = float(rng.uniform(*size))
        ang = np.sort(rng.uniform(0.0, 2.0 * math.pi, k))
        r = rng.uniform(0.6, 1.0, k) * s / 2.0
        pts = np.c_[r * np.cos(ang), r * np.sin(ang)]
        try:
            part = make_part(make_outline(name, pts.tolist()))
            hull = np.asarray(part.hull)
            w = rng.dirichlet(np.ones(len(hull)))
            com = 0.5 * (w @ hull) + 0.5 * hull.mean(axis=0)
            pf = push_function(make_part(part.outline, (float(com[0]), float(com[1]))))
        except InputError:
            continue
        if pf.n >= 2:
            return pf


def reference_critical(test, top: float, rel: float = REL) -> float | None:
    """Largest tolerance where ``test`` holds, by bisection on floats to ``rel`` of the
    answer (None: not even at 1e-9)."""
    lo = 1e-9
    if not test(lo):
        return None
    hi = top
    assert not test(hi)
    while hi - lo > rel * hi:
        mid = (lo + hi) / 2.0
        if test(mid):
            lo = mid
        else:
            hi = mid
    return lo


def pair_test(a, b):
    return lambda e: distinguishable(a, b, ToleranceSensor(e)) is None


def span(pfs) -> float:
    """A tolerance at which every state of every part reads alike every other."""
    ds = [s.diameter for pf in pfs for s in pf.states]
    return max(ds) - min(ds) + 1.0


@pytest.fixture(scope="module")
def pairs():
    rng = np.random.default_rng(20261201)
    out = []
    for i in range(200):
        a = random_pf(rng, f"a{i}")
        # Similar sizes for most pairs, so the answer comes from the fixpoint, not the sizes.
        b = random_pf(rng, f"b{i}", (20.0, 40.0) if i % 4 else (10.0, 60.0))
        out.append((a, b))
    return out


def test_last_true_is_a_binary_search():
    calls = []
    for count in range(0, 9):
        for answer in range(-1, count):
            calls.clear()

            def test(k, answer=answer):
                calls.append(k)
                return k <= answer

            assert last_true(count, test) == answer
            assert len(calls) <= math.ceil(math.log2(count + 1))


CHUNK = 25


@pytest.mark.parametrize("chunk", range(8))
def test_critical_matches_float_bisection_on_200_random_pairs(pairs, chunk):
    found = 0
    for a, b in pairs[chunk * CHUNK : (chunk + 1) * CHUNK]:
        exact = pair_critical_tolerance(a, b).critical_tolerance
        ref = reference_critical(pair_test(a, b), span([a, b]))
        if ref is None:
            assert exact is None
            continue
        found += 1
        assert exact is not None
        assert exact in pair_breakpoints(a, b)
        # The reference's largest distinguishable float lies just below the exact answer.
        assert ref <= exact * (1 + 1e-12) and exact - ref <= 2 * REL * exact + 1e-9
    assert found >= CHUNK // 2


@pytest.mark.parametrize("chunk", range(2))
def test_distinguishability_is_monotone_in_the_tolerance(pairs, chunk):
    for a, b in pairs[chunk * 30 : (chunk + 1) * 30]:
        breaks = pair_breakpoints(a, b)
        seq = [pair_test(a, b)(interval_probe(breaks, k)) for k in range(len(breaks) + 1)]
        assert seq == sorted(seq, reverse=True), (a.part.name, seq)
        assert not seq[-1]  # past every breakpoint all cross pairs read alike


@pytest.mark.parametrize("chunk", range(4))
def test_just_below_and_above_the_critical_tolerance(pairs, chunk):
    checked = 0
    for a, b in pairs[chunk * 10 : (chunk + 1) * 10]:
        x = pair_critical_tolerance(a, b).critical_tolerance
        if x is None:
            continue
        breaks = pair_breakpoints(a, b)
        k = breaks.index(x)
        above = (x + breaks[k + 1]) / 2.0 if k + 1 < len(breaks) else 2.0 * x
        for e in (x, math.nextafter(x, 0.0), x * (1 - 1e-6)):
            assert distinguishable(a, b, ToleranceSensor(e)) is None
        assert distinguishable(a, b, ToleranceSensor(math.nextafter(x, math.inf))) is not None
        assert distinguishable(a, b, ToleranceSensor(above)) is not None
        checked += 1
    assert checked >= 5


@pytest.mark.parametrize("rank", range(4))
def test_a_verified_plan_recognizes_the_pair_just_below_not_above(pairs, rank):
    # The pairs with the fewest states (their plans are quick), one per test.
    usable = [(a, b) for a, b in pairs[:60] if pair_critical_tolerance(a, b).critical_tolerance]
    a, b = sorted(usable, key=lambda p: p[0].n + p[1].n)[rank]
    x = pair_critical_tolerance(a, b).critical_tolerance
    breaks = pair_breakpoints(a, b)
    k = breaks.index(x)
    above = (x + breaks[k + 1]) / 2.0 if k + 1 < len(breaks) else 2.0 * x
    # The critical tolerance is the ideal model's (Theorem 9; docs/design.md): plan there.
    made = make_plan([a, b], ToleranceSensor(x), uncertainty=IDEAL)
    assert made.report.ok
    assert all(len(parts) == 1 for parts in leaf_parts(made.plan))
    made = make_plan([a, b], ToleranceSensor(above), uncertainty=IDEAL)
    assert made.report.ok
    assert any(len(parts) == 2 for parts in leaf_parts(made.plan))


def leaf_parts(plan: dict) -> list[set[str]]:
    """The part names of each result of a plan file (shared subplans followed)."""
    nodes = plan.get("nodes", {})
    out = []
    stack = [plan["root"]]
    while stack:
        node = stack.pop()
        if "ref" in node:
            node = nodes[node["ref"]]
        if "result" in node:
            out.append({r["part"] for r in node["result"]})
        else:
            stack.extend(b["next"] for b in node["branches"])
    return out


@pytest.mark.parametrize("seed", range(4))
def test_mix_critical_matches_bisection_on_random_mixes(seed):
    rng = np.random.default_rng(700 + seed)
    for m in range(10):
        pfs = [random_pf(rng, f"m{seed}.{m}p{i}") for i in range(int(rng.integers(2, 5)))]
        exact = mix_critical_tolerance(pfs)
        pair_values = [p.critical_tolerance for p in exact.pairs]
        assert len(pair_values) == len(pfs) * (len(pfs) - 1) // 2

        def recognizable(e, pfs=pfs):
            return not unrecognizable_pairs(pfs, ToleranceSensor(e))

        ref = reference_critical(recognizable, span(pfs))
        x = exact.critical_tolerance
        if ref is None:
            assert x is None and exact.inseparable
            continue
        assert x is not None and ref <= x * (1 + 1e-12) and x - ref <= 2 * REL * x + 1e-9
        assert x == min(pair_values) and all(p.critical_tolerance == x for p in exact.limiting)


def test_lookalike_pair_has_no_critical_tolerance():
    rng = np.random.default_rng(3)
    pf = random_pf(rng, "orig")
    twin = build_lookalike(pf.part, "push-diameter", 0).part
    twin_pf = push_function(make_part(twin.outline, twin.com))
    got = pair_critical_tolerance(pf, twin_pf)
    assert got.critical_tolerance is None
    assert got.witness is not None and "Lemma 8" in got.witness.reason
    assert got.to_dict()["critical_tolerance_mm"] is None


def test_equal_diameter_difference_reads_apart_at_exactly_half():
    # The open interval: diameters differing by exactly 2X read apart at X (design.md).
    rng = np.random.default_rng(11)
    a, b = random_pf(rng, "a"), random_pf(rng, "b")
    for x in pair_breakpoints(a, b)[:20]:
        pairs_at = [
            (s, t) for s in a.states for t in b.states if abs(s.diameter - t.diameter) / 2.0 == x
        ]
        assert pairs_at
        sensor = ToleranceSensor(x)
        assert not any(sensor.can_read_alike(s.diameter, t.diameter) for s, t in pairs_at)
        wider = ToleranceSensor(math.nextafter(x, math.inf))
        assert all(wider.can_read_alike(s.diameter, t.diameter) for s, t in pairs_at)


@pytest.mark.slow
def test_critical_matches_float_bisection_on_600_more_pairs():
    rng = np.random.default_rng(99)
    for i in range(600):
        a = random_pf(rng, f"sa{i}", (15.0, 45.0))
        b = random_pf(rng, f"sb{i}", (15.0, 45.0))
        exact = pair_critical_tolerance(a, b).critical_tolerance
        ref = reference_critical(pair_test(a, b), span([a, b]))
        if ref is None:
            assert exact is None
        else:
            assert exact is not None and exact in pair_breakpoints(a, b)
            assert ref <= exact * (1 + 1e-12) and exact - ref <= 2 * REL * exact + 1e-9
