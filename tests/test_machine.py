"""The push-align machine: overlap ranges, reading branches, successors and the goal."""

from __future__ import annotations

import gc
import math
import random
import weakref

import pytest

from feederkit.errors import InputError
from feederkit.machine import (
    OverlapRange,
    branches,
    build_machine,
    image,
    inseparable,
    is_goal,
    mask_of,
    members,
    overlap_cells,
    overlap_ranges,
    search_space,
    successor,
)
from feederkit.mechanics import push_function
from feederkit.mechanics.actions import merge_boundaries
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sensors import (
    LedSensor,
    NoSensor,
    ReadingBranch,
    ToleranceSensor,
    sensor_from_dict,
    sensor_warnings,
)
from feederkit.uncertainty import IDEAL


def part(name, vertices, com=None):
    return push_function(make_part(make_outline(name, vertices), com))


def regular(n, com):
    pts = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]
    return part(f"regular-{n}", pts, com)


def random_part(seed, n):
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0, 2 * math.pi) for _ in range(n))
    return part(f"r{seed}", [(30 * math.cos(t), 20 * math.sin(t)) for t in angles])


def reference_overlap_ranges(machine, mask):
    """Section 3.2.2 by the book: merge all boundaries, the image at each cell's middle."""
    bounds = merge_boundaries([[r.lo for r in machine.action_maps[i]] for i in members(mask)])
    m = len(bounds)
    cells = []
    for k in range(m):
        lo = bounds[k]
        hi = bounds[k + 1] if k + 1 < m else bounds[0] + 360.0
        cells.append([lo, hi, image(machine, mask, (lo + hi) / 2.0)])
    merged = []
    for cell in cells:
        if merged and merged[-1][2] == cell[2]:
            merged[-1][1] = cell[1]
        else:
            merged.append(cell)
    if len(merged) > 1 and merged[0][2] == merged[-1][2]:
        last = merged.pop()
        merged[0][0] = last[0] - 360.0 if last[0] > merged[0][0] else last[0]
        if merged[0][0] < 0.0:
            merged[0][0] += 360.0
            merged[0][1] += 360.0
    if len(merged) == 1:
        merged[0][0], merged[0][1] = 0.0, 360.0
    return [OverlapRange(lo, hi, img) for lo, hi, img in merged]


MACHINES = [
    build_machine([regular(n, com)], uncertainty=IDEAL)
    for n in (3, 4, 5, 8, 12, 24, 32)
    for com in ((0.0, 0.0), (0.13, 0.05), (0.02, 0.008), (1e-3, 0.0))
] + [
    build_machine([part("rect", [(0, 0), (2, 0), (2, 1), (0, 1)])], uncertainty=IDEAL),
    build_machine([random_part(s, 9) for s in range(4)], uncertainty=IDEAL),
]


@pytest.mark.parametrize(
    "machine",
    # The reference is quadratic in the set size: the large machines are the slow step.
    [pytest.param(m, marks=pytest.mark.slow) if m.n >= 18 else m for m in MACHINES],
    ids=lambda m: f"{m.part_names[0]}-{m.n}",
)
def test_overlap_ranges_match_the_reference(machine):
    rng = random.Random(machine.n)
    masks = {machine.all_states, 1, 1 << (machine.n - 1)}
    masks |= {rng.randrange(1, 1 << machine.n) for _ in range(60)}
    for mask in masks:
        got = overlap_ranges(machine, mask)
        assert got == reference_overlap_ranges(machine, mask)
        assert [(a.lo, a.hi, a.image) for a in got] == overlap_cells(machine, mask)
        # The ranges tile the circle, and every cell between boundaries inside a range (the
        # rotations strictly between two boundaries) has the range's image.
        assert abs(sum(a.hi - a.lo for a in got) - 360.0) < 1e-6
        bounds = merge_boundaries([[r.lo for r in machine.action_maps[i]] for i in members(mask)])
        cuts = bounds + [bounds[0] + 360.0]
        for lo, hi in zip(cuts, cuts[1:], strict=False):
            mid = ((lo + hi) / 2.0) % 360.0
            (a,) = [a for a in got if a.lo <= mid < a.hi or a.lo <= mid + 360.0 < a.hi]
            assert image(machine, mask, mid) == a.image
        # Merged as far as it goes: neighbouring ranges (cyclically) differ in image.
        if len(got) > 1:
            assert all(got[k].image != got[k - 1].image for k in range(len(got)))


def test_successor_follows_the_action_maps():
    m = build_machine([part("tri", [(0, 0), (1, 0), (0, 1)])], uncertainty=IDEAL)
    for i in range(m.n):
        for r in m.action_maps[i]:
            for t in (0.1, 0.5, 0.9):
                assert successor(m, i, r.lo + t * (r.hi - r.lo)) == r.target
                assert successor(m, i, r.lo + t * (r.hi - r.lo) - 720.0) == r.target


def reference_branches(machine, mask, grouping="exact"):
    """The sensor's split of the set's diameters, relabelled to machine states by hand."""
    idx = members(mask)
    split = machine.sensor.split([machine.states[i].diameter for i in idx], grouping)
    return [ReadingBranch(b.lo, b.hi, mask_of(idx[j] for j in b.members)) for b in split]


