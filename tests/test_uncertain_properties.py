"""The uncertain mechanics against an independent brute-force model (hypothesis, derandomized).

The reference here shares no code with feederkit's mechanics: its own hull, its own radius
function on a dense grid, a quasi-static descent toward the local minimum, and vibration that
carries a resting part over any barrier lower than the model's vibration. It samples shapes in
the tolerance zone (every vertex moved by at most t, the COM by at most c) and rotation errors
in the bound, and checks that every sampled rest lies in the computed outcome set and every
sampled reading in the computed diameter interval. ``test_price_of_conservatism`` (slow)
prints how much larger the computed sets are than the sampled envelope (docs/uncertainty.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from feederkit.mechanics.certificates import max_rotation_error
from feederkit.mechanics.outcomes import fence_outcomes, outcome_set
from feederkit.mechanics.uncertain import UncertainMechanics, uncertain_mechanics
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sources import load_part
from feederkit.uncertainty import Uncertainty, com_clearance, max_shape_tolerance

FAST = settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow],
)
SLOW = settings(FAST, max_examples=600)
TOL = 1e-7  # degrees: membership tolerance for exact orientations
CATALOG = Path(__file__).resolve().parents[1] / "catalog"


# --- the independent reference --------------------------------------------------------------


def hull_of(pts: np.ndarray) -> np.ndarray:
    """Monotone chain, counter-clockwise, collinear points dropped."""
    p = sorted(map(tuple, pts.tolist()))

    def half(seq: list) -> list:
        out: list = []
        for q in seq:
            while (
                len(out) >= 2
                and (
                    (out[-1][0] - out[-2][0]) * (q[1] - out[-2][1])
                    - (out[-1][1] - out[-2][1]) * (q[0] - out[-2][0])
                )
                <= 0
            ):
                out.pop()
            out.append(q)
        return out

    return np.asarray(half(p)[:-1] + half(p[::-1])[:-1], dtype=float)


def off(x: float, ref: float) -> float:
    """Signed angle from ref to x in [-180, 180)."""
    return (x - ref + 180.0) % 360.0 - 180.0


@dataclass
class Shape:
    """A perturbed part (hull CCW, COM) and its exact quasi-static push, event by event.

    On the normal cone of vertex j (between the normals of edges j - 1 and j) the radius
    function is ``rho_j cos(phi - alpha_j)``: the part turns away from ``alpha_j`` to the end of
    the cone, and rests on the edge there if the radius rises again beyond it.
    """

    hull: np.ndarray
    com: np.ndarray

    def __post_init__(self) -> None:
        d = np.roll(self.hull, -1, axis=0) - self.hull
        self.nrm = np.mod(np.degrees(np.arctan2(-d[:, 0], d[:, 1])), 360.0).tolist()
        rel = self.hull - self.com
        self.rho = np.hypot(rel[:, 0], rel[:, 1]).tolist()
        self.alpha = np.degrees(np.arctan2(rel[:, 1], rel[:, 0])).tolist()
        self.k = len(self.hull)

    def cone(self, theta: float) -> int:
        """The vertex whose normal cone holds theta."""
        for j in range(self.k):
            lo, hi = self.nrm[j - 1], self.nrm[j]
            if 0.0 <= (theta - lo) % 360.0 < (hi - lo) % 360.0:
                return j
        raise AssertionError(theta)

    def edge_height(self, e: int) -> float:
        u = np.array([math.cos(math.radians(self.nrm[e])), math.sin(math.radians(self.nrm[e]))])
        return float((self.hull[e] - self.com) @ u)

    def descend(self, theta: float) -> int:
        """The edge the part comes to rest on from fence orientation theta."""
        j = self.cone(theta)
        step = 1 if off(theta, self.alpha[j]) > 0.0 else -1
        for _ in range(self.k + 1):
            e = j if step > 0 else (j - 1) % self.k  # the edge at the end of the cone
            nxt = (e + 1) % self.k if step > 0 else e  # the vertex beyond that edge
            if step * off(self.nrm[e], self.alpha[nxt]) < 0.0:
                return e  # the radius rises again past the edge: it rests here
            j = nxt
        raise AssertionError("no resting edge")

    def hilltop(self, e: int, step: int) -> tuple[float, float]:
        """Direction and height of the radius maximum next to edge e's rest, toward ``step``."""
        j = (e + 1) % self.k if step > 0 else e
        for _ in range(self.k + 1):
            lo, hi = self.nrm[j - 1], self.nrm[j]
            if 0.0 <= (self.alpha[j] - lo) % 360.0 <= (hi - lo) % 360.0:
                return self.alpha[j], self.rho[j]
            j = (j + step) % self.k
        raise AssertionError("no hilltop")

    def width(self, phi: float) -> float:
        u = np.array([math.cos(math.radians(phi)), math.sin(math.radians(phi))])
        p = self.hull @ u
        return float(p.max() - p.min())

    def rest_from(self, theta: float, vibration: float) -> float:
        """Push from fence orientation theta; vibration carries it over barriers below its own."""
        e = self.descend(theta % 360.0)
        for _ in range(self.k + 2):
            h = self.edge_height(e)
            (a_lo, r_lo), (a_hi, r_hi) = self.hilltop(e, -1), self.hilltop(e, 1)
            if min(r_lo, r_hi) - h >= vibration:
                break
            over = a_lo - 1e-6 if r_lo <= r_hi else a_hi + 1e-6
            e = self.descend(over % 360.0)
        return float(self.nrm[e])


