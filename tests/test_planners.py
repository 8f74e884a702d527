"""The planners of issue 3 on geometry and on hand-built machines.

Every emitted plan is executed on its machine by ``check_plan`` below: from every start
state, through every reading branch the state can follow, it must end in a leaf that lists
the state it is really in, and only states inseparable from it.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from itertools import product

import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from feederkit.errors import InputError, PlanningError
from feederkit.machine import (
    MachineState,
    PushAlignMachine,
    build_machine,
    inseparable,
    is_goal,
    members,
    overlap_ranges,
    search_space,
    successor,
)
from feederkit.mechanics import push_function
from feederkit.mechanics.actions import ActionRange
from feederkit.mechanics.polygon_classes import polygon_class
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import _result, plan
from feederkit.planning.budget import Deadline, Timeout
from feederkit.planning.fallback import _fewest_after, sensorless_plan
from feederkit.planning.options import Grouping, Method, Objective, PlanningOptions
from feederkit.planning.problem import Problem
from feederkit.planning.sensorless import Backchain, push_circle
from feederkit.planning.stats import expected_operations
from feederkit.planning.tree import Leaf
from feederkit.sensors import (
    LedSensor,
    NoSensor,
    ToleranceSensor,
)
from feederkit.uncertainty import IDEAL

# ---------------------------------------------------------------- helpers


def part(name, vertices, com=None):
    return push_function(make_part(make_outline(name, vertices), com))


def regular(n, com=(0.13, 0.05)):
    pts = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]
    return part(f"regular-{n}", pts, com)


RECT = [(0, 0), (2, 0), (2, 1), (0, 1)]
TRIANGLE = [(0, 0), (1, 0), (0, 1)]


def random_convex(seed, n):
    import random

    rng = random.Random(seed)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    radii = [rng.uniform(0.8, 1.0) for _ in angles]
    pts = [(30 * r * math.cos(t), 20 * r * math.sin(t)) for r, t in zip(radii, angles, strict=True)]
    hull = shapely.MultiPoint(pts).convex_hull.exterior.coords[:-1]
    return part(f"random-{seed}", hull)


def _reading_points(machine, branch):
    """Readings to try inside a closed branch interval: its ends and middle."""
    if branch.lo is None:
        return [None]
    return [branch.lo, (branch.lo + branch.hi) / 2.0, branch.hi]


def check_plan(result) -> int:
    """Execute the plan from every start and every reading branch; return the longest run.

    At each step the state must be in the branch it follows (its reading is possible
    there), every branch a state can read into must exist, and the leaf must hold the
    state and only states inseparable from it.
    """
    machine = result.machine
    insep = inseparable(machine)
    sensor = machine.sensor
    longest = 0

    def can_follow(state, branch):
        if branch.lo is None:
            return True
        d = machine.states[state].diameter
        # Some reading strictly inside the branch interval (or at an LED count) is possible.
        if isinstance(sensor, ToleranceSensor):
            e = sensor.tolerance
            return max(branch.lo, d - e) < min(branch.hi, d + e)
        return any(sensor.consistent(d, r) for r in _reading_points(machine, branch))

    seen: set[tuple[int, int, int]] = set()

    def run(node, state, ops):
        nonlocal longest
        # A plan is a DAG in memory: a node met again in the same state at the same depth
        # runs the same way (without this, a chain whose branches share one subplan has
        # exponentially many paths).
        key = (id(node), state, ops)
        if key in seen:
            return
        seen.add(key)
        if isinstance(node, Leaf):
            assert node.mask >> state & 1, "the leaf does not list the true state"
            for j in members(node.mask):
                assert j == state or insep[state] >> j & 1, "the leaf lists a separable state"
            longest = max(longest, ops)
            return
        if node.action is not None:
            a = node.action
            assert a.lo < a.representative + (360 if a.representative < a.lo else 0) < a.hi + 1e-9
            state = successor(machine, state, a.representative)
        ops += 1
        assert_covered(node, state)
        for b, sub in node.branches:
            if can_follow(state, b):
                assert b.mask >> state & 1, "a branch the state can read into omits it"
                run(sub, state, ops)

    def assert_covered(node, state):
        """Every reading the state can give lies in a branch that lists it."""
        d = machine.states[state].diameter
        mine = [b for b, _ in node.branches if b.mask >> state & 1]
        if isinstance(sensor, NoSensor):
            assert mine
            return
        if isinstance(sensor, ToleranceSensor):
            e = sensor.tolerance
            lo = max(0.0, d - e)  # readings are never negative
            pts = sorted({lo, d + e} | {x for b in mine for x in (b.lo, b.hi) if lo < x < d + e})
            probes = [(a + b) / 2 for a, b in zip(pts, pts[1:], strict=False)]
        else:
            c0, c1 = sensor.counts(d)
            probes = [c * sensor.pitch for c in range(c0, c1 + 1)]
        for x in probes:
            assert any(b.lo - 1e-12 <= x <= b.hi + 1e-12 for b in mine), f"reading {x} uncovered"

    for s in range(machine.n):
        run(result.root, s, 0)
    assert longest == result.length
    return longest


# ---------------------------------------------------------------- known cases


def test_rectangle_sensorless_length_2_up_to_symmetry():
    m = build_machine(
        [part("rect", [(-1, -0.5), (1, -0.5), (1, 0.5), (-1, 0.5)])], uncertainty=IDEAL
    )
    r = plan(m)
    assert r.length == 2 and r.optimal
    check_plan(r)
    leaves = _leaves(r.root)
    assert all(leaf.mask.bit_count() == 2 for leaf in leaves)
    (leaf,) = leaves
    a, b = members(leaf.mask)
    normals = [s.normal_deg for s in push_function(make_part(make_outline("r", RECT))).states]
    assert abs(abs(normals[a] - normals[b]) - 180.0) < 1e-9


def test_isosceles_right_triangle():
    pf = part("tri", TRIANGLE)
    with_sensor = plan(build_machine([pf], ToleranceSensor(0.01), uncertainty=IDEAL))
    without = plan(build_machine([pf], NoSensor(), uncertainty=IDEAL))
    assert (with_sensor.length, without.length) == (2, 3)
    check_plan(with_sensor)
    check_plan(without)
    assert all(leaf.mask.bit_count() == 1 for leaf in _leaves(with_sensor.root))


@pytest.mark.parametrize(
    "n", [*range(5, 11), *(pytest.param(n, marks=pytest.mark.slow) for n in (11, 12))]
)
def test_offset_regular_polygon_needs_n(n):
    m = build_machine([regular(n)], uncertainty=IDEAL)
    r = plan(m)
    assert r.length == n == 1 + shortest_synchronizing_word(m)
    check_plan(r)


def test_all_diameters_distinct_gives_length_1():
    pf = part("scalene", [(0, 0), (4, 0), (1, 3)])
    assert len({round(s.diameter, 6) for s in pf.states}) == pf.n
    r = plan(build_machine([pf], ToleranceSensor(1e-3), uncertainty=IDEAL))
    assert r.length == 1
    assert abs(r.expected_length - 1.0) < 1e-12
    assert all(isinstance(sub, Leaf) for _, sub in r.root.branches)
    check_plan(r)


def _leaves(node):
    if isinstance(node, Leaf):
        return [node]
    return [leaf for _, sub in node.branches for leaf in _leaves(sub)]


def shortest_synchronizing_word(machine) -> int:
    """Breadth-first search over subsets with this test's own representative rotations."""
    n = machine.n
    bounds = sorted({r.lo % 360.0 for rs in machine.action_maps for r in rs})
    reps = [(a + b) / 2 for a, b in zip(bounds, bounds[1:] + [bounds[0] + 360.0], strict=True)]

    def go(i, a):
        a %= 360.0
        for r in machine.action_maps[i]:
            if r.lo < a < r.hi or r.lo < a + 360.0 < r.hi:
                return r.target
        raise AssertionError("rotation on a boundary")

    start = frozenset(range(n))
    seen, frontier, depth = {start}, [start], 0
    while frontier:
        if any(len(s) == 1 for s in frontier):
            return depth
        nxt = []
        for s in frontier:
            for a in reps:
                t = frozenset(go(i, a) for i in s)
                if t not in seen:
                    seen.add(t)
                    nxt.append(t)
        frontier, depth = nxt, depth + 1
    raise AssertionError("not synchronizing")