def reference_tolerance_cells(machine, mask, e):
    """Exact branching under a tolerance sensor, cell by cell: between consecutive ends
    ``d -/+ e`` the states within ``e`` of the cell's middle, equal neighbours joined."""
    d = {i: machine.states[i].diameter for i in members(mask)}
    points = sorted({max(0.0, x - e) for x in d.values()} | {x + e for x in d.values()})
    out: list[list] = []
    joinable = False
    for lo, hi in zip(points, points[1:], strict=False):
        x = (lo + hi) / 2.0
        here = mask_of(i for i, di in d.items() if abs(di - x) < e)
        if not here:
            joinable = False
            continue
        if joinable and out[-1][2] == here:
            out[-1][1] = hi
        else:
            out.append([lo, hi, here])
        joinable = True
    return [ReadingBranch(lo, hi, m) for lo, hi, m in out]


@pytest.mark.parametrize("tol", [1e-4, 0.05, 0.3, 1.0, 3.0])
def test_tolerance_branches_match_the_cell_by_cell_reference(tol):
    m = build_machine(
        [random_part(s, 8) for s in range(6)], ToleranceSensor(tol), uncertainty=IDEAL
    )
    rng = random.Random(7)
    for _ in range(300):
        mask = rng.randrange(1, 1 << m.n)
        assert branches(m, mask) == reference_tolerance_cells(m, mask, tol)
        assert branches(m, mask, "components") == reference_branches(m, mask, "components")


def test_branches_cover_every_state_and_led_works():
    m = build_machine([random_part(s, 8) for s in range(3)], LedSensor(1.0, 0.3), uncertainty=IDEAL)
    rng = random.Random(3)
    for _ in range(100):
        mask = rng.randrange(1, 1 << m.n)
        got = branches(m, mask)
        assert got == reference_branches(m, mask)
        covered = 0
        for b in got:
            covered |= b.mask
        assert covered == mask


def test_inseparable_pairs():
    rect = build_machine(
        [part("rect", [(-1, -0.5), (1, -0.5), (1, 0.5), (-1, 0.5)])], uncertainty=IDEAL
    )
    insep = inseparable(rect)
    normals = [
        s.normal_deg
        for s in push_function(
            make_part(make_outline("r", [(-1, -0.5), (1, -0.5), (1, 0.5), (-1, 0.5)]))
        ).states
    ]
    for i in range(rect.n):
        for j in range(rect.n):
            opposite = abs(abs(normals[i] - normals[j]) - 180.0) < 1e-9
            assert bool(insep[i] >> j & 1) == opposite
    assert is_goal(insep, mask_of([0, 2])) != is_goal(insep, mask_of([0, 1]))
    tri = build_machine(
        [part("tri", [(0, 0), (1, 0), (0, 1)])], ToleranceSensor(0.01), uncertainty=IDEAL
    )
    assert inseparable(tri) == (0, 0, 0)
    assert is_goal(inseparable(tri), 0b100) and not is_goal(inseparable(tri), 0b101)
    octagon = build_machine([regular(8, (0.0, 0.0))], NoSensor(), uncertainty=IDEAL)
    assert all(x.bit_count() == 7 for x in inseparable(octagon))


def brute_inseparable(machine):
    """The fixpoint by rounds over all pairs and one rotation per cell of every state's
    boundaries (merged within ANGLE_EPS, as the machine merges them), without a worklist."""
    n = machine.n
    sensor = machine.sensor
    d = [s.diameter for s in machine.states]
    bounds = merge_boundaries([[r.lo for r in rs] for rs in machine.action_maps])
    cuts = bounds + [bounds[0] + 360.0]
    grid = [(a + b) / 2.0 for a, b in zip(cuts, cuts[1:], strict=False)]
    alive = {
        (i, j) for i in range(n) for j in range(n) if i != j and sensor.can_read_alike(d[i], d[j])
    }
    changed = True
    while changed:
        changed = False
        for i, j in sorted(alive):
            for a in grid:
                p, q = successor(machine, i, a), successor(machine, j, a)
                if p == q or (p, q) not in alive:
                    alive.discard((i, j))
                    changed = True
                    break
    out = [0] * n
    for i, j in alive:
        out[i] |= 1 << j
    return tuple(out)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("sensor", [NoSensor(), ToleranceSensor(0.4), LedSensor(1.0, 0.2)])
def test_inseparable_matches_rounds_over_a_rotation_grid(seed, sensor):
    m = build_machine([regular(6, (0.0, 0.0)), random_part(seed, 7)], sensor, uncertainty=IDEAL)
    assert inseparable(m) == brute_inseparable(m)


def test_the_search_space_is_built_once_and_does_not_keep_its_machine():
    m = build_machine([random_part(1, 8)], ToleranceSensor(0.1), uncertainty=IDEAL)
    space = search_space(m)
    assert search_space(m) is space
    assert space.inseparable is space.inseparable  # computed once
    ref = weakref.ref(m)
    del m
    gc.collect()
    assert ref() is None
    with pytest.raises(ReferenceError):
        _ = space.machine


