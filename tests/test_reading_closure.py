"""Sets whose readings carry no information are solved as sensorless problems (docs/planning.md).

A mix of a right triangle and the two landings of an off-centre regular polygon, read by a
fine tolerance sensor: the polygon's states all read one diameter and only reach each
other, so once the reading says "polygon" the rest is a sensorless problem (section 4), and
``WorstCase`` answers it by a shortest-path search over sets instead of the AND/OR search.
These tests hold that shortcut, the vectorised cells and branches it relies on, and the
dominance pruning of the length view to independent computations.
"""

from __future__ import annotations

import math
import random
from functools import cache

import pytest

import feederkit.machine.space as space_module
from feederkit.landing.model import landings_of_outline
from feederkit.machine import build_machine, members
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.andor import WorstCase
from feederkit.planning.api import plan
from feederkit.planning.choices import children_key
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.reindex import by_diameter
from feederkit.planning.sensorless import bfs_length
from feederkit.planning.solvable import solve
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

TRIANGLE = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]


def _polygon(k: int) -> list[tuple[float, float]]:
    return [(math.cos(2 * j * math.pi / k), math.sin(2 * j * math.pi / k)) for j in range(k)]


@cache
def _mix(k: int, rotation_error: float = 0.0):
    """The triangle with both landings of a ``k``-gon (COM off centre), numbered by diameter."""
    parts = [
        make_part(make_outline("tri", TRIANGLE)),
        make_part(make_outline("poly", _polygon(k), com=(0.13, 0.05))),
    ]
    pfs = [push_function(x.part) for p in parts for x in landings_of_outline(p)]
    unc = IDEAL if rotation_error == 0.0 else Uncertainty(rotation_error_deg=rotation_error)
    machine, _old = by_diameter(build_machine(pfs, ToleranceSensor(0.01), unc))
    return machine


def _roots(problem: Problem) -> list[int]:
    return sorted(maximal_sets({b.mask for b in problem.readings.branches(problem.full)}))


def _polygon_states(machine) -> int:
    return sum(1 << i for i, s in enumerate(machine.states) if s.part > 0)


def test_only_the_polygon_root_carries_no_information():
    machine = _mix(6)
    problem = Problem(machine)
    poly = _polygon_states(machine)
    assert poly in _roots(problem)
    assert problem.carries_no_information(poly)
    tri = machine.all_states & ~poly
    assert not problem.carries_no_information(tri)
    assert not problem.carries_no_information(machine.all_states)
    assert not problem.carries_no_information(0)


@pytest.mark.parametrize("k", [4, 5])
def test_every_set_reachable_from_a_quiet_set_reads_alike(k):
    problem = Problem(_mix(k))
    start = _polygon_states(problem.machine)
    seen, todo = {start}, [start]
    while todo:
        m = todo.pop()
        assert problem.carries_no_information(m)
        for _lo, _hi, img in problem.choices.fixed_cells(m):
            assert problem.readings.all_children(img) == (img,)
            if img not in seen:
                seen.add(img)
                todo.append(img)
    assert len(seen) > 4


@pytest.mark.parametrize("k", [4, 5, 6])
def test_quiet_lengths_agree_with_bfs_and_the_plain_and_or_search(k):
    problem = Problem(_mix(k))
    for r in _roots(problem):
        fast = WorstCase(problem).length(r)
        plain = WorstCase(problem)
        plain._quiet = None  # the AND/OR search everywhere
        assert fast == plain.length(r) == bfs_length(problem, r)


def test_the_shortest_path_search_proves_its_path_and_bounds():
    problem = Problem(_mix(5))
    worst = WorstCase(problem)
    poly = _polygon_states(problem.machine)
    length = worst.sensorless_length(poly)
    assert length == 4
    # Every set on the path has its exact length and the action that proves it.
    mask, steps = poly, 0
    while not problem.is_goal(mask):
        k, act = worst.choice[mask]
        assert worst.exact[mask] == k == length - steps
        (mask,) = act.children
        steps += 1
    assert steps == length
    # The lower bounds it leaves are true.
    plain = WorstCase(problem)
    plain._quiet = None
    for m, lb in random.Random(3).sample(sorted(worst.lb.items()), 15):
        assert plain.length(m) >= lb


def test_the_part_bound_is_admissible():
    problem = Problem(_mix(5))
    worst = WorstCase(problem)
    plain = WorstCase(problem)
    plain._quiet = None
    rng = random.Random(5)
    poly = _polygon_states(problem.machine)
    idx = members(poly)
    tight = 0
    for _ in range(40):
        m = sum(1 << i for i in rng.sample(idx, rng.randint(2, len(idx))))
        bound, exact = worst.part_bound(m), plain.length(m)
        assert bound <= exact
        tight += bound == exact
    assert tight > 0


