"""The arc search (feederkit.planning.arcs): exact chain lengths of several parts' sets whose
readings carry nothing, against the tests' own search over every rotation and reading."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from shared import brute_lengths, small_mix
from test_planners import check_plan
from test_quiet import CASES, _coarse, _roots
from test_strong_plans import random_pf
from test_tie_breaks import _max_min

from feederkit.landing.model import landings_of_outline
from feederkit.machine import members
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning import arcs, fallback, quiet
from feederkit.planning.andor import part_chains
from feederkit.planning.api import _result, plan
from feederkit.planning.arcs import arc_space
from feederkit.planning.budget import Deadline, Timeout, WorkBudget
from feederkit.planning.methods import longest_root
from feederkit.planning.options import PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.quiet import MARGIN_STEP_DEG, QuietWorst, widest_chain
from feederkit.planning.tree import TIES_NONE


def _sets(machine, count: int, seed: str) -> list[int]:
    """The whole set and ``count`` random subsets of two or more states."""
    rng = random.Random(seed)
    out = [machine.all_states]
    while len(out) <= count:
        mask = rng.getrandbits(machine.n) & machine.all_states
        if mask.bit_count() >= 2:
            out.append(mask)
    return out


def _follow(worst: QuietWorst, mask: int) -> int:
    """The number of steps the recorded chain of ``mask`` takes to a goal (each step the
    chosen action's image, which must have a chosen action itself or be a goal)."""
    steps = 0
    while not worst.p.is_goal(mask):
        mask = worst.choice[mask][1].action.image
        steps += 1
    return steps


@pytest.mark.parametrize("name", CASES)
def test_the_arc_search_gives_every_sets_exact_length_and_a_chain_of_it(name):
    machine, tol = _coarse(CASES[name])
    problem = Problem(machine)
    assert arc_space(problem, part_chains(problem)) is not None  # it applies here
    exact, _children = brute_lengths(machine, tol)
    for mask in _sets(machine, 25, name):
        worst = QuietWorst(problem)
        got = worst.sensorless_length(mask)
        assert got == exact(mask), hex(mask)
        assert got == QuietWorst(problem, arcs=False).sensorless_length(mask)
        assert worst.arc_misses == 0  # its chain was followed on the machine
        if got:
            assert worst.exact[mask] == got and _follow(worst, mask) == got


@pytest.mark.parametrize("name", ["mix3-700", "mix3-300", "landings-8"])
def test_the_arc_search_within_a_cap_refutes_and_records_the_bound(name):
    machine, tol = _coarse(CASES[name])
    problem = Problem(machine)
    (root, *_), _branches = _roots(problem)
    exact, _children = brute_lengths(machine, tol)
    want = exact(root)
    worst = QuietWorst(problem)
    assert worst.sensorless_length(root, want - 1) == want  # cap + 1: more than the cap
    assert worst.lb[root] == want and root not in worst.exact
    assert not worst.within(root, want - 1) and worst.within(root, want)


def test_an_arc_search_cut_short_records_what_it_proved(monkeypatch):
    monkeypatch.setattr(arcs, "POLL_STATES", 1)
    machine, tol = _coarse(CASES["mix3-700"])
    problem = Problem(machine)
    (root,), _branches = _roots(problem)
    exact, _children = brute_lengths(machine, tol)
    recorded = []
    for polls in range(1, 40):
        worst = QuietWorst(problem, WorkBudget(Deadline(), polls))
        try:
            got = worst.length(root)
        except Timeout:
            recorded.append(worst.lb.get(root, 1))
            continue
        assert got == exact(root)
        break
    else:
        pytest.fail("the search never finished")
    assert recorded and all(b <= exact(root) for b in recorded)
    assert recorded == sorted(recorded)


def test_the_arc_search_does_not_apply_under_a_margin_floor():
    machine, _tol = _coarse(CASES["landings-8"])
    problem = Problem(machine)
    assert arc_space(problem, part_chains(problem)) is not None
    assert arc_space(problem.with_margin(0.5), part_chains(problem)) is None
    assert arc_space(problem, []) is None


@pytest.mark.parametrize("name", ["mix4-200", "mix3-300", "landings-9"])
@pytest.mark.parametrize("floor", [0.0, 2.0])
def test_many_arc_states_expanded_at_once_lead_where_each_one_does(name, floor):
    # The search expands its top bucket in one array pass (ArcSpace._expand); each state's
    # successors must be those of the one-state expansion (_next), repeats included.
    machine, _tol = _coarse(CASES[name])
    problem = Problem(machine)
    space = arc_space(problem)
    assert space is not None
    parts = list(range(len(space.parts)))
    sizes = [pt.arcs for pt in space.parts]
    stride = [math.prod(sizes[j + 1 :]) for j in range(len(parts))]
    rng = random.Random(name)
    codes = [rng.randrange(math.prod(sizes)) for _ in range(300)]
    arcs_of = [[(c // stride[j]) % sizes[j] for j in parts] for c in codes]
    got, source = space._expand(
        parts, [np.asarray([a[j] for a in arcs_of]) for j in parts], stride, floor
    )
    for n, arcs_here in enumerate(arcs_of):
        want, _cuts, _widths = space._next(parts, arcs_here, stride, floor)
        assert sorted(got[source == n].tolist()) == sorted(want.tolist()), n


def _polygon(name: str, points, com=None):
    return push_function(make_part(make_outline(name, [list(p) for p in points]), com))


def _triangle_and_rectangle():
    """A near-equilateral triangle (its centre of mass 0.05 mm off) and a 30 x 12 rectangle:
    the first rotation of the arcs' chain, taken at its cell's middle, is 300 degrees
    exactly, a boundary of a state inside the arcs."""
    tri = [
        (10 * math.cos(2 * math.pi * k / 3), 10 * math.sin(2 * math.pi * k / 3)) for k in range(3)
    ]
    return [
        _polygon("tri", tri, [0.05, 0.0]),
        _polygon("rect", [(0, 0), (30, 0), (30, 12), (0, 12)]),
    ]


def _landings(seed: int):
    return [push_function(x.part) for x in landings_of_outline(random_pf(seed).part)]


WIDE = {
    "mix2-37": lambda: small_mix(2, 37),
    "mix2-111": lambda: small_mix(2, 111),
    "landings-16": lambda: _landings(16),
    "landings-7": lambda: _landings(7),
    "triangle+rectangle": _triangle_and_rectangle,
}
"""Machines where a chain whose arcs' ranges are wide can keep a far smaller margin (its
sets' states inside the arcs add boundaries), and one whose arcs' chain starts on a
state's boundary."""


def _setup(pfs):
    machine, _tol = _coarse(pfs)
    problem = Problem(machine)
    roots, _branches = _roots(problem)
    longest = max(QuietWorst(problem, arcs=False).sensorless_length(r) for r in roots)
    want = min(_max_min(problem, r, longest, {}) for r in roots)
    return machine, problem, roots, longest, want


@pytest.mark.parametrize("name", WIDE)
def test_the_margin_bisection_keeps_the_largest_margin_with_the_arcs(name):
    # Against the brute force over every plan (test_tie_breaks._max_min): where the arcs'
    # chain keeps less than the probed margin, the search over sets decides the probe.
    machine, problem, roots, longest, want = _setup(WIDE[name]())
    worst = QuietWorst(problem)
    assert worst.arc_space() is not None
    found = widest_chain(worst, roots, longest, 0.0, Deadline())
    assert want - MARGIN_STEP_DEG <= found.margin <= want
    assert want - MARGIN_STEP_DEG <= plan(machine).min_margin <= want


def test_a_chain_starting_on_a_states_boundary_is_followed_on_the_machine():
    machine, problem, roots, longest, _want = _setup(_triangle_and_rectangle())
    worst = QuietWorst(problem)
    assert worst.sensorless_length(machine.all_states) == longest
    assert worst.arc_misses == 0
    # Under a floor the set search keeps, the arc search finds chains too (its "none"
    # would say that none keeps the floor).
    assert QuietWorst(problem.with_margin(0.05), arcs=False).within(roots[0], longest)
    search = QuietWorst(problem)
    margin = search.arc_chains(worst.arc_space(), roots, longest, 0.05)
    assert margin is not None and margin > 0.0 and search.arc_misses == 0


def test_a_margin_probe_the_search_over_sets_leaves_open_is_not_called_proven(monkeypatch):
    # mix2-37: some probe's arc chain keeps less than the probe (the search over sets
    # decides it); with no polls for that search the bisection says it is not proven.
    machine, problem, roots, longest, want = _setup(WIDE["mix2-37"]())
    monkeypatch.setattr(quiet, "SET_PROBE_POLLS", 0)
    found = widest_chain(QuietWorst(problem), roots, longest, 0.0, Deadline())
    assert found.cut_by == "work" and found.margin <= want
    result = plan(machine)
    assert result.tie_breaks == TIES_NONE and result.ties_cut_by == "work"
    assert result.optimal and result.length == 1 + longest == check_plan(result)


@pytest.mark.parametrize("name", CASES)
def test_weighted_chains_are_plans_within_their_weight_of_the_shortest(name, monkeypatch):
    machine, tol = _coarse(CASES[name])
    problem = Problem(machine)
    roots, _branches = _roots(problem)
    exact, _children = brute_lengths(machine, tol)
    want = max(exact(r) for r in roots)
    worst = QuietWorst(problem)
    longest = worst.weighted_chains(roots, Deadline())
    assert longest is not None and worst.arc_misses == 0
    assert want <= longest <= quiet.CHAIN_WEIGHTS[-1] * want
    for r in roots:
        assert _follow(worst, r) <= longest and r not in worst.exact
    # The fallback's first plan where the exact search ran out: no beams over sets needed.
    monkeypatch.setattr(fallback, "widening_chains", lambda *_a, **_k: pytest.fail("beams"))
    # Nor the subsets' AND/OR search over reading sets: the A* at the bound proves it.
    monkeypatch.setattr(fallback, "subset_lower_bound", lambda *_a, **_k: pytest.fail("subsets"))
    monkeypatch.setattr(arcs, "POLL_STATES", 1)  # the exact arc search cut at once
    cut = QuietWorst(problem, WorkBudget(Deadline(), 0))
    with pytest.raises(Timeout):
        longest_root(problem, cut, roots, "auto")
    root, _optimal, _length, lower, _ties, _cut = fallback.fallback(
        problem, cut, roots, _branches, Deadline(20.0), PlanningOptions(time_limit_s=20.0), "time"
    )
    result = _result(machine, root, False, None, lower, "worst", "none")
    assert lower == 1 + want == result.length == check_plan(result) and result.optimal


def _regular(n: int, com=None):
    points = [
        (10 * math.cos(2 * math.pi * k / n), 10 * math.sin(2 * math.pi * k / n)) for k in range(n)
    ]
    return _polygon(f"regular-{n}", points, com)


SYMMETRIC = {
    "square+rectangle": lambda: [
        _polygon("square", [(0, 0), (10, 0), (10, 10), (0, 10)]),
        _polygon("rect", [(0, 0), (30, 0), (30, 12), (0, 12)]),
    ],
    "hexagon+rectangle": lambda: [
        _regular(6),
        _polygon("rect", [(0, 0), (20, 0), (20, 10), (0, 10)]),
    ],
    "pentagon+triangle off centre": lambda: [_regular(5), _regular(3, [0.5, 0.1])],
}
"""Mixes with parts whose push function repeats within a turn (periods of 60-180 degrees)."""


def _target(machine, state: int, alpha: float) -> int | None:
    """The state the machine's action ranges take ``state`` to under rotation ``alpha``
    (None within 1e-6 degrees of a range's end)."""
    for r in machine.action_maps[state]:
        for x in (alpha, alpha + 360.0):
            if r.lo + 1e-6 < x < r.hi - 1e-6:
                return r.target
    return None


@pytest.mark.parametrize("name", [*SYMMETRIC, "mix3-300"])
def test_an_arcs_image_under_a_rotation_is_the_arc_between_its_ends_images(name):
    # Against the machine's own action ranges (a rotation theta of the arcs is the
    # machine's -theta): every part's arcs, symmetric parts (periods below 360) included.
    machine, _tol = _coarse(SYMMETRIC[name]() if name in SYMMETRIC else CASES[name])
    space = arc_space(Problem(machine))
    assert space is not None
    rng = random.Random(name)
    for i, pt in enumerate(space.parts):
        cls = {s: c for c, mask in enumerate(pt.states) for s in members(mask)}
        checked = 0
        while checked < 300:
            a, m = rng.randrange(pt.k), rng.randrange(pt.k)
            cuts, outs = space._moves_of(i, a * (pt.k + 1) + m)
            theta = rng.uniform(0.0, 360.0)
            first = _target(machine, min(members(pt.states[a])), -theta % 360.0)
            last = _target(machine, min(members(pt.states[(a + m) % pt.k])), -theta % 360.0)
            if first is None or last is None or np.min(np.abs(cuts - theta)) < 1e-6:
                continue  # on a boundary: no action there
            got_first, got_steps = divmod(
                int(outs[cuts.searchsorted(theta, "right") - 1]), pt.k + 1
            )
            assert got_first == cls[first], (i, a, m, theta)
            steps = (cls[last] - cls[first]) % pt.k
            # The ends' classes alike: a point, or (grown past a turn) the whole circle.
            assert got_steps == steps or (steps == 0 and m and got_steps == pt.k), (i, a, m)
            checked += 1


@pytest.mark.parametrize("name", SYMMETRIC)
def test_the_arc_search_is_exact_on_parts_whose_push_function_repeats(name):
    # Against the A* over sets (itself checked against the brute force above): a regular
    # polygon's equal diameters read as one span, which the brute force does not model.
    machine, _tol = _coarse(SYMMETRIC[name]())
    problem = Problem(machine)
    space = arc_space(problem, part_chains(problem))
    assert space is not None and any(pt.period < 360.0 for pt in space.parts)
    for mask in _sets(machine, 25, name):
        worst = QuietWorst(problem)
        got = worst.sensorless_length(mask)
        assert got == QuietWorst(problem, arcs=False).sensorless_length(mask), hex(mask)
        assert worst.arc_misses == 0
        if got:
            assert _follow(worst, mask) == got