# ---------------------------------------------------------------- methods agree


PARTS = [
    ("tri", TRIANGLE, None),
    ("rect", RECT, None),
    ("rect-off", RECT, (0.8, 0.45)),
    ("quad", [(0, 0), (3, 0), (2.2, 1.6), (0.4, 1.1)], None),
    ("penta", [(0, 0), (2, -0.3), (3, 1), (1.5, 2.2), (-0.4, 1.2)], None),
    ("hexa", [(0, 0), (2, 0), (3, 1), (2, 2), (0, 2), (-1, 1)], (0.9, 1.05)),
]
SENSORS = [NoSensor(), ToleranceSensor(0.01), ToleranceSensor(0.2), LedSensor(0.25, 0.05)]


@pytest.mark.parametrize(("name", "verts", "com"), PARTS)
@pytest.mark.parametrize("sensor", SENSORS, ids=lambda s: repr(s))
def test_methods_agree_and_bounds_hold(name, verts, com, sensor):
    pf = part(name, verts, com)
    m = build_machine([pf], sensor, uncertainty=IDEAL)
    r = plan(m)
    check_plan(r)
    assert r.optimal and r.lower_bound == r.length
    assert plan(m, PlanningOptions(method="andor")).length == r.length
    assert plan(m, PlanningOptions(method="bottom-up")).length == r.length
    sensorless = plan(build_machine([pf], NoSensor(), uncertainty=IDEAL))
    assert r.length <= sensorless.length
    assert (
        plan(
            build_machine([pf], NoSensor(), uncertainty=IDEAL), PlanningOptions(method="bfs")
        ).length
        == sensorless.length
    )
    assert (
        plan(
            build_machine([pf], NoSensor(), uncertainty=IDEAL), PlanningOptions(method="backchain")
        ).length
        == sensorless.length
    )
    assert r.length <= polygon_class(pf, sensor).bound
    comp = plan(m, PlanningOptions(grouping="components"))
    check_plan(comp)
    assert r.length <= comp.length


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10**6), st.integers(3, 9), st.sampled_from([0.0, 0.005, 0.02, 0.05]))
def test_random_parts_methods_agree(seed, n, rel_tol):
    pf = random_convex(seed, n)
    sensor = NoSensor() if rel_tol == 0.0 else ToleranceSensor(rel_tol * pf.part.size)
    m = build_machine([pf], sensor, uncertainty=IDEAL)
    r = plan(m)
    check_plan(r)
    assert plan(m, PlanningOptions(method="andor")).length == r.length
    if pf.n <= 10:
        assert plan(m, PlanningOptions(method="bottom-up")).length == r.length
    sensorless = build_machine([pf], NoSensor(), uncertainty=IDEAL)
    s = plan(sensorless)
    assert r.length <= s.length
    assert (
        plan(sensorless, PlanningOptions(method="bfs")).length
        == s.length
        == plan(sensorless, PlanningOptions(method="andor")).length
    )
    assert r.length <= polygon_class(pf, sensor).bound
    assert s.length <= polygon_class(pf, NoSensor()).bound