def test_machine_successor_and_image_agree_with_the_functions():
    m = build_machine([random_part(2, 9)], uncertainty=IDEAL)
    for i in range(m.n):
        for a in (0.0, 17.5, 123.0, 359.9):
            assert m.successor(i, a) == successor(m, i, a)
    assert m.image(m.all_states, 45.0) == image(m, m.all_states, 45.0)


def test_branches_are_labelled_by_machine_state():
    m = build_machine(
        [random_part(3, 8), random_part(4, 8)], ToleranceSensor(0.2), uncertainty=IDEAL
    )
    mask = 0b10110100 & m.all_states
    for b in branches(m, mask):
        assert b.mask & ~mask == 0
        assert b.members == tuple(members(b.mask))
        assert isinstance(b, ReadingBranch)


# ---------------------------------------------------------------- sensors


def test_readings_are_clipped_at_zero():
    s = ToleranceSensor(5.0)
    assert s.reading_interval(2.0) == (0.0, 7.0)
    assert all(r >= 0.0 for r in s.probe_readings(2.0, 1e-6))
    assert all(b.lo >= 0.0 for b in s.split([2.0, 4.0, 30.0]))
    assert LedSensor(10.0).reading_interval(3.0) == (0.0, 0.0)


def test_split_uses_the_labels_given():
    s = ToleranceSensor(0.5)
    plain = s.split([10.0, 10.9, 12.0])
    labelled = s.split([10.0, 10.9, 12.0], labels=[5, 1, 3])
    relabel = {0: 5, 1: 1, 2: 3}
    assert [(b.lo, b.hi) for b in plain] == [(b.lo, b.hi) for b in labelled]
    for p, q in zip(plain, labelled, strict=True):
        assert q.mask == mask_of(relabel[j] for j in p.members)


@pytest.mark.parametrize(
    ("sensor", "diameters", "expected"),
    [
        (ToleranceSensor(0.01), [10.0, 12.0], []),
        (NoSensor(), [10.0, 12.0], []),
        (ToleranceSensor(2.0), [10.0, 12.0], ["every state reads alike"]),
        (ToleranceSensor(8.0), [10.0, 12.0], ["every state reads alike", "largest diameter"]),
        (LedSensor(50.0), [10.0, 12.0], ["every state reads alike", "largest diameter (12 mm)"]),
        (LedSensor(1.0), [10.0, 12.0], []),
        (LedSensor(20.0), [5.0], ["largest diameter"]),
        # No alignment noise: 21.96 mm is 0.04 mm below a beam of a 0.5 mm array.
        (LedSensor(0.5), [21.96, 33.3], ["1 diameter lies within 25% of the pitch"]),
        (LedSensor(0.5, 0.02), [21.96, 33.3], []),
        (LedSensor(0.5), [22.0, 33.3], []),  # on a beam: both counts are read
    ],
)
def test_sensor_warnings(sensor, diameters, expected):
    got = sensor_warnings(sensor, diameters)
    assert len(got) == len(expected)
    for line, words in zip(got, expected, strict=True):
        assert words in line and "\n" not in line


def test_tolerance_reading_windows_and_shared_probability():
    s = ToleranceSensor(0.5)
    d = [1.0, 1.6, 3.0]
    assert s.reading_windows(d) == [0b011, 0b010, 0b100]
    assert s.reading_windows([2.0, 1.0]) is None  # not in diameter order
    assert s.reading_windows([1.0, 2.0]) is None  # exactly twice the tolerance apart
    shared = s.shared_reading_probability([1.0, 1.6])
    assert shared == pytest.approx([0.4, 0.4])
    assert LedSensor(1.0).reading_windows(d) is None
    assert NoSensor().shared_reading_probability(d) is None


@pytest.mark.parametrize("sensor", [NoSensor(), ToleranceSensor(0.2), LedSensor(1.0, 0.1)])
def test_sensor_dicts_round_trip(sensor):
    assert sensor_from_dict(sensor.to_dict()) == sensor
    assert sensor.describe() and "\n" not in sensor.describe()


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"model": "sonar"}, "unknown sensor model 'sonar'"),
        ({"model": ["led"]}, "unknown sensor model"),
        ({"model": "tolerance"}, "lacks its parameters"),
        ({"model": "led", "pitch_mm": "wide"}, "lacks its parameters"),
        ([], "must be an object with a 'model'"),
    ],
)
def test_broken_sensor_dicts_are_bad_input(data, message):
    with pytest.raises(InputError, match=message):
        sensor_from_dict(data)


def test_a_sensor_is_described_at_the_precision_it_was_given():
    # 0.143673 and 0.143674 mm may be either side of a mix's critical tolerance: both were
    # shown as "±0.1437 mm", above the critical one.
    assert "±0.143673 mm" in ToleranceSensor(0.143673).describe()
    assert "±0.143674 mm" in ToleranceSensor(0.143674).describe()
    led = LedSensor(0.51234, 0.012345).describe()
    assert "every 0.51234 mm, alignment noise 0.012345 mm" in led