def perturb(hull, com, t: float, c: float, rng: np.random.Generator) -> Shape:
    """Every vertex within t of its place, the COM within c (corners of the zone favoured)."""

    def disc(n: int, radius: float) -> np.ndarray:
        ang = rng.uniform(0.0, 2 * math.pi, n)
        rad = radius * np.where(rng.random(n) < 0.5, 1.0, np.sqrt(rng.random(n)))
        return np.stack([rad * np.cos(ang), rad * np.sin(ang)], axis=-1)

    h = np.asarray(hull, dtype=float)
    moved = h + disc(len(h), t) if t > 0 else h
    cm = np.asarray(com, dtype=float) + (disc(1, c)[0] if c > 0 else 0.0)
    return Shape(hull_of(moved), cm)


# --- the computed sets ------------------------------------------------------------------------


def in_arc(x: float, lo: float, hi: float) -> bool:
    return hi - lo >= 360.0 or (x - lo) % 360.0 <= hi - lo + TOL or (lo - x) % 360.0 <= TOL


def states_at(mech: UncertainMechanics, nu: float) -> list[int]:
    return [s.id for s in mech.states if in_arc(nu, *s.rest_deg)]


@st.composite
def cases(draw):
    """A random convex-ish polygon, a COM inside, an uncertainty within the bounds, a seed."""
    n = draw(st.integers(3, 7))
    gaps = np.asarray(draw(st.lists(st.floats(1.0, 3.0), min_size=n, max_size=n)))
    angles = (np.cumsum(gaps) / gaps.sum() * 360.0 + draw(st.floats(0.0, 360.0))).tolist()
    radii = draw(st.lists(st.floats(0.6, 1.6), min_size=n, max_size=n))
    pts = [
        (r * math.cos(math.radians(a)), r * math.sin(math.radians(a)))
        for a, r in zip(angles, radii, strict=True)
    ]
    hull = hull_of(np.asarray(pts))
    assume(len(hull) >= 3)
    w = np.asarray(draw(st.lists(st.floats(0.2, 1.0), min_size=len(hull), max_size=len(hull))))
    com = (w[:, None] * hull).sum(axis=0) / w.sum()
    part = make_part(make_outline("random", [tuple(p) for p in hull.tolist()]), tuple(com.tolist()))
    t_frac = draw(st.sampled_from([0.0, 0.0, 0.002, 0.01, 0.03, 0.1, 0.3]))
    c = draw(st.sampled_from([0.0, 0.0, 0.005, 0.02, 0.05]))
    assume(c < com_clearance(part))  # a COM that could leave the part is refused
    r = draw(st.sampled_from([0.0, 0.5, 1.0, 3.0]))
    t = t_frac * max_shape_tolerance(part)
    seed = draw(st.integers(0, 2**31 - 1))
    return part, Uncertainty(r, t, c), seed


@dataclass
class Tally:
    """Computed against sampled: outcome set sizes and diameter interval widths."""

    computed_sizes: list[int]
    sampled_sizes: list[int]
    computed_widths: list[float]
    sampled_widths: list[float]


