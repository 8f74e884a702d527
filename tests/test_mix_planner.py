"""Multi-part plans (section 8.5) against the independent exhaustive planner of the tests, and
every emitted mix plan verified on the kinematic model for every part of its mix (issue 5)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mix_oracle import MixOracle, OraclePart

from feederkit.errors import InputError, PlanningError
from feederkit.machine import build_machine
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan
from feederkit.plans.make import make_plan
from feederkit.plans.verify import verify_plan
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL


def random_part(seed: int, name: str, kmax: int = 6):
    """A random convex 3- to kmax-gon of size about 40 mm with a random COM inside."""
    rng = np.random.default_rng(seed)
    for _ in range(50):
        k = int(rng.integers(3, kmax + 1))
        ang = np.sort(rng.uniform(0.0, 2.0 * math.pi, k))
        r = rng.uniform(12.0, 20.0, k)
        pts = np.c_[r * np.cos(ang), r * np.sin(ang)]
        try:
            part = make_part(make_outline(name, pts.tolist()))
            hull = np.asarray(part.hull)
            com = 0.5 * (rng.dirichlet(np.ones(len(hull))) @ hull) + 0.5 * hull.mean(axis=0)
            return make_part(part.outline, (float(com[0]), float(com[1])))
        except InputError:
            continue
    raise AssertionError("no random part")


def oracle_length(parts, tolerance):
    return MixOracle([OraclePart(list(p.hull), p.com) for p in parts], tolerance).length()


mixes = st.tuples(
    st.lists(st.integers(0, 10**6), min_size=2, max_size=4, unique=True),
    st.sampled_from([0.005, 0.02, 0.05, 0.1]),
)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mixes)
def test_mix_planner_agrees_with_exhaustive_search(mix):
    seeds, rel_tol = mix
    parts = [random_part(s, f"m{k}") for k, s in enumerate(seeds)]
    tol = rel_tol * max(p.size for p in parts)
    pfs = [push_function(p) for p in parts]
    result = plan(build_machine(pfs, ToleranceSensor(tol), uncertainty=IDEAL))
    assert result.optimal
    assert result.length == oracle_length(parts, tol)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.integers(0, 10**6), min_size=2, max_size=2, unique=True))
def test_sensorless_mix_agrees_with_exhaustive_search(seeds):
    parts = [random_part(s, f"s{k}", kmax=4) for k, s in enumerate(seeds)]
    pfs = [push_function(p) for p in parts]
    try:
        result = plan(build_machine(pfs, NoSensor(), uncertainty=IDEAL))
    except PlanningError:
        with pytest.raises(AssertionError):
            oracle_length(parts, None)
        return
    assert result.length == oracle_length(parts, None)


def test_oracle_reproduces_the_paper_figure_27_mix():
    """Isosceles right triangle (legs 1) and regular 8-gon, tolerance 0.01: length 2."""
    tri = make_part(make_outline("tri", [[0, 0], [1, 0], [0, 1]]))
    octagon = make_part(
        make_outline(
            "oct", [[math.cos(k * math.pi / 4), math.sin(k * math.pi / 4)] for k in range(8)]
        )
    )
    assert oracle_length([tri, octagon], 0.01) == 2
    result = plan(
        build_machine(
            [push_function(tri), push_function(octagon)], ToleranceSensor(0.01), uncertainty=IDEAL
        )
    )
    assert result.length == 2


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mixes)
def test_every_mix_plan_passes_verification_for_every_part(mix):
    seeds, rel_tol = mix
    parts = [random_part(s, f"v{k}") for k, s in enumerate(seeds)]
    tol = rel_tol * max(p.size for p in parts)
    made = make_plan([push_function(p) for p in parts], ToleranceSensor(tol), uncertainty=IDEAL)
    assert made.report.ok
    for k in range(len(parts)):
        report = verify_plan(made.plan, [k])
        assert report.ok, report.first_problem()
        assert report.paths > 0
