"""The uncertain push-align machine: states from physical resting states, outcome sets,
readings from diameter intervals, and the inseparability (bisimulation) goal.

References written here from the definitions (docs/planning.md, "Strong plans"): reading
sets sampled point by point, the greatest bisimulation by brute force over a fine grid of
rotations; the ideal machine as the special case of the uncertain one.
"""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest
from test_strong_plans import convex_hull

from feederkit.angles import ActionRange
from feederkit.machine import (
    MachineState,
    OutcomeRange,
    PushAlignMachine,
    build_machine,
    inseparable,
    is_goal,
    members,
    overlap_cells,
)
from feederkit.machine.build import uncertain_machine
from feederkit.mechanics import push_function
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.outline import load_outline_json, make_outline
from feederkit.part import make_part
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

CATALOG = Path(__file__).resolve().parent.parent / "catalog"


def catalog_pfs():
    out = []
    for path in sorted(CATALOG.glob("*.json")):
        out.append(push_function(make_part(load_outline_json(path))))
    return out


def random_pf(seed: int, n: int = 6):
    rng = random.Random(seed)
    while True:
        pts = [[rng.uniform(-10, 10), rng.uniform(-10, 10)] for _ in range(n)]
        hull = convex_hull(pts)
        if len(hull) >= 3:
            return push_function(make_part(make_outline(f"r{seed}", [list(p) for p in hull])))


# --- the ideal machine is the special case --------------------------------------------------


def test_ideal_uncertainty_builds_exactly_the_ideal_machine():
    pfs = catalog_pfs()
    for pf in pfs:
        a = build_machine([pf], ToleranceSensor(0.1), IDEAL)
        b = build_machine([pf], ToleranceSensor(0.1), Uncertainty(0, 0, 0))
        assert a == b and a.deterministic and a.uncertainty.is_ideal


def test_uncertain_machine_at_zero_uncertainty_has_the_ideal_ranges():
    """The uncertain construction fed the ideal mechanics: one state per stable state,
    singleton outcome sets, the ideal action ranges (to rounding) and exact diameters."""
    for pf in catalog_pfs():
        ideal = build_machine([pf], NoSensor(), IDEAL)
        mech = uncertain_mechanics(pf.part, IDEAL)
        m = uncertain_machine([pf], [mech], NoSensor())
        assert m.n == ideal.n and m.deterministic
        for s, t in zip(m.states, ideal.states, strict=True):
            assert s.state == t.state
            assert s.diameter_range is not None
            assert s.diameter_range[0] == pytest.approx(t.diameter, abs=1e-9)
            assert s.diameter_range[1] == pytest.approx(t.diameter, abs=1e-9)
        for i in range(m.n):
            for a in [k + 0.37 for k in range(0, 360, 7)]:
                assert m.outcomes(i, a) == ideal.outcomes(i, a) or _near_boundary(ideal, i, a)


def _near_boundary(machine, i, a, eps=1e-6):
    return any(
        min(abs((a - r.lo + 180) % 360 - 180), abs((a - r.hi + 180) % 360 - 180)) < eps
        for r in machine.action_maps[i]
    )


def test_default_uncertainty_is_one_degree_and_outcomes_are_sets():
    pf = random_pf(3)
    m = build_machine([pf], NoSensor())
    assert m.uncertainty == Uncertainty(1.0, 0.0, 0.0)
    assert not m.deterministic
    sizes = {bin(mask).count("1") for masks in m.outcomes_of for mask in masks}
    assert 1 in sizes and max(sizes) >= 2


def test_outcome_sets_contain_the_ideal_outcomes_of_every_rotation_within_the_error():
    """Rotation error alone: the outcome set of rotation a holds the ideal successor of every
    rotation in [a - r, a + r] (sampled), for states that did not merge."""
    for seed in range(8):
        pf = random_pf(seed, 7)
        unc = Uncertainty(2.0)
        mech = uncertain_mechanics(pf.part, unc)
        if mech.n != pf.n:
            continue
        m = build_machine([pf], NoSensor(), unc)
        ideal = build_machine([pf], NoSensor(), IDEAL)
        rng = random.Random(seed)
        for _ in range(200):
            i = rng.randrange(m.n)
            a = rng.uniform(0, 360)
            got = m.outcomes(i, a)
            for err in (-2.0, -1.0, 0.0, 1.0, 2.0, rng.uniform(-2, 2)):
                if _near_boundary(ideal, i, a + err, 1e-7):
                    continue
                assert got & ideal.outcomes(i, a + err)  # the ideal successor is an outcome


