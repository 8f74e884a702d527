"""Numeric edges (docs/conventions.md, "Numeric tolerances: one policy"), against exact geometry.

- Snapped diameters read as their cluster's span, so every reading a state's true,
  unsnapped diameter can give lies in a branch (the catalog octagon at tolerance 0.01; a
  1e6 mm square with a corner raised 5e-4 mm), and a tolerance below the snapping scale is
  refused in one line.
- Margins are per state: every reachable state at every step is at least ``margin_deg``
  from each divergent orientation (with a rotation error: from where its outcome set
  changes), checked by :mod:`edge_oracle`, which shares no code with feederkit, on a
  hexagon whose rotation used to sit on an unstable equilibrium and on random parts.
- Cells no wider than ``ANGLE_EPS`` are never used (a cross with a 1e-9 perturbation).

Each case runs on the ideal model and under the default uncertainty (rotation error 1 deg).
"""

from __future__ import annotations

import copy
import json
import math
import random
from pathlib import Path

import pytest
from edge_oracle import check_plan, circle_distance, mechanics

from feederkit.angles import ANGLE_EPS, boundary_cells, norm360
from feederkit.cli.app import main
from feederkit.errors import InputError, PlanningError
from feederkit.machine import search_space
from feederkit.machine.build import build_machine, snap_intervals, snap_spans
from feederkit.mechanics.push import push_function
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.outline import make_outline, outline_from_dict
from feederkit.part import make_part
from feederkit.planning.choices import Choices
from feederkit.planning.options import Grouping, PlanningOptions
from feederkit.planning.readings import Readings
from feederkit.plans.make import make_plan
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
MODELS = [pytest.param(IDEAL, id="ideal"), pytest.param(Uncertainty(), id="default")]
PUSH_DEPTH_REL = 2e-3
"""The push bands' depth under uncertainty: twice the default vibration, 1e-3 of the size
(docs/uncertainty.md, "Push bands")."""


def _pf(name, vertices, com=None):
    return push_function(make_part(make_outline(name, vertices), com=com))


def _octagon():
    return push_function(
        make_part(outline_from_dict(json.loads((CATALOG / "octagon.json").read_text())))
    )


def _raised_square():
    """A 1e6 mm square with one corner raised 5e-4 mm: its diameters differ by less than the
    snapping scale (1e-9 of the size), by far more than an ulp."""
    s = 1e6
    return _pf("raised-square", [(0.0, 0.0), (s, 0.0), (s, s + 5e-4), (0.0, s)])


def _nodes(plan):
    """Every node of a plan file (shared subplans resolved), each once."""
    shared = plan.get("nodes") or {}
    out, stack, seen = [], [plan["root"]], set()
    while stack:
        node = stack.pop()
        while "ref" in node:
            node = shared[node["ref"]]
        if id(node) in seen:
            continue
        seen.add(id(node))
        out.append(node)
        stack.extend(b["next"] for b in node.get("branches", ()))
    return out


def _true_reading_sets(pf, unc, tolerance):
    """Each state's open reading interval from its true, unsnapped diameter (interval)."""
    if unc.is_ideal:
        spans = [(s.diameter, s.diameter) for s in pf.states]
    else:
        spans = [s.diameter for s in uncertain_mechanics(pf.part, unc).states]
    return [(max(0.0, lo - tolerance), hi + tolerance) for lo, hi in spans]


def _uncovered(lo, hi, intervals):
    """Whether some reading of the open (lo, hi) lies in none of the closed intervals."""
    cur = lo
    for a, b in sorted(intervals):
        if a > cur:
            return True
        cur = max(cur, b)
        if cur >= hi:
            return False
    return cur < hi


def _root_gaps(plan, pf, unc, tolerance):
    """The true reading sets the root's branches leave a reading of uncovered."""
    ivs = [tuple(b["reading"]) for b in plan["root"]["branches"]]
    return [iv for iv in _true_reading_sets(pf, unc, tolerance) if _uncovered(*iv, ivs)]


# ---------------------------------------------------------------- item 2: snapping gaps


def test_snap_spans_hold_every_value_and_keep_ties():
    values = [2.0, 1.0, 1.0 + 1e-12, 3.0, 1.0 + 2e-12]
    spans = snap_spans(values, 1e-9)
    assert spans[1] == spans[2] == spans[4] == (1.0, 1.0 + 2e-12)
    assert all(lo <= v <= hi for v, (lo, hi) in zip(values, spans, strict=True))
    assert spans[0] == (2.0, 2.0) and spans[3] == (3.0, 3.0)
    ivs = snap_intervals([(1.0, 2.0 - 1e-12), (1.0 + 1e-12, 2.0)], 1e-9)
    assert ivs[0] == ivs[1] == (1.0, 2.0)


