"""The cycle-time objectives (``time``, ``worst-time``) and "ties prefer less time".

An evaluator written here (no code shared with ``planning.stats``) gives a plan tree's
expected and worst seconds from the machine alone: a state's mass follows its outcome set
under the action's representative rotation (shared equally), then each branch with the
probability that its reading falls in it (docs/planning.md). A brute force, also written
here, tries every plan over the same actions (the sets' overlap ranges) and reading
branches up to the objective's horizon, with no bound (only the plain length is memoised).
"""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest

from feederkit.errors import InputError
from feederkit.machine import build_machine, members, search_space
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan
from feederkit.planning.options import ActionCosts, Objective, PlanningOptions
from feederkit.planning.refine import EXPECTED_HORIZON
from feederkit.planning.tree import Leaf
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.sources import load_part
from feederkit.uncertainty import IDEAL, Uncertainty

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
COSTS = ActionCosts(pick_place_s=1.2, rotation_speed_deg_s=60.0, drift_s=0.5)
FREE_TURNS = ActionCosts(pick_place_s=1.2, rotation_speed_deg_s=math.inf, drift_s=0.5)


def turn_seconds(rotation: float | None, costs: ActionCosts) -> float:
    """One operation's seconds, from docs/cell.md's formula."""
    if rotation is None:
        return costs.drift_s
    a = rotation % 360.0
    return costs.pick_place_s + min(a, 360.0 - a) / costs.rotation_speed_deg_s + costs.drift_s


def evaluate(machine, root, costs: ActionCosts) -> tuple[float, float, float]:
    """(expected seconds, worst seconds, expected operations) of a plan tree."""

    def walk(node, state: int) -> tuple[float, float]:
        if isinstance(node, Leaf):
            assert node.mask >> state & 1
            return 0.0, 0.0
        rot = None if node.action is None else node.action.representative
        outs = [state] if rot is None else members(machine.outcomes(state, rot))
        secs, ops = turn_seconds(rot, costs), 1.0
        for t in outs:
            sensed = machine.states[t].sensed
            for b, sub in node.branches:
                if b.mask >> t & 1:
                    p = machine.sensor.reading_probability(sensed, b.lo, b.hi)
                    if p > 0.0:
                        s, o = walk(sub, t)
                        secs += p * s / len(outs)
                        ops += p * o / len(outs)
        return secs, ops

    def slowest(node) -> float:
        if isinstance(node, Leaf):
            return 0.0
        rot = None if node.action is None else node.action.representative
        return turn_seconds(rot, costs) + max(slowest(sub) for _, sub in node.branches)

    total = sum(s.weight for s in machine.states)
    exp_s = exp_o = 0.0
    for i, s in enumerate(machine.states):
        a, b = walk(root, i)
        exp_s += s.weight * a
        exp_o += s.weight * b
    return exp_s / total, slowest(root), exp_o / total


def catalog_pfs(*names: str):
    return [push_function(load_part(str(CATALOG / f"{n}.json"))) for n in names]


def random_pf(seed: int):
    rng = random.Random(seed)
    n = rng.randint(3, 5)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    a = rng.uniform(5, 20)
    b = a * rng.uniform(0.5, 1.0)
    pts = [(a * math.cos(t), b * math.sin(t)) for t in angles]
    mx, my = sum(p[0] for p in pts) / n, sum(p[1] for p in pts) / n
    vx, vy = rng.choice(pts)
    t = rng.uniform(0.0, 0.5)  # toward a vertex: inside the convex polygon
    cx, cy = mx + t * (vx - mx), my + t * (vy - my)
    part = make_part(make_outline(f"r{seed}", pts), com=(cx, cy))
    return push_function(part)


MACHINES = [
    ("mix3-ideal", lambda: build_machine(
        catalog_pfs("quadrilateral", "rectangle-2x1", "l-bracket"), ToleranceSensor(0.2), IDEAL)),
    ("mix3-strong", lambda: build_machine(
        catalog_pfs("quadrilateral", "rectangle-2x1", "l-bracket"), ToleranceSensor(0.2),
        Uncertainty())),
    ("tclip-plate", lambda: build_machine(
        catalog_pfs("t-clip", "chamfered-plate"), ToleranceSensor(0.5), Uncertainty())),
    ("quad-sensorless", lambda: build_machine(
        catalog_pfs("quadrilateral"), NoSensor(), Uncertainty())),
    ("triangles", lambda: build_machine(
        catalog_pfs("equilateral-triangle", "isosceles-right-triangle"), ToleranceSensor(0.01),
        IDEAL)),
]  # fmt: skip


def plans_for(machine, costs: ActionCosts):
    return {
        obj: plan(machine, PlanningOptions(objective=obj, costs=costs))
        for obj in ("worst", "expected", "time", "worst-time")
    }