# ---------------------------------------------------------------- ties and objectives


@pytest.mark.parametrize(("name", "verts", "com"), PARTS)
def test_no_plan_of_the_same_length_keeps_a_larger_margin(name, verts, com):
    for sensor in (NoSensor(), ToleranceSensor(0.2)):
        m = build_machine([part(name, verts, com)], sensor, uncertainty=IDEAL)
        r = plan(m)
        if r.length == 1:
            assert r.min_margin == math.inf
            continue
        assert 0.0 < r.min_margin < 180.0
        with contextlib.suppress(PlanningError):
            assert (
                plan(m, PlanningOptions(min_margin_deg=r.min_margin * (1 + 1e-9))).length > r.length
            )


def test_expected_objective_never_worse_and_statistics_consistent():
    for name, verts, com in PARTS:
        m = build_machine([part(name, verts, com)], ToleranceSensor(0.05), uncertainty=IDEAL)
        w = plan(m)
        e = plan(m, PlanningOptions(objective="expected"))
        check_plan(e)
        assert e.expected_length <= w.expected_length + 1e-12
        assert abs(expected_operations(m, e.root) - e.expected_length) < 1e-12
        assert 1.0 - 1e-9 <= e.expected_length <= e.length + 1e-9


def test_min_margin_respected_or_named():
    pf = regular(7)
    m = build_machine([pf], uncertainty=IDEAL)
    r = plan(m)
    floor = r.min_margin
    same = plan(m, PlanningOptions(min_margin_deg=floor))
    assert same.min_margin >= floor and same.length == r.length
    with pytest.raises(PlanningError) as err:
        plan(m, PlanningOptions(min_margin_deg=179.0))
    assert "largest margin" in str(err.value)
    best = float(str(err.value).split("is ")[-1].split(" deg")[0])
    ok = plan(m, PlanningOptions(min_margin_deg=best * 0.999))
    check_plan(ok)
    assert ok.min_margin >= best * 0.999