def test_the_octagon_machine_reads_its_symmetric_states_as_one_span():
    pf = _octagon()
    true = sorted({s.diameter for s in pf.states})
    assert len(true) == 2 and 0.0 < true[1] - true[0] < 1e-12  # rounding, not geometry
    m = build_machine([pf], ToleranceSensor(0.01), IDEAL)
    assert {s.sensed for s in m.states} == {(true[0], true[1])}


@pytest.mark.parametrize("unc", MODELS)
def test_every_true_octagon_reading_lies_in_a_branch(unc):
    pf = _octagon()
    made = make_plan([pf], ToleranceSensor(0.01), uncertainty=unc, certify=False)
    assert _root_gaps(made.plan, pf, unc, 0.01) == []
    # the readings the issue saw rejected as a foreign part
    top = max(s.diameter for s in pf.states) + 0.01
    for r in (1.857759065022 + 2e-14, math.nextafter(top, 0.0)):
        assert any(
            lo <= r <= hi for lo, hi in (b["reading"] for b in made.plan["root"]["branches"])
        )


def test_the_octagon_plan_from_the_command_line_holds_its_top_reading(tmp_path, capsys):
    out = tmp_path / "octagon.plan.json"
    args = ["plan", str(CATALOG / "octagon.json"), "--tolerance", "0.01", "--rotation-error", "0"]
    assert main([*args, "-o", str(out)]) == 0, capsys.readouterr().err
    plan = json.loads(out.read_text())
    top = max(s.diameter for s in _octagon().states) + 0.01
    assert max(b["reading"][1] for b in plan["root"]["branches"]) >= top
    assert main(["run", str(out), "--all"]) == 0
    assert "paths end in their result" in capsys.readouterr().out


@pytest.mark.parametrize("unc", MODELS)
def test_a_tolerance_below_the_snapping_scale_is_refused_in_one_line(unc):
    with pytest.raises(InputError, match="finer than the parts' diameters are known") as exc:
        make_plan([_raised_square()], ToleranceSensor(1e-4), uncertainty=unc, certify=False)
    assert "\n" not in str(exc.value)