@pytest.mark.parametrize(("name", "make"), MACHINES, ids=[m[0] for m in MACHINES])
def test_time_is_never_slower_than_the_operation_count_plans(name, make):
    machine = make()
    made = plans_for(machine, COSTS)
    seconds = {obj: evaluate(machine, r.root, COSTS) for obj, r in made.items()}
    plain = plan(machine, PlanningOptions(objective="expected"))
    plain_s = evaluate(machine, plain.root, COSTS)[0]
    for obj in ("worst", "expected", "worst-time"):
        assert seconds["time"][0] <= seconds[obj][0] + 1e-9, obj
    assert seconds["time"][0] <= plain_s + 1e-9
    # Shortest first: the worst-time plan is as short as the worst plan and never slower
    # on its slowest path than any plan of that length found here.
    assert made["worst-time"].length == made["worst"].length
    assert seconds["worst-time"][1] <= seconds["worst"][1] + 1e-9
    # The time plan keeps the expected objective's horizon.
    assert made["time"].length <= EXPECTED_HORIZON * (made["worst"].length - 1) + 1
    assert made["time"].objective == "time" and made["worst-time"].objective == "worst-time"


@pytest.mark.parametrize(("name", "make"), MACHINES, ids=[m[0] for m in MACHINES])
def test_free_rotations_make_time_the_expected_operations(name, make):
    machine = make()
    timed = plan(machine, PlanningOptions(objective="time", costs=FREE_TURNS))
    counted = plan(machine, PlanningOptions(objective="expected"))
    t_s, _w, t_ops = evaluate(machine, timed.root, FREE_TURNS)
    assert t_ops == pytest.approx(counted.expected_length, abs=1e-9)
    # Every operation after the first costs the same: seconds are an affine map of counts.
    want = FREE_TURNS.drift_s + (t_ops - 1.0) * FREE_TURNS.least_s
    assert t_s == pytest.approx(want, rel=1e-9)


@pytest.mark.parametrize(("name", "make"), MACHINES, ids=[m[0] for m in MACHINES])
def test_ties_among_equal_counts_prefer_less_time(name, make):
    machine = make()
    for obj in ("worst", "expected"):
        plain = plan(machine, PlanningOptions(objective=obj))
        timed = plan(machine, PlanningOptions(objective=obj, costs=COSTS))
        assert timed.length == plain.length
        assert timed.expected_length == pytest.approx(plain.expected_length, abs=1e-9)
        if obj == "worst":
            assert timed.min_margin == pytest.approx(plain.min_margin, abs=1e-9)
        assert evaluate(machine, timed.root, COSTS)[0] <= (
            evaluate(machine, plain.root, COSTS)[0] + 1e-9
        )


def test_the_planner_reports_the_evaluators_figures():
    from feederkit.planning.stats import expected_seconds, worst_seconds

    machine = MACHINES[1][1]()
    for obj, r in plans_for(machine, COSTS).items():
        exp_s, worst_s, exp_ops = evaluate(machine, r.root, COSTS)
        assert expected_seconds(machine, r.root, COSTS) == pytest.approx(exp_s, rel=1e-12), obj
        assert worst_seconds(r.root, COSTS) == pytest.approx(worst_s, rel=1e-12), obj
        assert r.expected_length == pytest.approx(exp_ops, rel=1e-12), obj


# The brute force: every plan over the sets' overlap ranges, plainly.


class Brute:
    def __init__(self, machine, costs: ActionCosts) -> None:
        self.m = machine
        self.space = search_space(machine)
        self.insep = self.space.inseparable
        self.costs = costs
        self._length: dict[tuple[int, int], float] = {}

    def goal(self, mask: int) -> bool:
        return all(self.insep[i] >> j & 1 for i in members(mask) for j in members(mask) if i < j)

    def moves(self, mask: int, masses):
        """Per overlap range: its seconds and, per reading branch, (set, mass, masses)."""
        for lo, hi, img in self.space.overlap_cells(mask):
            rot = (lo + hi) / 2.0
            moved: dict[int, float] = {}
            for i, w in zip(members(mask), masses, strict=True):
                outs = members(self.m.outcomes(i, rot))
                for t in outs:
                    moved[t] = moved.get(t, 0.0) + w / len(outs)
            yield turn_seconds(rot, self.costs), self.split(img, moved)

    def split(self, image: int, moved: dict[int, float]):
        out = []
        for b in self.space.branches(image):
            idx = members(b.mask)
            ws = [
                moved.get(t, 0.0)
                * self.m.sensor.reading_probability(self.m.states[t].sensed, b.lo, b.hi)
                for t in idx
            ]
            total = sum(ws)
            norm = [w / total for w in ws] if total > 0.0 else [1.0 / len(idx)] * len(idx)
            out.append((b.mask, total, norm))
        return out

    def length(self, mask: int, k: int) -> float:
        if self.goal(mask):
            return 0
        if k == 0:
            return math.inf
        if (mask, k) not in self._length:
            best = math.inf
            for _sec, kids in self.moves(mask, [1.0] * mask.bit_count()):
                best = min(best, 1 + max(self.length(c, k - 1) for c, _p, _w in kids))
            self._length[(mask, k)] = best
        return self._length[(mask, k)]

    def expected(self, mask: int, masses, k: int) -> float:
        if self.goal(mask):
            return 0.0
        if k == 0:
            return math.inf
        best = math.inf
        for sec, kids in self.moves(mask, masses):
            val = sec
            for c, p, w in kids:
                if p > 0.0:
                    val += p * self.expected(c, w, k - 1)
                elif self.length(c, k - 1) == math.inf:
                    val = math.inf  # a plan must orient every branch, likely or not
            best = min(best, val)
        return best

    def worst(self, mask: int, k: int) -> float:
        if self.goal(mask):
            return 0.0
        if k == 0:
            return math.inf
        best = math.inf
        for sec, kids in self.moves(mask, [1.0] * mask.bit_count()):
            best = min(best, sec + max(self.worst(c, k - 1) for c, _p, _w in kids))
        return best

    def roots(self):
        full = self.m.all_states
        return self.split(full, {i: s.weight for i, s in enumerate(self.m.states)})