def test_outcome_sets_use_breadth_first_search_and_agree_with_solve():
    machine = _mix(5, rotation_error=0.5)
    assert not machine.deterministic
    problem = Problem(machine)
    poly = _polygon_states(machine)
    assert problem.carries_no_information(poly)
    worst = WorstCase(problem)
    assert worst.part_bound(poly) == 0  # backchaining needs exact push functions
    known = solve(problem, [poly])
    assert known is not None
    value = known[poly]
    got = worst.sensorless_length(poly)
    assert (got is None and value == math.inf) or got == value


def test_the_two_landing_octagon_mix_plans_fast_and_optimal():
    result = plan(_mix(8))
    assert result.optimal and result.length == 8


MACHINES = [(4, 0.0), (6, 0.0), (8, 0.0), (4, 1.0), (6, 1.0), (8, 2.0)]
"""(k, rotation error in deg): the ideal machines have one target per range, the others
outcome sets (read off ``SearchSpace.set_cell_table``)."""


@pytest.mark.parametrize(("k", "err"), MACHINES)
def test_vectorised_cells_match_fixed_cells(k, err, monkeypatch):
    machine = _mix(k, err)
    problem = Problem(machine)
    space = problem.choices._space
    # Small machines keep the pure Python cells: build the table for them too.
    monkeypatch.setattr(space_module, "_CELL_TABLE_MIN", 0)
    vars(space).pop("cell_table", None)
    vars(space).pop("set_cell_table", None)
    assert machine.deterministic == (err == 0.0)
    rng = random.Random(k)
    for t in range(60):
        mask = machine.all_states if t == 0 else rng.getrandbits(machine.n) or 1
        fast = space.cells_and_images(mask)
        assert fast is not None
        got = list(zip(fast[0].tolist(), fast[1].tolist(), fast[2], strict=True))
        assert got == problem.choices.fixed_cells(mask)


def test_restricted_reading_cells_match_the_sensor_split():
    problem = Problem(_mix(6))
    readings = problem.readings
    rng = random.Random(9)
    for _ in range(80):
        img = rng.getrandbits(problem.n) or 1
        want = {b.mask for b in readings.branches(img)}
        got = readings.all_children(img)
        assert set(got) == want and len(got) == len(want)
        assert [c.bit_count() for c in got] == sorted((c.bit_count() for c in want), reverse=True)


def test_the_length_view_leaves_out_dominated_actions():
    problem = Problem(_mix(5))
    choices = problem.choices
    rng = random.Random(11)
    pruned = 0
    for _ in range(30):
        mask = rng.getrandbits(problem.n) or 1
        images = [a.action.image for a in choices.lazy_actions(mask)]
        assert len(set(images)) == len(images)
        assert all(a & mask != mask for a in images)
        # The smallest image (the first tried) dominates every image containing it.
        cells = sorted(choices.cells(mask), key=lambda c: (c[2].bit_count(), c[0] - c[1]))
        if cells:
            first = cells[0][2]
            assert not any(a != first and a & first == first for a in images)
            pruned += sum(c[2] != first and c[2] & first == first for c in cells)
        # Tried in the search order: the smallest largest reading branch first, then the
        # fewest states over the branches; each action's branches the maximal ones.
        acts = list(choices.lazy_actions(mask))
        keys = [children_key(a.children) for a in acts]
        assert keys == sorted(keys)
        assert all(a.children == problem.readings.children(a.action.image) for a in acts)
    assert pruned > 0


@pytest.mark.parametrize("err", [1.0, 3.0])
def test_cells_of_a_large_uncertain_machine_come_from_its_outcome_lists(err):
    # Beyond 62 states the outcome sets do not fit a word: the table keeps each state's
    # outcomes as indices (SearchSpace.outcome_cell_table), and must give the same cells and
    # images as the sweep.
    from shared import small_mix

    machine = build_machine(small_mix(16), ToleranceSensor(1.0), Uncertainty(err))
    assert machine.n > 62 and not machine.deterministic
    problem = Problem(machine)
    space = problem.choices._space
    assert space.set_cell_table is None and space.outcome_cell_table is not None
    rng = random.Random(int(err))
    for t in range(80):
        if t == 0:
            mask = machine.all_states
        else:
            keep = rng.choice([0.05, 0.2, 0.6])
            mask = sum(1 << i for i in range(machine.n) if rng.random() < keep) or 1
        fast = space.cells_and_images(mask)
        assert fast is not None
        got = list(zip(fast[0].tolist(), fast[1].tolist(), fast[2], strict=True))
        assert got == problem.choices.fixed_cells(mask)
