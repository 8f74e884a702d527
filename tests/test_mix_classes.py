"""Behaviour classes (sections 8.2-8.3): rotation-invariant signatures, phase shifts, and the
hashed classes agreeing with an all-pairs comparison."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_mix_planner import random_part

from feederkit.mechanics.push import push_function
from feederkit.mix.behaviour import push_classes, push_diameter_classes
from feederkit.mix.lookalike import build_lookalike
from feederkit.mix.signatures import (
    matching_shifts,
    same_push_diameter_function,
    same_push_function,
    signature,
)
from feederkit.outline import make_outline
from feederkit.part import make_part


def rotated(part, deg, name=None, scale=1.0):
    """The part rotated counter-clockwise by ``deg`` (and scaled) about the origin, COM kept."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))

    def f(p):
        return (scale * (c * p[0] - s * p[1]), scale * (s * p[0] + c * p[1]))

    outline = make_outline(name or part.name, [f(p) for p in part.hull], com=f(part.com))
    return make_part(outline)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10**6), st.floats(0.0, 359.0))
def test_rotation_keeps_both_functions_with_the_phase_shift(seed, deg):
    part = random_part(seed, "a")
    pa, pb = push_function(part), push_function(rotated(part, deg, "b"))
    alpha = same_push_diameter_function(pa, pb)
    assert alpha is not None
    assert same_push_function(pa, pb) is not None
    # Rotating the part by deg turns every stable normal by deg: that is the phase shift.
    d = (alpha - deg) % 360.0
    assert min(d, 360.0 - d) < 1e-6 or _symmetric_shift(pa, d)


def _symmetric_shift(pf, shift):
    sig = signature(pf)
    normals = sorted(s.normal_deg for s in pf.states)
    return any(
        all(
            min(abs((x + shift - y) % 360.0), 360.0 - abs((x + shift - y) % 360.0)) < 1e-6
            for x, y in zip(normals, np.roll(normals, -k), strict=True)
        )
        for k in range(sig.n)
    )


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10**6))
def test_scaling_keeps_the_push_function_not_the_push_diameter_function(seed):
    part = random_part(seed, "a")
    big = rotated(part, 0.0, "b", scale=1.5)
    pa, pb = push_function(part), push_function(big)
    assert same_push_function(pa, pb) is not None
    assert same_push_diameter_function(pa, pb) is None


def test_perturbation_beyond_the_tolerance_is_a_different_function():
    part = random_part(7, "a")
    pf = push_function(part)
    hull = list(part.hull)
    x, y = hull[0]
    moved = make_part(make_outline("b", [(x + 1e-3, y)] + hull[1:], com=part.com))
    assert same_push_function(pf, push_function(moved)) is None
    tiny = make_part(make_outline("c", [(x + 1e-13, y)] + hull[1:], com=part.com))
    assert same_push_diameter_function(pf, push_function(tiny)) == 0.0


def _brute_classes(sigs, length_tol):
    """All-pairs: the class of each part is its first matching earlier class representative."""
    reps, labels = [], []
    for k, s in enumerate(sigs):
        for c, r in enumerate(reps):
            if matching_shifts(sigs[r], s, length_tol=length_tol):
                labels.append(c)
                break
        else:
            reps.append(k)
            labels.append(len(reps) - 1)
    groups = {}
    for k, c in enumerate(labels):
        groups.setdefault(c, []).append(k)
    return sorted(tuple(g) for g in groups.values())


def test_hashed_classes_match_all_pairs_on_a_catalog_with_lookalikes_and_copies():
    rng = np.random.default_rng(11)
    parts = [random_part(int(s), f"r{k}") for k, s in enumerate(rng.integers(0, 10**6, 40))]
    extra = []
    for k, p in enumerate(parts[:12]):
        keep = "push" if k % 2 else "push-diameter"
        extra.append(build_lookalike(p, keep, k).part)
        extra.append(rotated(p, float(rng.uniform(0, 360)), f"rot{k}"))
    extra.append(rotated(parts[0], 0.0, "scaled", scale=2.0))
    pfs = [push_function(p) for p in parts + extra]
    sigs = [signature(pf) for pf in pfs]
    got_push = sorted(c.members for c in push_classes(sigs))
    got_pdf = sorted(c.members for c in push_diameter_classes(sigs))
    assert got_push == _brute_classes(sigs, None)
    assert got_pdf == _brute_classes(sigs, 1e-6)
    # Parts 0..11 each share a push function with their look-alike and rotated copy.
    idx = {pf.part.name: k for k, pf in enumerate(pfs)}
    for k in range(12):
        cls = next(c for c in push_classes(sigs) if k in c.members)
        assert idx[f"rot{k}"] in cls.members
        look = f"{parts[k].name}-lookalike-{'push' if k % 2 else 'push-diameter'}"
        assert idx[look] in cls.members
    assert len(got_push) < len(got_pdf) <= len(pfs)


def test_heptagon_of_fig_17_shares_the_triangles_push_function_only():
    from pathlib import Path

    from feederkit.mechanics.symmetry import push_period, symmetry
    from feederkit.outline import load_outline_json

    root = Path(__file__).resolve().parents[1] / "catalog"
    tri = push_function(make_part(load_outline_json(root / "equilateral-triangle.json")))
    hept = push_function(make_part(load_outline_json(root / "heptagon-fig17.json")))
    assert len(hept.part.hull) == 7
    assert same_push_function(tri, hept) is not None
    assert same_push_diameter_function(tri, hept) is None
    assert abs(push_period(hept) - 120.0) < 1e-6
    assert symmetry(hept).kind == "aperiodic"
    assert abs(symmetry(tri).part_period_deg - 120.0) < 1e-6  # oriented up to symmetry only
    assert symmetry(hept).part_period_deg == 360.0  # a sensor can orient it uniquely
    assert len({round(s.diameter, 9) for s in hept.states}) == 3