def check_case(part, unc: Uncertainty, seed: int, shapes: int, actions: int) -> Tally:
    """Sample shapes and rotations; every rest and reading must lie in the computed sets."""
    mech = uncertain_mechanics(part, unc)
    rng = np.random.default_rng(seed)
    t, c, r = unc.shape_tolerance_mm, unc.com_tolerance_mm, unc.rotation_error_deg
    acts = rng.uniform(0.0, 360.0, actions)
    seen: dict[tuple[int, int], set[int]] = {}
    readings: dict[int, list[float]] = {}
    for _ in range(shapes):
        shape = perturb(part.hull, part.com, t, c, rng)
        theta0 = float(rng.uniform(0.0, 360.0))
        nu0 = shape.rest_from(theta0, mech.vibration_mm)
        first = fence_outcomes(mech, theta0, theta0)
        here = states_at(mech, nu0)
        assert set(here) & first, (theta0, nu0, first, here)
        for s in here:
            lo, hi = mech.states[s].diameter
            w = shape.width(nu0)
            assert lo - 1e-9 <= w <= hi + 1e-9, (s, w, lo, hi)
            readings.setdefault(s, []).append(w)
        for k, a in enumerate(acts.tolist()):
            # Half the errors at the ends of the bound, where the sets are decided.
            err = float(rng.choice([-r, r]) if rng.random() < 0.5 else rng.uniform(-r, r))
            nu1 = shape.rest_from(nu0 - a - err, mech.vibration_mm)
            ends = set(states_at(mech, nu1))
            for s in here:
                out = outcome_set(mech, s, a)
                assert ends & out, (s, a, err, nu0, nu1, out, ends)
                seen.setdefault((s, k), set()).update(ends & out)
    tally = Tally([], [], [], [])
    for (s, k), got in seen.items():
        tally.computed_sizes.append(len(outcome_set(mech, s, float(acts[k]))))
        tally.sampled_sizes.append(len(got))
    for s, ws in readings.items():
        lo, hi = mech.states[s].diameter
        tally.computed_widths.append(hi - lo)
        tally.sampled_widths.append(max(ws) - min(ws))
    return tally


@FAST
@given(cases())
def test_sampled_outcomes_and_readings_lie_in_the_computed_sets(case) -> None:
    part, unc, seed = case
    check_case(part, unc, seed, shapes=4, actions=6)


@FAST
@given(cases())
def test_the_rotation_certificate_holds_for_sampled_errors_below_it(case) -> None:
    part, unc, seed = case
    mech = uncertain_mechanics(part, unc)
    rng = np.random.default_rng(seed)
    for _ in range(3):
        shape = perturb(part.hull, part.com, unc.shape_tolerance_mm, unc.com_tolerance_mm, rng)
        nu0 = shape.rest_from(float(rng.uniform(0.0, 360.0)), mech.vibration_mm)
        for s in states_at(mech, nu0):
            a = float(rng.uniform(0.0, 360.0))
            assumed = outcome_set(mech, s, a)
            cert = max_rotation_error(mech, [s], a)
            assert cert >= unc.rotation_error_deg
            assert outcome_set(mech, s, a, cert * (1.0 - 1e-9)) <= assumed
            if cert < 90.0:
                assert not outcome_set(mech, s, a, cert + 1e-6) <= assumed
            for err in (-cert, cert, *rng.uniform(-cert, cert, 4).tolist()):
                err *= 1.0 - 1e-9
                nu1 = shape.rest_from(nu0 - a - err, mech.vibration_mm)
                assert set(states_at(mech, nu1)) & assumed


@pytest.mark.slow
@SLOW
@given(cases())
def test_sampled_outcomes_and_readings_lie_in_the_computed_sets_many(case) -> None:
    part, unc, seed = case
    check_case(part, unc, seed, shapes=30, actions=12)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(p.stem for p in CATALOG.glob("*.json")))
@pytest.mark.parametrize(
    "unc", [Uncertainty(), Uncertainty(1.0, 0.005, 0.01), Uncertainty(2.0, 0.02, 0.05)]
)
def test_catalog_parts_against_the_reference(name: str, unc: Uncertainty) -> None:
    part = load_part(str(CATALOG / f"{name}.json"))
    unc = Uncertainty(
        unc.rotation_error_deg,
        min(unc.shape_tolerance_mm, 0.3 * max_shape_tolerance(part)),
        unc.com_tolerance_mm,
    )
    check_case(part, unc, seed=7, shapes=40, actions=20)


