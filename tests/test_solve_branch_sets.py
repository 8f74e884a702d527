"""``Choices.branch_sets`` (the actions of a set from its images alone) and ``solve`` over it,
against every action made one by one and a brute-force fixpoint written here."""

from __future__ import annotations

import math
import random

import pytest

from feederkit.landing.model import landings_of_outline
from feederkit.machine import build_machine
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.problem import Problem
from feederkit.planning.readings import maximal_sets
from feederkit.planning.reindex import by_diameter
from feederkit.planning.solvable import solve
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

TRIANGLE = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]


def _machine(k: int, err: float, sensor=None):
    polygon = [(math.cos(2 * j * math.pi / k), math.sin(2 * j * math.pi / k)) for j in range(k)]
    parts = [
        make_part(make_outline("tri", TRIANGLE)),
        make_part(make_outline("poly", polygon, com=(0.13, 0.05))),
    ]
    pfs = [push_function(x.part) for p in parts for x in landings_of_outline(p)]
    unc = IDEAL if err == 0.0 else Uncertainty(rotation_error_deg=err)
    sensor = ToleranceSensor(0.01) if sensor is None else sensor
    return by_diameter(build_machine(pfs, sensor, unc))[0]


def _every_action(problem: Problem, mask: int) -> set[tuple[int, ...]]:
    """The maximal branches of every useful cell's action, none left out for dominance
    (with a margin floor every branch of every cell wide enough: the exact view)."""
    if problem.min_margin > 0.0:
        return {
            problem.choices.act(mask, c, exact=True).children
            for c in problem.choices.cells(mask, False)
        }
    out = set()
    for cell in problem.choices.cells(mask):
        act = problem.choices.act(mask, cell)
        if act is not None:
            out.add(act.children)
    return out


def _brute_values(problem: Problem, roots: list[int]) -> dict[int, float]:
    """Minimum worst-case lengths by value iteration over every reachable set and action."""
    acts: dict[int, set[tuple[int, ...]]] = {}
    stack = list(roots)
    while stack:
        m = stack.pop()
        if m in acts:
            continue
        acts[m] = set() if problem.is_goal(m) else _every_action(problem, m)
        stack.extend(c for ch in acts[m] for c in ch if c not in acts)
    value = {m: (0.0 if problem.is_goal(m) else math.inf) for m in acts}
    changed = True
    while changed:
        changed = False
        for m, chs in acts.items():
            best = min((1 + max(value[c] for c in ch) for ch in chs), default=math.inf)
            if best < value[m]:
                value[m], changed = best, True
    return value


MACHINES = [(4, 0.0), (6, 0.0), (5, 1.0), (6, 2.0), (8, 1.0)]


@pytest.mark.parametrize(("k", "err"), MACHINES)
def test_branch_sets_are_the_actions_up_to_dominated_ones(k, err):
    machine = _machine(k, err)
    problem = Problem(machine)
    rng = random.Random(k * 10 + int(err))
    pruned = 0
    for t in range(60):
        mask = machine.all_states if t == 0 else rng.getrandbits(machine.n) or 1
        got = problem.choices.branch_sets(mask)
        every = _every_action(problem, mask)
        assert got <= every
        # Each action left out is dominated: the branches of one kept lie inside its own.
        for e in every - got:
            assert any(all(any(c & f == c for f in e) for c in g) for g in got), (mask, e)
        pruned += len(every - got)
        # The same tuples whatever is cached (a fresh problem; after the search's actions).
        assert Problem(machine).choices.branch_sets(mask) == got
        for _ in problem.choices.search_actions(mask):
            pass
        assert problem.choices.branch_sets(mask) == got
    assert pruned > 0  # the pass leaves dominated actions out


@pytest.mark.parametrize(("k", "err"), MACHINES)
def test_solve_matches_value_iteration_over_every_action(k, err):
    machine = _machine(k, err)
    problem = Problem(machine)
    roots = sorted(maximal_sets({b.mask for b in problem.readings.branches(problem.full)}))
    want = _brute_values(problem, roots)
    got = solve(Problem(machine), roots)
    assert got is not None
    for r in roots:
        assert got[r] == want[r]
    for m, v in got.items():  # every set solve met, with its exact value
        assert v == want.get(m, v)


def test_sensorless_branch_sets_are_the_images():
    machine = _machine(6, 1.0, NoSensor())
    problem = Problem(machine)
    rng = random.Random(3)
    for _ in range(30):
        mask = rng.getrandbits(machine.n) or 1
        got = problem.choices.branch_sets(mask)
        assert all(len(t) == 1 for t in got)
        assert got <= _every_action(problem, mask)


@pytest.mark.parametrize(("k", "err"), [(6, 0.0), (5, 1.0)])
def test_with_a_margin_floor_every_branch_of_every_wide_cell_counts(k, err):
    # Margins are not monotone under subsets: the exact view, nothing left out.
    machine = _machine(k, err)
    problem = Problem(machine, min_margin=0.3)
    rng = random.Random(k)
    for t in range(30):
        mask = machine.all_states if t == 0 else rng.getrandbits(machine.n) or 1
        assert problem.choices.branch_sets(mask) == _every_action(problem, mask)
    roots = sorted(maximal_sets({b.mask for b in problem.readings.branches(problem.full)}))
    want = _brute_values(problem, roots)
    got = solve(Problem(machine, min_margin=0.3), roots)
    assert got is not None and all(got[m] == want[m] for m in got)


def test_distinct_maps_give_the_same_branch_sets():
    machine = _machine(6, 1.0)
    plain, by_map = Problem(machine), Problem(machine, distinct_maps=True)
    rng = random.Random(5)
    for t in range(30):
        mask = machine.all_states if t == 0 else rng.getrandbits(machine.n) or 1
        assert by_map.choices.branch_sets(mask) == plain.choices.branch_sets(mask)