def _goal_known(m):
    """The machine, its goal relation computed (the states of these are already sorted by
    diameter, so ``plan`` reuses it and a tiny time limit reaches the search)."""
    assert len(search_space(m).inseparable) == m.n
    return m


def test_time_limit_returns_a_valid_plan_with_a_lower_bound():
    # The plain AND/OR search needs about a second for the offset 12-gon.
    m = _goal_known(build_machine([regular(12)], uncertainty=IDEAL))
    r = plan(m, PlanningOptions(method="andor", time_limit_s=2.0))
    check_plan(r)
    assert 2 <= r.lower_bound <= 12 <= r.length
    # A mix has no backchaining fallback.
    with pytest.raises(PlanningError, match="time limit"):
        plan(
            _goal_known(build_machine([regular(12), regular(11)], uncertainty=IDEAL)),
            PlanningOptions(method="andor", time_limit_s=1e-4),
        )


def test_backchaining_fallback_is_a_valid_plan_of_the_sensorless_length():
    m = _goal_known(build_machine([regular(32, (0.02, 0.008))], uncertainty=IDEAL))
    problem = Problem(m)
    root = sensorless_plan(problem, problem.readings.branches(problem.full), Deadline())
    blind = _result(m, root, False, None, 2, "worst", "exact")
    check_plan(blind)
    assert blind.length == 32  # the sensorless optimum (nothing to read)
    with pytest.raises(Timeout):
        sensorless_plan(problem, problem.readings.branches(problem.full), Deadline(1e-9))


def test_the_plan_that_follows_the_readings_is_a_valid_plan_shorter_than_the_chain():
    # The hull of 200 random points, 19 stable states at 0.6 mm: the backchaining chain
    # needs 12 operations; rotations chosen by the sensorless lengths the readings leave,
    # each reading set going on as the largest reading set holding it, need 7.
    import random

    rng = random.Random(4)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(200))
    pts = [(30 * rng.uniform(0.7, 1.0), t) for t in angles]
    outline = [(r * math.cos(t), r * math.sin(t)) for r, t in pts]
    pf = part("rand-200", outline)
    m = _goal_known(build_machine([pf], ToleranceSensor(0.01 * pf.part.size), IDEAL))
    problem = Problem(m)
    branches = problem.readings.branches(problem.full)
    chain = _result(m, sensorless_plan(problem, branches, Deadline(), by_image=True),
                    False, None, 2, "worst", "exact")  # fmt: skip
    read = _result(m, sensorless_plan(problem, branches, Deadline()), False, None, 2, "worst",
                   "exact")  # fmt: skip
    assert check_plan(chain) == chain.length == 12
    assert check_plan(read) == read.length == 7