def test_overlap_cells_keep_the_image():
    """On each overlap range of a set the union of its members' outcome sets is the range's
    image everywhere (sampled): a rotation error up to the margin beyond the declared one
    keeps every outcome inside it. Neighbours with equal images are merged, as in the ideal
    model."""
    pf = random_pf(11, 8)
    m = build_machine([pf], ToleranceSensor(0.2), Uncertainty(1.5))
    rng = random.Random(2)
    for _ in range(20):
        mask = rng.randrange(1, 1 << m.n)
        cells = overlap_cells(m, mask)
        assert all(a[2] != b[2] for a, b in zip(cells, cells[1:], strict=False))
        for lo, hi, img in cells:
            for a in (lo + (hi - lo) * f for f in (0.01, 0.1, 0.5, 0.9, 0.99)):
                u = 0
                for i in members(mask):
                    u |= m.outcomes(i, a)
                assert u == img


# --- readings from intervals ----------------------------------------------------------------


@pytest.mark.parametrize("e", [0.05, 0.3, 1.0])
def test_interval_branches_match_readings_point_by_point(e):
    rng = random.Random(int(e * 100))
    sensor = ToleranceSensor(e)
    for _ in range(30):
        ivs = []
        for _ in range(rng.randint(1, 6)):
            lo = rng.uniform(1, 6)
            ivs.append((lo, lo + rng.choice([0.0, rng.uniform(0, 1.5)])))
        branches = sensor.split(ivs)
        for _ in range(200):
            x = rng.uniform(0, 9)
            want = {j for j, (lo, hi) in enumerate(ivs) if lo - e < x < hi + e}
            holding = [b for b in branches if b.lo <= x <= b.hi]
            if not want:
                assert all(x in (b.lo, b.hi) for b in holding)
                continue
            assert holding, x
            for b in holding:
                got = set(b.members)
                assert want <= got or x in (b.lo, b.hi)
                assert got <= want or x in (b.lo, b.hi)
            for j, iv in enumerate(ivs):
                assert sensor.consistent(iv, x) == (j in want)


def test_point_intervals_branch_as_exact_diameters():
    for sensor in (ToleranceSensor(0.2), LedSensor(0.5, 0.1)):
        ds = [3.0, 3.3, 4.1, 4.15, 7.0]
        assert sensor.split(ds) == sensor.split([(d, d) for d in ds])
        assert sensor.can_read_alike(3.0, 3.3) == sensor.can_read_alike((3.0, 3.0), (3.3, 3.3))


def test_uncovered_reading_is_exact_for_tolerance_and_led():
    s = ToleranceSensor(0.5)
    assert s.uncovered_reading((2.0, 3.0), [(1.5, 2.5), (2.5, 3.5)]) is None
    gap = s.uncovered_reading((2.0, 3.0), [(1.5, 2.4), (2.5, 3.5)])
    assert gap is not None and 2.4 < gap < 2.5
    assert s.uncovered_reading((2.0, 3.0), [(1.5, 3.4)]) is not None  # 3.4 .. 3.5 missing
    led = LedSensor(1.0)
    assert led.uncovered_reading((2.5, 4.5), [(2.0, 3.0), (4.0, 4.0)]) is None
    assert led.uncovered_reading((2.5, 4.5), [(2.0, 2.0), (4.0, 4.0)]) == 3.0
    assert NoSensor().uncovered_reading((1.0, 2.0), []) is None


# --- the goal: inseparable = bisimilar ------------------------------------------------------


def reference_bisimulation(machine: PushAlignMachine, step: float = 0.05) -> set[tuple[int, int]]:
    """The greatest bisimulation by brute force: rotations on a fine grid (plus every
    boundary's neighbours), outcomes looked up here, iterated to a fixpoint."""
    bounds = sorted({r.lo % 360 for rs in machine.action_maps for r in rs})
    grid = {k * step + step / 3 for k in range(int(360 / step))}
    grid |= {(b + d) % 360 for b in bounds for d in (-1e-6, 1e-6)}

    def out(i, a):
        for r in machine.action_maps[i]:
            x = (a - r.lo) % 360
            if 0 < x < r.hi - r.lo:
                return r.targets if isinstance(r, OutcomeRange) else 1 << r.target
        raise AssertionError("no range holds the rotation")

    n = machine.n
    sensor = machine.sensor
    rel = {
        (i, j)
        for i in range(n)
        for j in range(i + 1, n)
        if sensor.can_read_alike(machine.states[i].sensed, machine.states[j].sensed)
    }
    table = {i: [out(i, a) for a in sorted(grid)] for i in range(n)}

    def linked(x, y):
        return x != y and (min(x, y), max(x, y)) in rel

    while True:
        drop = set()
        for i, j in rel:
            for a, b in zip(table[i], table[j], strict=True):
                xs, ys = members(a), members(b)
                if not all(any(linked(x, y) for y in ys) for x in xs) or not all(
                    any(linked(x, y) for x in xs) for y in ys
                ):
                    drop.add((i, j))
                    break
        if not drop:
            return rel
        rel -= drop