@pytest.mark.slow
def test_price_of_conservatism(capsys) -> None:  # noqa: ANN001
    """Print the mean outcome-set size ratio and diameter widening (docs/uncertainty.md)."""
    tallies: list[Tally] = []

    @settings(SLOW, max_examples=150)
    @given(cases())
    def run(case) -> None:
        part, unc, seed = case
        assume(not unc.is_ideal)
        tallies.append(check_case(part, unc, seed, shapes=20, actions=10))

    run()
    comp = np.concatenate([np.asarray(t.computed_sizes, float) for t in tallies])
    samp = np.concatenate([np.asarray(t.sampled_sizes, float) for t in tallies])
    cw = np.concatenate([np.asarray(t.computed_widths, float) for t in tallies])
    sw = np.concatenate([np.asarray(t.sampled_widths, float) for t in tallies])
    with capsys.disabled():
        print(
            f"\nparts {len(tallies)}, (state, action) pairs {len(comp)}: mean outcome-set size "
            f"computed {comp.mean():.3f} vs sampled {samp.mean():.3f} (ratio "
            f"{(comp / samp).mean():.3f}, exact in {np.mean(comp == samp):.1%}); diameter "
            f"intervals {len(cw)}: mean width computed {cw.mean():.4f} mm vs sampled "
            f"{sw.mean():.4f} mm (mean widening {(cw - sw).mean():.4f} mm)"
        )
    assert (comp >= samp).all()


# --- every fence cell against the reference: pushes from inside it end in its targets -------


SAMPLES = Path(__file__).resolve().parents[2] / "shared" / "samples"


def _slot_outline(facets: int = 19):  # noqa: ANN202
    """A 60 x 20 slot, each semicircular end flattened to ``facets`` edges (one at its tip)."""
    pts = []
    for cx, a0 in ((50.0, -90.0), (10.0, 90.0)):
        for k in range(facets + 1):
            a = math.radians(a0 + 180.0 * k / facets)
            pts.append((cx + 10.0 * math.cos(a), 10.0 + 10.0 * math.sin(a)))
    return make_part(make_outline("slot", pts))


@pytest.mark.parametrize(
    ("source", "unc"),
    [
        ("slot.dxf", Uncertainty(1.0)),
        ("slot.dxf", Uncertainty(1.0, 0.005, 0.01)),
        ("slot-outline", Uncertainty(1.0)),
        ("slot-outline", Uncertainty(1.0, 0.005, 0.01)),
        ("l-bracket", Uncertainty(1.0, 0.005, 0.01)),
        ("l-bracket", Uncertainty(2.0, 0.02, 0.05)),
        ("cadquery__gear.dxf", Uncertainty(1.0)),
        ("cadquery__gear.dxf", Uncertainty(1.0, 0.005, 0.01)),
        ("cadquery__vslot-2020_1.dxf", Uncertainty(1.0, 0.005, 0.01)),
        ("trimesh__wrench.dxf", Uncertainty(1.0, 0.005, 0.01)),
    ],
)
def test_pushes_sampled_in_each_fence_cell_end_in_its_targets(source, unc, tmp_path) -> None:
    """Orientations sampled in every fence cell (the bands' push bands too, where the
    reference's plain descent is one of the outcomes), each pushed on a shape perturbed within
    the tolerance: the rest lies in a target of the cell, and at t = c = 0 the ideal push's
    state is a target. The slot's and the l-bracket's push bands end at a neighbouring state's
    normal (the cells narrowed to what no push from them can leave)."""
    from feederkit.mechanics import push, push_function

    if source == "slot.dxf":
        import fixtures_cad as fx

        part = load_part(str(fx.write_slot(tmp_path / source)))
    elif source == "slot-outline":
        part = _slot_outline()
    elif source.endswith(".dxf"):
        if not (SAMPLES / source).exists():
            pytest.skip(f"sample drawing not found: {SAMPLES / source}")
        part = load_part(str(SAMPLES / source))
    else:
        part = load_part(str(CATALOG / f"{source}.json"))
    mech = uncertain_mechanics(part, unc)
    pf = push_function(part)
    ideal = unc.shape_tolerance_mm == unc.com_tolerance_mm == 0.0
    rng = np.random.default_rng(11)
    for cell in mech.cells:
        if cell.hi - cell.lo < 1e-9:
            continue
        for theta in rng.uniform(cell.lo, cell.hi, 12).tolist():
            shape = perturb(part.hull, part.com, unc.shape_tolerance_mm, unc.com_tolerance_mm, rng)
            nu = shape.rest_from(theta, mech.vibration_mm)
            assert set(states_at(mech, nu)) & cell.targets, (cell, theta, nu)
            if ideal:
                assert mech.state_of[push(pf, theta).id] in cell.targets, (cell, theta)
