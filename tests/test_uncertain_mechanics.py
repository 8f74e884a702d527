"""The uncertainty value and the mechanics under uncertainty on known parts.

Zero uncertainty must give back the ideal model exactly (states, diameters, action ranges);
the default uncertainty must merge the wrench's two bottom edges and the d-washer's arc facets;
bands, outcome sets and certificates must follow their definitions.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest

from feederkit.angles import norm360
from feederkit.errors import InputError
from feederkit.mechanics import action_ranges, diameter, push, push_function
from feederkit.mechanics.analysis import FRAGILE_BARRIER_REL
from feederkit.mechanics.certificates import max_rotation_error, max_shape_tolerance
from feederkit.mechanics.outcomes import action_map, fence_outcomes, outcome_at, outcome_set
from feederkit.mechanics.uncertain import (
    PUSH_BAND_DEG,
    PUSH_BAND_FACTOR,
    SHALLOW_WELL_FACTOR,
    mechanics_to_dict,
    uncertain_mechanics,
    width_range,
)
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sources import load_part
from feederkit.uncertainty import (
    IDEAL,
    Uncertainty,
    check_for_part,
)
from feederkit.uncertainty import (
    max_shape_tolerance as tolerance_limit,
)

ROOT = Path(__file__).resolve().parents[1]
CATALOG = ROOT / "catalog"
WRENCH = ROOT.parent / "shared" / "samples" / "trimesh__wrench.dxf"
GEAR = ROOT.parent / "shared" / "samples" / "cadquery__gear.dxf"
CATALOG_PARTS = sorted(p.stem for p in CATALOG.glob("*.json"))


def catalog_part(name: str):  # noqa: ANN201
    return load_part(str(CATALOG / f"{name}.json"))


def circ(a: float, b: float) -> float:
    d = (a - b) % 360.0
    return min(d, 360.0 - d)


# --- the Uncertainty value --------------------------------------------------------------------


def test_defaults_and_round_trip() -> None:
    u = Uncertainty()
    assert (u.rotation_error_deg, u.shape_tolerance_mm, u.com_tolerance_mm) == (1.0, 0.0, 0.0)
    assert not u.is_ideal and IDEAL.is_ideal
    v = Uncertainty(0.5, 0.02, 0.1)
    assert v.to_dict() == {
        "rotation_error_deg": 0.5,
        "shape_tolerance_mm": 0.02,
        "com_tolerance_mm": 0.1,
    }
    assert Uncertainty.from_dict(v.to_dict()) == v
    assert Uncertainty.from_dict({}) == Uncertainty()
    assert v.radius_error_mm == pytest.approx(0.12)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"rotation_error_deg": -1.0}, "rotation error"),
        ({"rotation_error_deg": float("nan")}, "rotation error"),
        ({"rotation_error_deg": 90.0}, "[0, 90)"),
        ({"rotation_error_deg": 120.0}, "[0, 90)"),
        ({"shape_tolerance_mm": -0.1}, "shape tolerance"),
        ({"shape_tolerance_mm": float("inf")}, "shape tolerance"),
        ({"com_tolerance_mm": float("nan")}, "COM tolerance"),
        ({"com_tolerance_mm": "abc"}, "COM tolerance"),
    ],
)
def test_bad_values_are_one_line_input_errors(kwargs: dict, words: str) -> None:
    with pytest.raises(InputError) as err:
        Uncertainty(**kwargs)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_bad_dicts_are_input_errors() -> None:
    with pytest.raises(InputError, match="unknown key"):
        Uncertainty.from_dict({"rotation_error": 1.0})
    with pytest.raises(InputError, match="must be an object"):
        Uncertainty.from_dict([1.0])


def test_shape_tolerance_is_checked_against_the_smallest_edge() -> None:
    part = catalog_part("rectangle-2x1")  # 2 x 1: smallest edge 1 mm
    assert tolerance_limit(part) == pytest.approx(0.5)
    assert check_for_part(Uncertainty(1.0, 0.49), part).shape_tolerance_mm == 0.49
    with pytest.raises(InputError, match="half the smallest hull edge"):
        check_for_part(Uncertainty(1.0, 0.5), part)
    with pytest.raises(InputError, match="rectangle-2x1"):
        uncertain_mechanics(part, Uncertainty(1.0, 0.7))


# --- zero uncertainty is the ideal model -------------------------------------------------------


@pytest.mark.parametrize("name", CATALOG_PARTS)
def test_zero_uncertainty_is_the_ideal_model(name: str) -> None:
    part = catalog_part(name)
    pf = push_function(part)
    mech = uncertain_mechanics(part, IDEAL)
    assert mech.n == pf.n and mech.state_of == tuple(range(pf.n))
    for ps, s in zip(mech.states, pf.states, strict=True):
        assert ps.members == (s.id,)
        assert ps.rest_deg == (s.normal_deg, s.normal_deg)
        assert ps.diameter == (s.diameter, s.diameter)
        ideal = action_ranges(pf, s.id)
        amap = action_map(mech, ps.id)
        assert len(amap) == len(ideal)
        for (lo, hi, targets), r in zip(amap, ideal, strict=True):
            assert circ(lo, r.lo) < 1e-9 and abs((hi - lo) - (r.hi - r.lo)) < 1e-9
            assert targets == {r.target}
        # Exactly at a boundary the push may end on either side.
        lo, _, left = amap[0]
        _, _, right = amap[-1]
        assert outcome_set(mech, ps.id, lo) == left | right


def test_zero_uncertainty_fence_outcomes_are_the_push_function() -> None:
    part = catalog_part("heptagon-fig17")
    pf = push_function(part)
    mech = uncertain_mechanics(part, IDEAL)
    for theta in np.linspace(0.0, 360.0, 721)[:-1].tolist():
        if min(circ(theta, d) for d in pf.divergent_deg) < 1e-6:
            continue
        assert fence_outcomes(mech, theta, theta) == {push(pf, theta).id}
    for d in pf.divergent_deg:
        assert len(fence_outcomes(mech, d, d)) == 2


def test_rotation_error_alone_unions_the_ideal_outcomes() -> None:
    # No vibration, no tolerances: the outcome set is the ideal push over a - r .. a + r.
    part = catalog_part("quadrilateral")
    pf = push_function(part)
    mech = uncertain_mechanics(part, Uncertainty(2.0), vibration_mm=0.0)
    assert mech.n == pf.n
    rng = np.random.default_rng(5)
    for s in pf.states:
        for a in rng.uniform(0.0, 360.0, 40).tolist():
            want = {push(pf, s.normal_deg - a - e).id for e in np.linspace(-2.0, 2.0, 801)}
            assert want <= outcome_set(mech, s.id, a)
            got = outcome_set(mech, s.id, a)
            bounds = [norm360(s.normal_deg - d) for d in pf.divergent_deg]
            if min(abs(circ(a, b) - 2.0) for b in bounds) > 0.01:
                assert got == want


# --- physical states on known parts ------------------------------------------------------------


def bent_bar():  # noqa: ANN201
    """An 80 x 20 bar whose bottom is two edges 3 degrees apart, the bend just under the COM."""
    sag = 40.0 * math.tan(math.radians(1.5))
    pts = [(0, 0), (40.1, -sag), (80, 0), (80, 20), (0, 20)]
    return make_part(make_outline("bent-bar", pts), (40.0, 10.0))


def test_a_bar_rests_across_its_two_bottom_edges() -> None:
    part = bent_bar()
    pf = push_function(part)
    bottom = sorted(s.id for s in pf.states if circ(s.normal_deg, 270.0) < 2.0)
    assert len(bottom) == 2
    assert uncertain_mechanics(part, IDEAL).n == pf.n
    mech = uncertain_mechanics(part, Uncertainty())
    merged = mech.states[mech.state_of[bottom[0]]]
    assert merged.members == tuple(sorted(bottom, key=lambda i: pf.states[i].normal_deg))
    lo, hi = merged.rest_deg
    normals = [pf.states[i].normal_deg for i in bottom]
    assert hi - lo == pytest.approx(circ(*normals), abs=1e-9) and 2.9 < hi - lo < 3.1
    assert merged.diameter == pytest.approx(width_range(part.hull, lo, hi))
    widths = [pf.states[i].diameter for i in bottom]
    assert merged.diameter[0] <= min(widths) < max(widths) <= merged.diameter[1]
    # Away from the bottom nothing merges: the bar's ends and top keep their own states.
    assert mech.n == pf.n - 1


@pytest.mark.slow
def test_the_wrench_rests_across_its_two_bottom_edges() -> None:
    # On its hull simplified at 0.05 mm, which has a fragile side state (the import keeps a
    # smaller tolerance, on which that chord's state is gone: these are its mechanics).
    drawn = load_part(str(WRENCH))
    part = make_part(drawn.outline, drawn.com, hull_tolerance=0.05)
    pf = push_function(part)
    bottom = sorted(s.id for s in pf.states if circ(s.normal_deg, 268.5) < 3.0)
    assert len(bottom) == 2
    assert uncertain_mechanics(part, IDEAL).n == pf.n
    mech = uncertain_mechanics(part, Uncertainty())
    merged = mech.states[mech.state_of[bottom[0]]]
    assert set(merged.members) == set(bottom)
    lo, hi = merged.rest_deg
    assert hi - lo == pytest.approx(circ(*(pf.states[i].normal_deg for i in bottom)), abs=1e-9)
    widths = [pf.states[i].diameter for i in bottom]
    # It reads anything between (and including) the two states' diameters.
    assert merged.diameter[0] <= min(widths) and merged.diameter[1] >= max(widths)
    assert merged.diameter == pytest.approx(width_range(part.hull, lo, hi))
    assert float(diameter(part, (lo + hi) / 2.0)) <= merged.diameter[1]
    # The fragile side state is kept as one the part may stay in (the feeder's vibration is
    # not known); a push ending there may also end beyond its low barrier.
    side = next(s.id for s in pf.states if s.barrier_mm < 0.01 and s.id not in bottom)
    own = mech.state_of[side]
    assert own is not None and own in mech.destinations[side]
    assert len(mech.destinations[side]) >= 2


def test_the_d_washer_arc_facets_merge_and_the_flat_stays() -> None:
    part = catalog_part("d-washer")
    pf = push_function(part)
    flat = next(s.id for s in pf.states if circ(s.normal_deg, 270.0) < 1e-6)
    mech = uncertain_mechanics(part, Uncertainty())
    assert mech.n == 2
    assert mech.states[mech.state_of[flat]].members == (flat,)
    arc = mech.states[1 - mech.state_of[flat]]
    assert set(arc.members) == set(range(pf.n)) - {flat}
    d = [pf.states[i].diameter for i in arc.members]
    assert arc.diameter[0] <= min(d) and arc.diameter[1] >= max(d)
    data = mechanics_to_dict(mech)
    assert data["uncertainty"] == Uncertainty().to_dict() and len(data["physical_states"]) == 2


def test_plain_shapes_keep_their_states_at_the_default() -> None:
    for name in ("rectangle-2x1", "octagon", "equilateral-triangle"):
        part = catalog_part(name)
        assert uncertain_mechanics(part, Uncertainty()).n == push_function(part).n


def test_bands_are_asin_of_the_tolerance_at_a_sharp_vertex() -> None:
    part = make_part(make_outline("tri", [(0, 0), (40, 0), (10, 30)]))
    pf = push_function(part)
    unc = Uncertainty(1.0, 0.01, 0.02)
    mech = uncertain_mechanics(part, unc, vibration_mm=0.0)  # no push band: F2 alone
    assert len(mech.bands) == pf.n == 3
    com = np.asarray(part.com)
    for band in mech.bands:
        v = min(
            part.hull,
            key=lambda p: circ(
                math.degrees(math.atan2(p[1] - com[1], p[0] - com[0])), band.divergent_deg
            ),
        )
        rho = math.dist(v, part.com)
        spread = math.degrees(math.asin(unc.radius_error_mm / rho))
        assert band.lo_deg <= band.divergent_deg <= band.hi_deg
        assert band.divergent_deg - band.lo_deg == pytest.approx(spread, rel=1e-6)
        assert band.hi_deg - band.divergent_deg == pytest.approx(spread, rel=1e-6)


def test_outcome_sets_grow_with_the_uncertainty() -> None:
    part = catalog_part("l-bracket")
    rng = np.random.default_rng(2)
    actions = rng.uniform(0.0, 360.0, 60).tolist()
    levels = [
        Uncertainty(0.0),
        Uncertainty(0.5),
        Uncertainty(1.0),
        Uncertainty(2.0, 0.01, 0.01),
        Uncertainty(4.0, 0.05, 0.05),
    ]
    # The same vibration at every level (the ideal model has none: its states are exact).
    vibration = FRAGILE_BARRIER_REL * part.size
    mechs = [uncertain_mechanics(part, u, vibration_mm=vibration) for u in levels]

    def ideal_members(mech, i: int, a: float) -> set[int]:  # noqa: ANN001
        return {
            m
            for start in mech.destinations[i]
            for p in outcome_set(mech, start, a)
            for m in mech.states[p].members
        }

    for i in range(push_function(part).n):
        for a in actions:
            sets = [ideal_members(m, i, a) for m in mechs]
            for small, large in zip(sets, sets[1:], strict=False):
                assert small <= large


# --- certificates ------------------------------------------------------------------------------


def test_max_rotation_error_is_the_distance_to_the_nearest_boundary() -> None:
    part = catalog_part("rectangle-2x1")
    pf = push_function(part)
    mech = uncertain_mechanics(part, Uncertainty(0.0), vibration_mm=0.0)
    for s in pf.states:
        for r in action_ranges(pf, s.id):
            mid = (r.lo + r.hi) / 2.0
            got = max_rotation_error(mech, [s.id], mid, {s.id: frozenset({r.target})})
            # The supremum stops BOUNDARY_EPS_DEG short of the boundary (touching counts).
            assert got == pytest.approx(min((r.hi - r.lo) / 2.0, 90.0), abs=2e-9)
    # The certificate of a set is the smallest; just above it some outcome leaves the set.
    states = [0, 1]
    a = 100.0
    assumed = {s: outcome_set(mech, s, a, 0.0) for s in states}
    cert = max_rotation_error(mech, states, a, assumed)
    assert all(outcome_set(mech, s, a, cert * 0.999) <= assumed[s] for s in states)
    assert any(not outcome_set(mech, s, a, cert + 1e-6) <= assumed[s] for s in states)


def test_max_rotation_error_is_at_least_the_declared_error_for_the_declared_sets() -> None:
    part = catalog_part("l-bracket")
    mech = uncertain_mechanics(part, Uncertainty(1.0))
    for s in range(mech.n):
        for a in (10.0, 95.0, 200.0, 300.0):
            assert max_rotation_error(mech, [s], a) >= 1.0


def test_max_shape_tolerance_bisection_brackets_the_change() -> None:
    part = catalog_part("rectangle-2x1")
    pf = push_function(part)
    base = Uncertainty(1.0)
    checks = [
        (s.id, r.lo + 0.3 * (r.hi - r.lo), frozenset({r.target}))
        for s in pf.states
        for r in action_ranges(pf, s.id)[:1]
    ]
    t = max_shape_tolerance(part, base, checks, rel_tol=1e-3)
    assert 0.0 < t < tolerance_limit(part)

    def holds(tol: float) -> bool:
        mech = uncertain_mechanics(part, Uncertainty(1.0, tol))
        return all(
            {
                m
                for st in mech.destinations[i]
                for p in outcome_set(mech, st, a)
                for m in mech.states[p].members
            }
            <= allowed
            for i, a, allowed in checks
        )

    assert holds(t)
    assert not holds(t + 2e-3 * tolerance_limit(part))


# --- exactness of helpers and speed ------------------------------------------------------------


def test_width_range_is_exact() -> None:
    part = catalog_part("l-bracket")
    for lo, hi in ((10.0, 50.0), (200.0, 200.5), (300.0, 420.0), (0.0, 360.0)):
        grid = np.linspace(lo, hi, 20001)
        w = diameter(part, grid)
        got = width_range(part.hull, lo, hi)
        assert got[0] <= w.min() + 1e-12 and got[1] >= w.max() - 1e-12
        assert got[0] == pytest.approx(w.min(), abs=1e-6) and got[1] == pytest.approx(
            w.max(), abs=1e-6
        )


def test_action_map_covers_the_circle_and_agrees_with_outcome_set() -> None:
    part = bent_bar()
    mech = uncertain_mechanics(part, Uncertainty(1.0, 0.01, 0.02))
    for s in range(mech.n):
        amap = action_map(mech, s)
        assert amap[0][0] >= 0.0 and amap[0][0] < 360.0
        assert sum(hi - lo for lo, hi, _ in amap) == pytest.approx(360.0)
        for (_, hi, _), (lo, _, _) in zip(amap, amap[1:], strict=False):
            assert hi == pytest.approx(lo)
        for lo, hi, targets in amap:
            mid = (lo + hi) / 2.0
            assert outcome_set(mech, s, mid) == targets == outcome_at(amap, mid)


def _wavy_outline(n: int):
    """A convex ``n``-gon on a slightly wavy 60 mm circle: every point a hull vertex."""
    pts = [
        (
            30 * math.cos(2 * math.pi * k / n) * (1 + 0.02 * math.sin(14 * math.pi * k / n)),
            30 * math.sin(2 * math.pi * k / n),
        )
        for k in range(n)
    ]
    part = make_part(make_outline(f"wavy-{n}", pts))
    assert len(part.hull) == n
    return part


def _best_seconds(part, runs: int = 3) -> float:
    best = math.inf
    for _ in range(runs):
        start = time.perf_counter()
        mech = uncertain_mechanics(part, Uncertainty())
        best = min(best, time.perf_counter() - start)
        assert mech.n >= 1
    return best


def test_a_thousand_vertex_outline_costs_about_linear_time() -> None:
    # Growth, not speed (docs/performance.md keeps the seconds): four times the vertices
    # cost at most about four times as long (n log n; measured: twice, fixed costs included);
    # a quadratic step would cost 16 times. The ratio of two runs in the same process
    # absorbs a loaded machine.
    small, big = _wavy_outline(250), _wavy_outline(1000)
    uncertain_mechanics(small, Uncertainty())  # warm up
    ratio = _best_seconds(big) / max(_best_seconds(small), 1e-4)
    assert ratio < 10.0, ratio


def _radius_at(part, phi_deg: float) -> float:
    u = (math.cos(math.radians(phi_deg)), math.sin(math.radians(phi_deg)))
    return max((x - part.com[0]) * u[0] + (y - part.com[1]) * u[1] for x, y in part.hull)


def test_push_bands_are_a_fixed_angle_at_ordinary_hilltops() -> None:
    """Away from shallow states each flank gets PUSH_BAND_DEG, whatever the depth there."""
    part = make_part(make_outline("tri", [(0, 0), (40, 0), (10, 30)]))
    vib = 1e-3 * part.size
    mech = uncertain_mechanics(part, Uncertainty(1.0), vibration_mm=vib)
    assert len(mech.bands) == 3
    for band in mech.bands:
        assert band.divergent_deg - band.lo_deg == pytest.approx(PUSH_BAND_DEG, abs=1e-9)
        assert band.hi_deg - band.divergent_deg == pytest.approx(PUSH_BAND_DEG, abs=1e-9)
        # The depth rule would give 3.6-5 degrees here: the fixed band is narrower.
        assert _radius_at(part, band.lo_deg) > _radius_at(part, band.divergent_deg) - 2 * vib
        inside = band.divergent_deg - 0.9 * PUSH_BAND_DEG
        outside = band.divergent_deg - 1.1 * PUSH_BAND_DEG
        sides = {mech.state_of[band.left], mech.state_of[band.right]}
        assert sides <= fence_outcomes(mech, inside, inside)
        assert fence_outcomes(mech, outside, outside) == {mech.state_of[band.left]}
    # With shape and COM tolerance the push band widens the F2 band by the same angle.
    unc = Uncertainty(1.0, 0.01, 0.02)
    tol = uncertain_mechanics(part, unc, vibration_mm=vib)
    f2 = uncertain_mechanics(part, unc, vibration_mm=0.0)
    for band, inner in zip(tol.bands, f2.bands, strict=True):
        assert band.lo_deg == pytest.approx(inner.lo_deg - PUSH_BAND_DEG, abs=1e-9)
        assert band.hi_deg == pytest.approx(inner.hi_deg + PUSH_BAND_DEG, abs=1e-9)
    # The ideal model keeps its point bands.
    ideal = uncertain_mechanics(part, IDEAL)
    assert all(b.lo_deg == b.divergent_deg == b.hi_deg for b in ideal.bands)


def test_push_bands_do_not_depend_on_size_or_depth_at_ordinary_hilltops() -> None:
    """Parts with the same push function get the same bands (so Lemma 8 twins stay alike):
    the look-alike of the quadrilateral, and a part and its scaled copy."""
    from feederkit.mix.lookalike import build_lookalike

    original = catalog_part("quadrilateral")
    twin = build_lookalike(original, "push-diameter", 0).part
    big = make_part(make_outline("big", [(3 * x, 3 * y) for x, y in original.outline.vertices]))
    ref = uncertain_mechanics(original, Uncertainty(1.0))
    assert not np.allclose(
        [_radius_at(original, b.divergent_deg) for b in ref.bands],
        [_radius_at(twin, b.divergent_deg) for b in ref.bands],
    )
    for other in (twin, big):
        mech = uncertain_mechanics(other, Uncertainty(1.0))
        assert len(mech.bands) == len(ref.bands)
        for a, b in zip(ref.bands, mech.bands, strict=True):
            assert b.divergent_deg == pytest.approx(a.divergent_deg, abs=1e-6)
            assert b.lo_deg == pytest.approx(a.lo_deg, abs=1e-6)
            assert b.hi_deg == pytest.approx(a.hi_deg, abs=1e-6)


def test_push_bands_stop_at_a_shallow_neighbour_state() -> None:
    """The gear's tooth tips: two hills 2.75 degrees apart around a shallow state (0.005 mm
    deep, below SHALLOW_WELL_FACTOR vibrations); both bands end at its normal, their far flanks
    get the depth rule, and a push starting 3 degrees before either hilltop, on the far side
    from the tip, may end on the tip (the physics check saw it)."""
    if not GEAR.exists():
        pytest.skip(f"sample drawing not found: {GEAR}")
    pf = push_function(load_part(str(GEAR)))
    mech = uncertain_mechanics(pf.part, Uncertainty(1.0))
    tip = min(pf.states, key=lambda s: s.resting_range_deg[1] - s.resting_range_deg[0])
    touching = [b for b in mech.bands if tip.id in (b.left, b.right)]
    assert len(touching) == 2
    ideal = uncertain_mechanics(pf.part, Uncertainty(1.0), vibration_mm=0.0)
    for b in touching:
        tip_end = b.lo_deg if b.left == tip.id else b.hi_deg
        assert circ(tip_end, tip.normal_deg) == pytest.approx(0.0, abs=1e-9)
        # The far flank, beside a deep root, gets the depth rule, not the fixed angle.
        far_end, root = (b.hi_deg, b.right) if b.left == tip.id else (b.lo_deg, b.left)
        peak = _radius_at(pf.part, b.divergent_deg)
        vib = mech.vibration_mm
        assert peak - _radius_at(pf.part, tip.normal_deg) < SHALLOW_WELL_FACTOR * vib
        assert peak - _radius_at(pf.part, pf.states[root].normal_deg) > SHALLOW_WELL_FACTOR * vib
        assert _radius_at(pf.part, far_end) == pytest.approx(
            peak - PUSH_BAND_FACTOR * vib, abs=1e-9
        )
        assert circ(far_end, b.divergent_deg) > PUSH_BAND_DEG + 1.0
        start = b.divergent_deg + (3.0 if b.left == tip.id else -3.0)
        assert mech.state_of[tip.id] in fence_outcomes(mech, start, start)
        assert mech.state_of[tip.id] not in fence_outcomes(ideal, start, start)


# --- a push band clipped at a neighbouring state's normal --------------------------------------


def _open_cell_at(mech, theta: float):  # noqa: ANN202
    return next(c for c in mech.cells if not c.closed and c.lo < theta < c.hi)


def _chorded_slot(fx, tmp_path: Path):  # noqa: ANN001, ANN202
    """The 60 x 20 mm slot drawing on a hull simplified at 0.05 mm, whose chords make shallow
    tip states (the import keeps a smaller tolerance, on which the tips roll: these tests are
    about the mechanics of such states)."""
    part = load_part(str(fx.write_slot(tmp_path / "slot.dxf")))
    return make_part(part.outline, part.com, hull_tolerance=0.05)


def test_a_slot_is_oriented_onto_a_flat_side_without_a_sensor(tmp_path: Path) -> None:
    """A 60 x 20 mm slot: its tip states (0 and 180 degrees) are shallow, so the push bands of
    the hilltops beside them end exactly at their normals. A push from deep inside a flat
    side's basin crosses no hilltop and ends on that side only; rotating 45 degrees sends
    every state onto one of the flat sides (the user's drawing; it once had no strong plan at
    any rotation error above 0, the tips counted as reachable from the gap)."""
    import fixtures_cad as fx

    from feederkit.machine import build_machine
    from feederkit.planning.api import plan
    from feederkit.sensors import NoSensor

    pf = push_function(_chorded_slot(fx, tmp_path))
    mech = uncertain_mechanics(pf.part, Uncertainty(1.0))
    assert mech.n == pf.n == 4
    tips = [s for s in pf.states if min(circ(s.normal_deg, 0.0), circ(s.normal_deg, 180.0)) < 1e-6]
    flats = [s for s in pf.states if s not in tips]
    assert len(tips) == len(flats) == 2
    for flat in flats:
        own = mech.state_of[flat.id]
        cell = _open_cell_at(mech, flat.normal_deg)
        assert cell.targets == {own}
        assert cell.hi - cell.lo > 160.0  # the band ends: a tip's normal, 6.3 deg from it
    for s in mech.states:  # no interval reversed by rounding at 0/360
        assert s.rest_deg[0] <= s.rest_deg[1]
    for b in mech.bands:  # t = c = 0: every hilltop is the drawn one
        assert b.top_lo_deg == b.divergent_deg == b.top_hi_deg
    for tip in tips:
        # Both bands beside a tip end at its normal, and from a band the tip is reachable.
        touching = [b for b in mech.bands if tip.id in (b.left, b.right)]
        assert len(touching) == 2
        for b in touching:
            end = b.lo_deg if b.left == tip.id else b.hi_deg
            assert circ(end, tip.normal_deg) < 1e-9
            mid = (b.lo_deg + b.hi_deg) / 2.0
            assert mech.state_of[tip.id] in fence_outcomes(mech, mid, mid)
    for flat in flats:
        assert outcome_set(mech, mech.state_of[flat.id], 45.0) == {
            mech.state_of[f.id] for f in flats if circ(f.normal_deg, flat.normal_deg - 45.0) < 90
        }
    result = plan(build_machine([pf], NoSensor(), Uncertainty(1.0)))
    assert result.length == 2


def test_a_slot_with_shape_and_com_tolerance_keeps_its_hills_and_its_plan(tmp_path: Path) -> None:
    """The slot at shape 0.005 mm, COM 0.01 mm: no hilltop is sure (each beside a tip is only
    0.0044 mm above the tip state, below 2 (t + c) = 0.03 mm), but the tip state and its two
    hilltops form one certain hill between the flat sides' wells (about 20 mm higher). Its band
    holds every perturbed maximum, so a push from deep in a flat side's basin ends on that
    side only, and rotating about 45 degrees still sends every state onto a flat side. (It had
    no strong plan: without a band the circle was one cell.)"""
    import fixtures_cad as fx

    from feederkit.machine import build_machine
    from feederkit.mechanics.uncertain import _radius
    from feederkit.planning.api import plan
    from feederkit.sensors import NoSensor

    unc = Uncertainty(1.0, 0.005, 0.01)
    eps = unc.shape_tolerance_mm + unc.com_tolerance_mm
    pf = push_function(_chorded_slot(fx, tmp_path))
    mech = uncertain_mechanics(pf.part, unc)
    h, com = np.asarray(pf.part.hull), np.asarray(pf.part.com)
    peaks = _radius(h, com, np.asarray(pf.divergent_deg))
    wells = _radius(h, com, np.asarray([pf.states[i].normal_deg for i in pf.range_state]))
    m = len(peaks)
    assert all(
        peaks[k] - max(wells[k - 1], wells[k]) < 2.0 * eps for k in range(m)
    )  # no hilltop is sure on its own
    tips = [s for s in pf.states if min(circ(s.normal_deg, 0.0), circ(s.normal_deg, 180.0)) < 1e-6]
    flats = [s for s in pf.states if s not in tips]
    assert len(mech.bands) == 2
    for b in mech.bands:
        assert {b.left, b.right} == {f.id for f in flats}
        tip = next(s for s in tips if circ(s.normal_deg, b.divergent_deg) < 2.0)
        at = b.divergent_deg + (norm360(tip.normal_deg - b.divergent_deg + 180.0) - 180.0)
        assert b.lo_deg < b.top_lo_deg < at < b.top_hi_deg < b.hi_deg
    for flat in flats:
        cell = next(
            c
            for c in mech.cells
            if not c.closed and c.lo < c.lo + norm360(flat.normal_deg - c.lo) < c.hi
        )
        assert cell.targets == {mech.state_of[flat.id]}
        assert cell.hi - cell.lo > 160.0
        assert fence_outcomes(mech, flat.normal_deg, flat.normal_deg) == {mech.state_of[flat.id]}
    result = plan(build_machine([pf], NoSensor(), unc))
    assert result.length == 2


def test_certain_hills_are_the_minimal_certain_runs() -> None:
    """Against brute force on random profiles: every run of hilltops whose highest one stands
    more than 2 eps above both its wells holds one of the returned runs, the returned runs are
    certain, minimal and do not overlap, and a lone sure hilltop is a run of its own."""
    from feederkit.mechanics.uncertain import _certain_hills

    rng = np.random.default_rng(5)
    for _ in range(300):
        m = int(rng.integers(2, 9))
        wells = rng.uniform(0.0, 1.0, m)
        peaks = np.maximum(wells, np.roll(wells, 1)) + rng.uniform(0.0, 0.3, m)
        eps = float(rng.uniform(0.01, 0.2))

        def certain(k: int, e: int, peaks=peaks, wells=wells, eps=eps, m=m) -> bool:  # noqa: ANN001
            top = max(peaks[i % m] for i in range(k, e + 1))
            return top - max(wells[(k - 1) % m], wells[e % m]) > 2.0 * eps

        runs = [(k, k + p) for k in range(m) for p in range(m - 1) if certain(k, k + p)]
        minimal = {
            (k, e)
            for k, e in runs
            if not any(
                (k2 % m, e2) != (k, e) and k <= k2 + shift and e2 + shift <= e
                for k2, e2 in runs
                for shift in (0, m)
            )
        }
        got = _certain_hills(peaks, wells, eps)
        assert set(got) == minimal
        covered = [i % m for k, e in got for i in range(k, e + 1)]
        assert len(covered) == len(set(covered))
        for k in range(m):
            if certain(k, k):
                assert (k, k) in got


def test_a_push_from_a_gap_does_not_reach_a_state_beyond_a_clipped_push_band() -> None:
    """The l-bracket at shape 0.005 mm, COM 0.01 mm: the push band of the hilltop at 3 degrees
    is clipped at state 1's normal (0 degrees), whose normal arc (+-0.04 degrees) reaches past
    that end. A push starting between the bands cannot pass the hilltop (F2: within
    2.96-3.00 degrees), so it ends on state 2 only; from inside the band either side."""
    part = catalog_part("l-bracket")
    pf = push_function(part)
    mech = uncertain_mechanics(part, Uncertainty(1.0, 0.005, 0.01))
    band = next(b for b in mech.bands if circ(b.divergent_deg, 3.0) < 0.5)
    assert circ(band.lo_deg, pf.states[band.left].normal_deg) < 1e-9
    left, right = mech.state_of[band.left], mech.state_of[band.right]
    deep = pf.states[band.right].normal_deg
    assert _open_cell_at(mech, deep).targets == {right}
    start = (band.lo_deg + band.hi_deg) / 2.0
    assert {left, right} <= fence_outcomes(mech, start, start)
    assert band.lo_deg < band.top_lo_deg <= band.divergent_deg <= band.top_hi_deg < band.hi_deg