def _random_or_regular(kind: tuple[str, int], seed: int):
    """A random convex ``n``-gon of ``seed``, or a regular one with its COM off centre by
    ``seed``."""
    name, n = kind
    offset = (0.01 + seed % 7 / 100, 0.004 + seed % 5 / 200)
    return random_convex(seed, n) if name == "random" else regular(n, offset)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.sampled_from([("random", 9), ("random", 16), ("regular", 10), ("regular", 11)]),
    st.integers(0, 10**6),
    st.integers(1, 2**20 - 1),
)
def test_backchaining_length_of_any_set_is_the_breadth_first_length(kind, seed, bits):
    # Goldberg's table against a breadth-first search over the machine's own images, on
    # random parts (4-8 states) and off-centre regular polygons (10 and 11: more than a
    # byte of states).
    m = build_machine([_random_or_regular(kind, seed)], NoSensor(), uncertainty=IDEAL)
    insep = inseparable(m)
    circle = push_circle(m, insep)
    assume(circle is not None and bits & m.all_states)
    start = bits & m.all_states
    depth, frontier, seen = 0, {start}, {start}
    while not any(is_goal(insep, s) for s in frontier):
        frontier = {r.image for s in frontier for r in overlap_ranges(m, s)} - seen
        seen |= frontier
        depth += 1
    assert Backchain(circle).length(start) == depth


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.sampled_from([("random", 9), ("random", 16), ("regular", 11)]),
    st.integers(0, 10**6),
    st.integers(1, 2**20 - 1),
)
def test_the_rotation_by_the_readings_left_is_the_first_fewest_one_set_at_a_time(kind, seed, bits):
    # The plan that follows the readings takes the first rotation whose reading sets need
    # the fewest sensorless operations (the largest, then their sum): all the sets' lengths
    # by array operations against Goldberg's table one set at a time.
    pf = _random_or_regular(kind, seed)
    m = build_machine([pf], ToleranceSensor(0.02 * pf.part.size), IDEAL)
    problem = Problem(m)
    circle = push_circle(m, problem.insep)
    start = bits & m.all_states
    assume(circle is not None and start and not problem.is_goal(start))
    chain = Backchain(circle)
    kids = [problem.readings.children(c[2]) for c in problem.choices.cells(start, False)]
    sets = [b for ks in kids for b in ks]
    assert Backchain(circle).lengths_of_sets(sets).tolist() == [chain.length(b) for b in sets]

    def fewest(ks):
        lengths = [chain.length(b) for b in ks]
        return max(lengths), sum(lengths)

    assert _fewest_after(Backchain(circle), kids) == min(
        range(len(kids)), key=lambda i: fewest(kids[i])
    )


@pytest.mark.slow
def test_time_limit_falls_back_to_backchaining():
    # One part's push machine: backchaining gives a plan when the search cannot.
    blind = plan(
        _goal_known(build_machine([regular(32, (0.02, 0.008))], uncertainty=IDEAL)),
        PlanningOptions(method="andor", time_limit_s=2.0),
    )
    check_plan(blind)
    assert blind.length >= 32 >= blind.lower_bound
    # A plan that meets its proven bound is optimal, whichever search found it.
    assert blind.optimal == (blind.length == blind.lower_bound)


def test_the_time_limit_holds_for_the_goal_fixpoint_too():
    # The clock starts before the inseparability fixpoint, which polls it.
    m = build_machine([regular(32, (0.02, 0.008))], uncertainty=IDEAL)
    with pytest.raises(PlanningError, match="inseparable"):
        plan(m, PlanningOptions(time_limit_s=1e-6))


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"objective": "best"}, "the objective must be one of worst, expected, .*got 'best'"),
        ({"grouping": "pairs"}, "the reading grouping must be one of exact, components"),
        ({"method": "dfs"}, "the planning method must be one of auto, andor, bottom-up"),
        ({"min_margin_deg": -1.0}, r"the minimum margin must be in \[0, 180\) degrees"),
        ({"min_margin_deg": math.nan}, "the minimum margin must be in"),
        ({"min_margin_deg": 180.0}, "the minimum margin must be in"),
        ({"min_margin_deg": "5"}, "the minimum margin must be in"),
        ({"time_limit_s": 0.0}, "the time limit must be a finite positive number of seconds"),
        ({"time_limit_s": math.inf}, "the time limit must be a finite positive number of seconds"),
    ],
)
def test_bad_options_are_refused_once_in_library_words(options, message):
    with pytest.raises(InputError, match=message):
        PlanningOptions(**options)