def _pairs(masks):
    return {(i, j) for i, m in enumerate(masks) for j in members(m) if i < j}


def random_machine(seed: int, n: int) -> PushAlignMachine:
    """A hand-built nondeterministic machine: random ranges with random outcome sets."""
    rng = random.Random(seed)
    states = tuple(
        MachineState(0, i, float(rng.choice([1, 2])), 1.0 / n, (1.0, 1.0 + rng.choice([0, 0.5])))
        for i in range(n)
    )
    maps = []
    for _ in range(n):
        cuts = sorted(rng.sample(range(1, 36), rng.randint(1, 4)))
        los = [0.0] + [10.0 * c for c in cuts]
        his = los[1:] + [360.0]
        maps.append(
            tuple(
                OutcomeRange(
                    lo,
                    hi,
                    rng.randrange(1, 1 << n) if rng.random() < 0.3 else 1 << rng.randrange(n),
                )
                for lo, hi in zip(los, his, strict=True)
            )
        )
    return PushAlignMachine(("hand",), states, tuple(maps), ToleranceSensor(0.3))


def _random_targets(rng: random.Random, n: int) -> int:
    return rng.randrange(1, 1 << n) if rng.random() < 0.3 else 1 << rng.randrange(n)


@pytest.mark.parametrize("seed", range(40))
def test_bisimulation_matches_the_brute_force_reference_on_hand_machines(seed):
    m = random_machine(seed, 3 + seed % 4)
    assert _pairs(inseparable(m)) == reference_bisimulation(m, step=1.0)


def test_bisimulation_matches_the_reference_on_uncertain_parts():
    rect = push_function(make_part(make_outline("rect", [[-2, -1], [2, -1], [2, 1], [-2, 1]])))
    hexa = [[math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)] for k in range(6)]
    hexa_pf = push_function(make_part(make_outline("hexa", hexa)))
    cases = [(random_pf(seed, 6), NoSensor()) for seed in range(3)]
    cases += [(rect, NoSensor()), (hexa_pf, ToleranceSensor(0.01)), (rect, ToleranceSensor(0.5))]
    found = 0
    for pf, sensor in cases:
        m = build_machine([pf], sensor, Uncertainty(1.0))
        got = _pairs(inseparable(m))
        assert got == reference_bisimulation(m, step=0.1)
        found += len(got)
    assert found >= 4  # the symmetric parts have inseparable pairs


def test_symmetric_poses_and_lemma_8_twins_stay_inseparable():
    rect = [[-2, -1], [2, -1], [2, 1], [-2, 1]]
    pf = push_function(make_part(make_outline("rect", rect)))
    for unc in (Uncertainty(1.0), Uncertainty(3.0), Uncertainty(1.0, 0.01, 0.01)):
        m = build_machine([pf], NoSensor(), unc)
        insep = inseparable(m)
        assert m.n == 4
        for i in range(4):  # the opposite edge is the same pose up to the 180 deg symmetry
            assert insep[i] == 1 << ((i + 2) % 4)
        assert is_goal(insep, 0b0101) and not is_goal(insep, 0b0011)
    twin = push_function(make_part(make_outline("twin", rect)))
    m = build_machine([pf, twin], ToleranceSensor(0.1), Uncertainty(1.0))
    insep = inseparable(m)
    for i in range(4):
        assert insep[i] >> (i + 4) & 1  # the twin's same state


def test_deterministic_and_bisimulation_goals_agree_on_singleton_outcomes():
    """A machine with OutcomeRange singletons is the ideal machine: same inseparable pairs."""
    for pf in catalog_pfs()[:6]:
        ideal = build_machine([pf], ToleranceSensor(0.05), IDEAL)
        maps = tuple(
            tuple(OutcomeRange(r.lo, r.hi, 1 << r.target) for r in rs) for rs in ideal.action_maps
        )
        twin = PushAlignMachine(ideal.part_names, ideal.states, maps, ideal.sensor)
        assert twin.deterministic
        assert inseparable(twin) == inseparable(ideal)
        assert isinstance(ideal.action_maps[0][0], ActionRange)