SMALL = [
    ("triangles-ideal", lambda: build_machine(
        catalog_pfs("equilateral-triangle", "isosceles-right-triangle"), ToleranceSensor(0.01),
        IDEAL)),
    ("quad-strong", lambda: build_machine(
        catalog_pfs("quadrilateral"), ToleranceSensor(0.05), Uncertainty())),
] + [
    pytest.param("rect-quad", lambda: build_machine(
        catalog_pfs("rectangle-2x1", "quadrilateral"), ToleranceSensor(0.2), IDEAL),
        marks=pytest.mark.slow, id="rect-quad"),
] + [
    (f"random-{seed}", lambda seed=seed: build_machine(
        [random_pf(seed)], ToleranceSensor(0.5), IDEAL))
    for seed in range(4)
]  # fmt: skip


@pytest.mark.parametrize(("name", "make"), SMALL)
def test_brute_force_agrees_on_small_machines(name, make):
    machine = make()
    brute = Brute(machine, COSTS)
    roots = brute.roots()
    worst_plan = plan(machine, PlanningOptions(objective="worst-time", costs=COSTS))
    budget = worst_plan.length - 1
    assert max(brute.length(c, budget + 1) for c, _p, _w in roots) == budget
    # worst-time: the slowest path among plans of the minimum length.
    want_worst = COSTS.drift_s + max(brute.worst(c, budget) for c, _p, _w in roots)
    assert evaluate(machine, worst_plan.root, COSTS)[1] == pytest.approx(want_worst, rel=1e-9)
    # time: the expected seconds within the expected objective's horizon.
    horizon = EXPECTED_HORIZON * budget
    want = COSTS.drift_s + sum(p * brute.expected(c, w, horizon) for c, p, w in roots if p > 0)
    timed = plan(machine, PlanningOptions(objective="time", costs=COSTS))
    assert evaluate(machine, timed.root, COSTS)[0] == pytest.approx(want, rel=1e-9)


def test_bad_costs_and_missing_costs_are_input_errors():
    for kwargs, needle in (
        ({"pick_place_s": -1.0, "rotation_speed_deg_s": 1.0, "drift_s": 0.0}, "pick-and-place"),
        ({"pick_place_s": 1.0, "rotation_speed_deg_s": 0.0, "drift_s": 0.0}, "rotation speed"),
        ({"pick_place_s": 1.0, "rotation_speed_deg_s": 1.0, "drift_s": math.nan}, "drift"),
        ({"pick_place_s": True, "rotation_speed_deg_s": 1.0, "drift_s": 0.0}, "pick-and-place"),
    ):
        with pytest.raises(InputError, match=needle):
            ActionCosts(**kwargs)
    for obj in ("time", "worst-time"):
        with pytest.raises(InputError, match="needs the seconds of an operation"):
            PlanningOptions(objective=obj)
    with pytest.raises(InputError, match="worst, expected, time, worst-time"):
        PlanningOptions(objective="fastest", costs=COSTS)
    assert Objective("worst-time").timed and not Objective("expected").timed


@pytest.mark.parametrize(("name", "make"), MACHINES[:3], ids=[m[0] for m in MACHINES[:3]])
def test_a_margin_floor_holds_with_costs(name, make):
    machine = make()
    widest = plan(machine, PlanningOptions(objective="worst")).min_margin
    floor = widest / 2.0
    for obj in ("worst", "expected", "time", "worst-time"):
        r = plan(machine, PlanningOptions(objective=obj, costs=COSTS, min_margin_deg=floor))
        assert r.min_margin >= floor - 1e-9, obj
    # The worst objective keeps the largest smallest margin with or without costs.
    timed = plan(machine, PlanningOptions(objective="worst", costs=COSTS))
    assert timed.min_margin == pytest.approx(widest, abs=1e-9)