def test_the_command_line_refuses_it_with_exit_2(tmp_path, capsys):
    path = tmp_path / "raised-square.json"
    s = 1e6
    verts = [[0.0, 0.0], [s, 0.0], [s, s + 5e-4], [0.0, s]]
    path.write_text(json.dumps({"name": "raised-square", "units": "mm", "vertices": verts}))
    from feederkit.cli.app import main

    assert main(["plan", str(path), "--tolerance", "1e-4"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    # A square a kilometre across said to be in mm is warned about first (its units).
    assert [x[:7] for x in lines] == ["warning", "error: "] and "check the units" in lines[0]
    assert "finer than the parts' diameters are known" in lines[1]


@pytest.mark.parametrize("unc", MODELS)
def test_readings_of_diameters_snapped_together_stay_in_the_plan(unc):
    # Just above the scale (1e-3 mm): the 5e-4 mm the snapping joins is a third of the
    # tolerance, and a branch built on the snapped value alone would miss it.
    pf = _raised_square()
    sensor = ToleranceSensor(1.5e-3)
    made = make_plan([pf], sensor, uncertainty=unc, certify=False)
    assert made.report.ok
    assert _root_gaps(made.plan, pf, unc, 1.5e-3) == []


def test_the_gap_check_can_fail():
    plan = {"root": {"branches": [{"reading": [0.9, 1.1]}, {"reading": [1.1 + 1e-9, 2.0]}]}}
    assert _uncovered(0.95, 1.5, [tuple(b["reading"]) for b in plan["root"]["branches"]])
    assert not _uncovered(0.95, 1.1, [(0.9, 1.1)])


# ---------------------------------------------------------------- item 3: margins per state


def _hexagon():
    pts = [(math.cos(math.radians(60 * k)), math.sin(math.radians(60 * k))) for k in range(6)]
    pts[0] = (1.01, 0.0)  # one vertex pushed out 1 %
    return _pf("hexagon", pts, com=(0.0, 0.0))


def test_the_hexagon_rotation_keeps_every_state_off_its_divergent_orientations():
    made = make_plan([_hexagon()], NoSensor(), uncertainty=IDEAL, certify=False)
    assert list(check_plan(made.plan)) == []
    mech = mechanics(made.plan["parts"][0]["hull"], made.plan["parts"][0]["com"])
    for node in _nodes(made.plan):
        a = node.get("action_deg")
        if a is None:
            continue
        for normal in mech.normals.values():
            gap = min(circle_distance(normal - a, d) for d in mech.divergent)
            assert gap > 0.1  # the old plan's rotation of 30 deg sat on one: 0


def test_the_checker_finds_a_rotation_on_a_divergent_orientation():
    made = make_plan([_hexagon()], NoSensor(), uncertainty=IDEAL, certify=False)
    plan = copy.deepcopy(made.plan)
    step = next(n for n in _nodes(plan) if n.get("action_deg") is not None)
    mech = mechanics(plan["parts"][0]["hull"], plan["parts"][0]["com"])
    normal = min(mech.normals.values())
    step["action_deg"] = norm360(normal - mech.divergent[0])  # the fence meets a vertex
    assert any(f.kind == "margin" for f in check_plan(plan))


def _random_part(rng, k):
    n = rng.randint(3, 9)
    pts = []
    for a in sorted(rng.uniform(0.0, 2.0 * math.pi) for _ in range(n)):
        r = rng.uniform(5.0, 20.0)
        pts.append((r * math.cos(a), r * math.sin(a)))
    return make_part(make_outline(f"random-{k}", pts))


def _plain(pf, unc):
    """Whether the part's physical states are its ideal states, each settling only in
    itself (the checker models rotation error and push bands, not vibration merging)."""
    mech = uncertain_mechanics(pf.part, unc)
    return all(len(s.members) == 1 for s in mech.states) and all(
        len(d) == 1 for d in mech.destinations
    )


def random_margin_violations(count, unc, seed=1):
    """Plans of ``count`` random parts (sensorless and with a 1 % tolerance sensor, in turn)
    checked by the independent checker: (plans checked, plans with a violation, first)."""
    rng = random.Random(seed)
    checked, bad, first = 0, 0, None
    depth = 0.0 if unc.is_ideal else PUSH_DEPTH_REL
    for k in range(count):
        try:
            pf = push_function(_random_part(rng, k))
        except InputError:
            continue  # a self-intersecting outline
        if not unc.is_ideal and not _plain(pf, unc):
            continue
        sensor = NoSensor() if k % 2 else ToleranceSensor(round(pf.part.size * 0.01, 3))
        try:
            made = make_plan(
                [pf], sensor, PlanningOptions(time_limit_s=5.0), uncertainty=unc, certify=False
            )
        except PlanningError:
            continue  # no strong plan at this uncertainty
        checked += 1
        found = list(check_plan(made.plan, push_depth_rel=depth))
        if found:
            bad += 1
            first = first or found[0].text
    return checked, bad, first


@pytest.mark.parametrize(
    ("unc", "count"), [(IDEAL, 40), (Uncertainty(), 16)], ids=["ideal", "default"]
)
def test_random_parts_keep_their_margins(unc, count):
    checked, bad, first = random_margin_violations(count, unc)
    assert checked >= count // 3
    assert bad == 0, first


@pytest.mark.slow
@pytest.mark.parametrize("unc", MODELS)
def test_four_hundred_random_parts_keep_their_margins(unc):
    checked, bad, first = random_margin_violations(400, unc)
    assert checked >= 250
    assert bad == 0, first


# ---------------------------------------------------------------- item 6: cells below ANGLE_EPS


def test_boundary_cells_leave_out_slivers_and_keep_the_rest_exactly():
    cells = boundary_cells([[10.0, 90.0], [10.0 + 5e-8, 200.0]])
    assert cells == [(10.0 + 5e-8, 90.0), (90.0, 200.0), (200.0, 370.0)]
    assert boundary_cells([[0.0, 180.0], [359.99999995]]) == [(0.0, 180.0), (180.0, 359.99999995)]


def _cross(perturbation):
    a, b = 0.5, 1.5
    pts = [(a, -b), (a, -a), (b, -a), (b, a), (a, a), (a, b), (-a, b), (-a, a), (-b, a)]
    pts += [(-b, -a), (-a, -a), (-a, -b)]
    pts[2] = (b + perturbation, -a)
    return _pf("cross", pts, com=(0.0, 0.0))


def _genuine_cells(machine, mask):
    """Brute force: the intervals between consecutive boundaries wider than ANGLE_EPS."""
    bounds = sorted(
        {norm360(x) for i in range(machine.n) if mask >> i & 1 for x in machine.starts[i]}
    )
    pairs = list(zip(bounds, bounds[1:], strict=False)) + [(bounds[-1], bounds[0] + 360.0)]
    return [(lo, hi) for lo, hi in pairs if hi - lo > ANGLE_EPS]


@pytest.mark.parametrize("unc", MODELS)
def test_the_planners_cells_are_every_cell_wider_than_the_angle_tolerance(unc):
    pf = _cross(1e-9)
    machine = build_machine([pf], NoSensor(), unc)
    choices = Choices(machine, Readings(machine, Grouping.EXACT, (0,) * machine.n))
    rng = random.Random(3)
    for _ in range(30):
        mask = rng.randrange(1, 1 << machine.n)
        cells = choices.fixed_cells(mask)
        assert [(lo, hi) for lo, hi, _img in cells] == _genuine_cells(machine, mask)
        for lo, hi, img in cells:
            assert img == machine.image(mask, norm360((lo + hi) / 2.0))


@pytest.mark.parametrize("unc", MODELS)
@pytest.mark.parametrize(
    "sensor", [NoSensor(), ToleranceSensor(0.01)], ids=["sensorless", "tolerance"]
)
def test_the_perturbed_cross_is_planned_only_with_rotations_a_robot_can_hold(unc, sensor):
    pf = _cross(1e-9)
    assert (
        min(abs(s.normal_deg - t.normal_deg) for s in pf.states for t in pf.states if s != t) > 1.0
    )
    try:
        made = make_plan([pf], sensor, uncertainty=unc, certify=False)
    except PlanningError as exc:
        assert not unc.is_ideal and "no strong plan" in str(exc)
        return
    assert made.report.ok and made.plan["stats"]["optimal"]
    margins = [n["margin_deg"] for n in _nodes(made.plan) if n.get("margin_deg") is not None]
    assert all(m > ANGLE_EPS / 2.0 for m in margins)
    depth = 0.0 if unc.is_ideal else PUSH_DEPTH_REL
    assert list(check_plan(made.plan, push_depth_rel=depth)) == []


def _shortest_sensorless(machine, min_width):
    """Brute force: the fewest operations orienting every state with no sensor, rotating
    only in cells wider than ``min_width`` (the first alignment counted)."""
    space = search_space(machine)
    frontier, seen, depth = {machine.all_states}, {machine.all_states}, 1
    while frontier:
        if any(space.is_goal(m) for m in frontier):
            return depth
        nxt = set()
        for mask in frontier:
            bounds = sorted(
                {norm360(x) for i in range(machine.n) if mask >> i & 1 for x in machine.starts[i]}
            )
            pairs = list(zip(bounds, bounds[1:], strict=False))
            pairs.append((bounds[-1], bounds[0] + 360.0))
            for lo, hi in pairs:
                if hi - lo > min_width:
                    img = machine.image(mask, norm360((lo + hi) / 2.0))
                    if img not in seen:
                        seen.add(img)
                        nxt.add(img)
        frontier, depth = nxt, depth + 1
    return None


@pytest.mark.parametrize("perturbation", [0.0, 1e-9, 1e-3])
def test_the_cross_plan_is_optimal_among_rotations_a_robot_can_hold(perturbation):
    pf = _cross(perturbation)
    machine = build_machine([pf], NoSensor(), IDEAL)
    made = make_plan([pf], NoSensor(), uncertainty=IDEAL, certify=False)
    assert made.plan["stats"]["optimal"]
    assert made.plan["stats"]["length"] == _shortest_sensorless(machine, ANGLE_EPS)


def test_reading_windows_of_snapped_spans_match_reading_alike():
    rng = random.Random(5)
    sensor = ToleranceSensor(0.3)
    checked = 0
    for _ in range(50):
        xs = sorted(rng.uniform(1.0, 6.0) for _ in range(8))  # no reading set clipped at 0
        spans = [(x, x + rng.choice([0.0, 1e-12, 0.05])) for x in xs]
        spans = [
            s if s[1] <= (spans[i + 1][0] if i + 1 < 8 else 9.0) else (s[0], s[0])
            for i, s in enumerate(spans)
        ]
        wins = sensor.reading_windows(spans)
        if wins is None:
            continue  # a pair on the edge of reading alike: the reading cells decide
        checked += 1
        for a in range(8):
            want = sum(1 << b for b in range(a, 8) if sensor.can_read_alike(spans[a], spans[b]))
            assert wins[a] == want
        shared = sensor.shared_reading_probability(spans)
        cells = sensor.split(spans)
        for t in range(8):
            alone = sum(b.hi - b.lo for b in cells if b.mask == 1 << t)
            width = spans[t][1] - spans[t][0] + 0.6
            assert shared[t] == pytest.approx(1.0 - alone / width, abs=1e-9)
    assert checked >= 25