def test_options_normalise_strings_to_enums_and_are_values():
    o = PlanningOptions(objective="expected", grouping="components", method="bottom-up")
    assert o.objective is Objective.EXPECTED and o.method is Method.BOTTOM_UP
    assert o.grouping is Grouping.COMPONENTS
    assert o == PlanningOptions(Objective.EXPECTED, 0, Grouping.COMPONENTS, None, Method.BOTTOM_UP)
    assert isinstance(o.min_margin_deg, float)
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.min_margin_deg = 1.0  # type: ignore[misc]


def test_bad_arguments():
    m = build_machine([part("tri", TRIANGLE)], uncertainty=IDEAL)
    with pytest.raises(InputError, match="PlanningOptions"):
        plan(m, {"method": "andor"})  # type: ignore[arg-type]
    with pytest.raises(InputError, match="sensorless"):
        plan(
            build_machine([part("tri", TRIANGLE)], ToleranceSensor(0.01), uncertainty=IDEAL),
            PlanningOptions(method="bfs"),
        )


# ---------------------------------------------------------------- hand-built machines


def hand_machine(n, maps, diameters=None, sensor=None):
    """A machine from action maps given as lists of (lo, hi, target) per state."""
    diameters = diameters or [1.0] * n
    states = tuple(MachineState(0, i, diameters[i], 1.0 / n) for i in range(n))
    action_maps = tuple(tuple(ActionRange(lo, hi, t) for lo, hi, t in rs) for rs in maps)
    return PushAlignMachine(("hand",), states, action_maps, sensor or NoSensor())


def test_hand_machine_two_states_merge_in_one_step():
    # State 0 stays for rotations in (0, 180) and goes to 1 otherwise; state 1 always stays.
    m = hand_machine(2, [[(0, 180, 0), (180, 360, 1)], [(0, 360, 1)]])
    r = plan(m)
    assert r.length == 2
    check_plan(r)
    (leaf,) = _leaves(r.root)
    assert leaf.mask == 0b10
    assert r.min_margin == 90.0


def test_hand_machine_sensor_beats_sensorless():
    # Three states; rotation in (0, 120) cycles them, (120, 360) keeps them: no merging at all.
    cyc = [[(0, 120, (i + 1) % 3), (120, 360, i)] for i in range(3)]
    blind = hand_machine(3, cyc)
    assert inseparable(blind) == (0b110, 0b101, 0b011)
    r = plan(blind)
    assert r.length == 1 and _leaves(r.root)[0].mask == 0b111
    sensed = hand_machine(3, cyc, [1.0, 1.0, 2.0], ToleranceSensor(0.1))
    s = plan(sensed)
    check_plan(s)
    # Reading 1.0 leaves {0, 1}; cycling sends 0 -> 1 and 1 -> 2, which the reading tells apart.
    assert s.length == 2
    assert all(leaf.mask.bit_count() == 1 for leaf in _leaves(s.root))


def test_hand_machine_equal_readings_are_sensorless():
    maps = [[(0, 90, 0), (90, 360, 1)], [(0, 200, 2), (200, 360, 1)], [(0, 360, 2)]]
    a = plan(hand_machine(3, maps))
    b = plan(hand_machine(3, maps, [5.0] * 3, ToleranceSensor(0.5)))
    check_plan(a)
    check_plan(b)
    assert a.length == b.length == 3


def test_led_sensor_plans_are_valid():
    for name, verts, com in PARTS:
        for pitch, noise in product((0.1, 0.3), (0.0, 0.04)):
            m = build_machine([part(name, verts, com)], LedSensor(pitch, noise), uncertainty=IDEAL)
            r = plan(m)
            check_plan(r)
            assert plan(m, PlanningOptions(method="bottom-up")).length == r.length


def test_a_part_thinner_than_the_tolerance_reads_from_zero():
    """Readings are clipped at 0: a sliver's thin states read in [0, d + e)."""
    m = build_machine(
        [part("sliver", [(0, 0), (10, 0), (10, 0.1), (0, 0.1)])],
        ToleranceSensor(0.3),
        uncertainty=IDEAL,
    )
    r = plan(m)
    check_plan(r)
    lows = [b.lo for b, _ in r.root.branches]
    assert min(lows) == 0.0 and all(lo >= 0.0 for lo in lows)
