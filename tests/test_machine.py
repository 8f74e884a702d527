"""The push-align machine: overlap ranges, reading branches, successors and the goal."""

from __future__ import annotations

import math
import random

import pytest

from feederkit.machine import (
    Branch,
    SetAction,
    branches,
    build_machine,
    image,
    inseparable,
    is_goal,
    mask_of,
    members,
    overlap_cells,
    overlap_ranges,
    successor,
)
from feederkit.mechanics import push_function
from feederkit.mechanics.actions import merge_boundaries
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor, split_by_reading


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
    return [SetAction(lo, hi, img) for lo, hi, img in merged]


MACHINES = [
    build_machine([regular(n, com)])
    for n in (3, 4, 5, 8, 12, 24, 32)
    for com in ((0.0, 0.0), (0.13, 0.05), (0.02, 0.008), (1e-3, 0.0))
] + [
    build_machine([part("rect", [(0, 0), (2, 0), (2, 1), (0, 1)])]),
    build_machine([random_part(s, 9) for s in range(4)]),
]


@pytest.mark.parametrize("machine", MACHINES, ids=lambda m: f"{m.part_names[0]}-{m.n}")
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
    m = build_machine([part("tri", [(0, 0), (1, 0), (0, 1)])])
    for i in range(m.n):
        for r in m.action_maps[i]:
            for t in (0.1, 0.5, 0.9):
                assert successor(m, i, r.lo + t * (r.hi - r.lo)) == r.target
                assert successor(m, i, r.lo + t * (r.hi - r.lo) - 720.0) == r.target


def reference_branches(machine, mask, grouping="exact"):
    idx = members(mask)
    split = split_by_reading(machine.sensor, [machine.states[i].diameter for i in idx], grouping)
    return [Branch(b.lo, b.hi, mask_of(idx[j] for j in b.members)) for b in split]


@pytest.mark.parametrize("tol", [1e-4, 0.05, 0.3, 1.0, 3.0])
def test_tolerance_branches_match_split_by_reading(tol):
    m = build_machine([random_part(s, 8) for s in range(6)], ToleranceSensor(tol))
    rng = random.Random(7)
    for _ in range(300):
        mask = rng.randrange(1, 1 << m.n)
        assert branches(m, mask) == reference_branches(m, mask)
        assert branches(m, mask, "components") == reference_branches(m, mask, "components")


def test_branches_cover_every_state_and_led_works():
    m = build_machine([random_part(s, 8) for s in range(3)], LedSensor(1.0, 0.3))
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
    rect = build_machine([part("rect", [(-1, -0.5), (1, -0.5), (1, 0.5), (-1, 0.5)])])
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
    tri = build_machine([part("tri", [(0, 0), (1, 0), (0, 1)])], ToleranceSensor(0.01))
    assert inseparable(tri) == (0, 0, 0)
    assert is_goal(inseparable(tri), 0b100) and not is_goal(inseparable(tri), 0b101)
    octagon = build_machine([regular(8, (0.0, 0.0))], NoSensor())
    assert all(x.bit_count() == 7 for x in inseparable(octagon))
