"""Which states a plan may list together: only poses that look alike, unless asked otherwise.

docs/planning.md, "Near-symmetric states under uncertainty": under the default rule
(``Lumping.NEAR_SYMMETRIC``) a pair of one part's states that no strong plan resolves is
lumped only when their poses' outlines differ by at most ``NEAR_SYMMETRIC_REL`` of the part's
size (:func:`~feederkit.mechanics.symmetry.pose_difference`, recorded by the machine build);
``any`` lumps every such pair (with a warning), ``none`` never lumps.
"""

from __future__ import annotations

import json
import math
import random
from pathlib import Path

import pytest

from feederkit.cli.app import main
from feederkit.errors import InputError, PlanningError
from feederkit.hull import convex_hull
from feederkit.machine import (
    MachineState,
    OutcomeRange,
    PushAlignMachine,
    build_machine,
    search_space,
)
from feederkit.mechanics import push_function
from feederkit.mechanics.symmetry import (
    NEAR_SYMMETRIC_REL,
    look_alike,
    pose_difference,
    poses_difference,
)
from feederkit.outline import load_outline_json, make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan, strong_plan_exists
from feederkit.planning.lumping import may_lump, try_lumping
from feederkit.planning.options import Lumping, PlanningOptions
from feederkit.planning.solvable import NoStrongPlan
from feederkit.planning.tree import Leaf
from feederkit.plans.make import make_plan
from feederkit.plans.strong import verify_strong
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

CHAMFER = 0.2
"""The 5 x 2.5 rectangle with one corner cut by this much (mm): its two long-side poses
look 0.14 mm apart (2.8 % of the part), yet a push band keeps every strong plan from
telling them apart."""

RECT = [[0, 0], [5, 0], [5, 2.5], [0, 2.5]]


def chamfered(c: float = CHAMFER):
    pts = [[0, 0], [5, 0], [5, 2.5 - c], [5 - c, 2.5], [0, 2.5]]
    return push_function(make_part(make_outline("cham", pts)))


def near_rectangle(dx: float = 0.008):
    return push_function(make_part(make_outline("rect", RECT), [2.5 + dx, 1.25]))


def long_sides(pf) -> tuple[int, int]:
    """The two states resting on a long side (diameter 2.5 mm)."""
    a, b = (s.id for s in pf.states if math.isclose(s.diameter, 2.5, abs_tol=1e-9))
    return a, b


# --- the measure ---------------------------------------------------------------------------


def test_congruent_poses_differ_by_nothing():
    rect = near_rectangle()
    a, b = long_sides(rect)
    # Congruent outlines; the COM a hair off their symmetry moves by twice its offset.
    assert pose_difference(rect, a, b) == pytest.approx(2 * 0.008, abs=1e-9)
    assert pose_difference(rect, a, b) <= NEAR_SYMMETRIC_REL * rect.part.size
    centred = push_function(make_part(make_outline("rect", RECT)))
    a, b = long_sides(centred)
    assert pose_difference(centred, a, b) == pytest.approx(0.0, abs=1e-9)
    hexagon = [[math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)] for k in range(6)]
    pf = push_function(make_part(make_outline("hex", hexagon)))
    assert pf.n == 6
    assert all(pose_difference(pf, 0, k) == pytest.approx(0.0, abs=1e-9) for k in range(6))


def test_a_cut_corner_moves_the_pose_by_its_distance_from_the_corner():
    """Resting on either long side the outlines differ only at the cut corner (top right in
    one pose, bottom left in the other): each corner is c / sqrt(2) from the cut."""
    pf = chamfered()
    a, b = long_sides(pf)
    assert pose_difference(pf, a, b) == pytest.approx(CHAMFER / math.sqrt(2), rel=1e-9)
    assert pose_difference(pf, b, a) == pytest.approx(pose_difference(pf, a, b), rel=1e-12)
    # lying on a long side against a short one: at least the difference of the heights
    short = next(s.id for s in pf.states if s.id not in (a, b))
    assert pose_difference(pf, a, short) >= 5.0 - 2.5 - 1e-9


@pytest.mark.parametrize("seed", range(8))
def test_pose_difference_is_the_hausdorff_distance_of_the_outlines(seed):
    """Against shapely's own Hausdorff distance of the two placed hulls (an independent
    computation; for convex outlines the vertex-based one is exact)."""
    from shapely import Polygon, hausdorff_distance

    rng = random.Random(seed)
    k = rng.randint(3, 9)
    angles = sorted(rng.uniform(0, 2 * math.pi) for _ in range(k))
    pts = [[10 * math.cos(a) * rng.uniform(0.5, 1), 6 * math.sin(a)] for a in angles]
    pts = convex_hull(pts)  # the outline is its hull (a concave one: the next test)
    pf = push_function(make_part(make_outline("rnd", pts)))
    hull = [tuple(p) for p in pf.part.hull]

    def placed(i):
        t = math.radians(pf.states[i].pose_deg)
        xy = [
            (x * math.cos(t) - y * math.sin(t), x * math.sin(t) + y * math.cos(t)) for x, y in hull
        ]
        lo_x, hi_x = min(p[0] for p in xy), max(p[0] for p in xy)
        lo_y = min(p[1] for p in xy)
        return Polygon([(x - (lo_x + hi_x) / 2, y - lo_y) for x, y in xy])

    for i in range(pf.n):
        for j in range(pf.n):
            want = hausdorff_distance(placed(i), placed(j))
            assert pose_difference(pf, i, j) == pytest.approx(want, rel=1e-9, abs=1e-9)


def test_sets_of_poses_differ_by_their_farthest_pose():
    pf = chamfered()
    a, b = long_sides(pf)
    short = next(s.id for s in pf.states if s.id not in (a, b))
    d = pose_difference(pf, a, b)
    assert poses_difference(pf, [a], [b]) == pytest.approx(d)
    assert poses_difference(pf, [a, b], [b]) == pytest.approx(d)  # a is d from b
    assert poses_difference(pf, [a], [a, short]) == pytest.approx(pose_difference(pf, a, short))


@pytest.mark.parametrize(("c", "alike"), [(0.05, True), (CHAMFER, False)])
def test_look_alike_is_the_one_percent_bound(c, alike):
    pf = chamfered(c)
    a, b = long_sides(pf)
    near = pose_difference(pf, a, b) <= NEAR_SYMMETRIC_REL * pf.part.size
    assert near is alike
    groups = [[s.id] for s in pf.states]
    table = look_alike(pf, groups)
    assert (b in table[a]) is alike and (a in table[b]) is alike
    assert all(k not in table[k] for k in range(len(groups)))
    assert all(j in table[i] for i in range(len(groups)) for j in table[i])  # symmetric


def _plate(hole_x: float | None = None, notch: bool = False):
    """A 40 x 20 mm plate, with an R4 hole centred at (``hole_x``, 10) or a 1 x 1 mm notch in
    its top right corner; its COM where the material puts it."""
    outer = [[0, 0], [40, 0], [40, 20], [0, 20]]
    if notch:
        outer = [[0, 0], [40, 0], [40, 19], [39, 19], [39, 20], [0, 20]]
    holes = []
    if hole_x is not None:
        holes = [[[hole_x + 4 * math.cos(k * math.pi / 32), 10 + 4 * math.sin(k * math.pi / 32)]
                  for k in range(64)]]  # fmt: skip
    outline = make_outline("plate", outer, holes=holes)
    return push_function(make_part(outline))


def _brute_outline_distance(pf, a: int, b: int, step: float = 0.02) -> float:
    """The Hausdorff distance of the outline's boundary (outer ring and holes) in two poses,
    from points every ``step`` mm of each to every point of the other (numpy, no shapely)."""
    import numpy as np

    def samples(i):
        t = math.radians(pf.states[i].pose_deg)
        rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
        hull = np.asarray(pf.part.hull) @ rot.T
        shift = np.array([(hull[:, 0].min() + hull[:, 0].max()) / 2, hull[:, 1].min()])
        out = []
        for ring in (pf.part.outline.vertices, *pf.part.outline.holes):
            r = np.asarray(ring) @ rot.T - shift
            for p, q in zip(r, np.roll(r, -1, axis=0), strict=True):
                n = max(int(math.ceil(np.hypot(*(q - p)) / step)), 1)
                out.append(p + np.outer(np.arange(n) / n, q - p))
        return np.vstack(out)

    u, v = samples(a), samples(b)
    d = np.sqrt(((u[:, None, :] - v[None, :, :]) ** 2).sum(axis=2))
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


@pytest.mark.parametrize(
    ("hole_x", "notch", "alike"), [(32, False, False), (None, True, False), (20, False, True)]
)
def test_holes_and_notches_the_hull_does_not_show_set_poses_apart(hole_x, notch, alike):
    """The plate's two long-side poses have congruent hulls; an off-centre hole moves 24 mm
    along the fence between them and a corner notch moves to the other end, which the next
    station sees; a centred hole does not tell them apart."""
    pf = _plate(hole_x, notch)
    a, b = (s.id for s in pf.states if math.isclose(s.diameter, 20.0, abs_tol=1e-9))
    d = pose_difference(pf, a, b)
    brute = _brute_outline_distance(pf, a, b)
    assert brute - 0.02 <= d <= brute + NEAR_SYMMETRIC_REL * pf.part.size / 8  # a bound, close
    table = look_alike(pf, [[s.id] for s in pf.states])
    assert (b in table[a]) is alike and (a in table[b]) is alike
    assert (d <= NEAR_SYMMETRIC_REL * pf.part.size) is alike


def test_the_machine_records_which_states_look_alike():
    m = build_machine([near_rectangle()], NoSensor(), Uncertainty())
    assert all(s.look_alike is not None and len(s.look_alike) == 1 for s in m.states)
    assert build_machine([near_rectangle()], NoSensor(), IDEAL).states[0].look_alike is None
    cut = build_machine([chamfered()], NoSensor(), Uncertainty())
    assert all(s.look_alike == () for s in cut.states)


# --- the rule ------------------------------------------------------------------------------


def test_the_option_is_validated():
    assert PlanningOptions().lumping is Lumping.NEAR_SYMMETRIC
    assert PlanningOptions(lumping="any").lumping is Lumping.ANY
    with pytest.raises(InputError, match="near-symmetric, any, none"):
        PlanningOptions(lumping="some")
    with pytest.raises(InputError, match="lumping"):
        try_lumping(build_machine([chamfered()], NoSensor(), Uncertainty()), rule="some")


@pytest.mark.parametrize("sensor", [NoSensor(), ToleranceSensor(0.05)], ids=["none", "tol"])
def test_a_near_symmetric_part_still_plans_with_its_poses_listed_together(sensor):
    made = make_plan([near_rectangle()], sensor, certify=False)
    verify_strong(made.plan)
    assert made.result.lumped_pairs
    (words,) = (w for w in made.warnings if w.startswith("results list"))
    assert "not near-symmetric" not in words


@pytest.mark.parametrize("sensor", [NoSensor(), ToleranceSensor(0.05)], ids=["none", "tol"])
def test_unlike_poses_are_not_lumped_and_the_largest_rotation_error_is_named(sensor):
    pf = chamfered()
    m = build_machine([pf], sensor, Uncertainty())
    with pytest.raises(NoStrongPlan) as exc:
        plan(m)
    assert "cham state" in exc.value.hint and "lumping 'any'" in exc.value.hint
    with pytest.raises(PlanningError) as made:
        make_plan([pf], sensor, certify=False)
    text = str(made.value)
    assert "no strong plan exists" in text and "\n" not in text
    assert "only on the ideal model" in text or "largest rotation error" in text
    assert text.endswith("may exist with lumping 'any'")  # the hint comes last
    assert not strong_plan_exists(m)


@pytest.mark.parametrize("sensor", [NoSensor(), ToleranceSensor(0.05)], ids=["none", "tol"])
def test_lumping_any_plans_the_unlike_poses_and_warns(sensor):
    options = PlanningOptions(lumping="any")
    made = make_plan([chamfered()], sensor, options, certify=False)
    verify_strong(made.plan)
    assert made.result.lumped_pairs
    (words,) = (w for w in made.warnings if w.startswith("results list"))
    assert "not near-symmetric" in words and "the default lumping says which" in words
    assert "--" not in words  # library words, no command-line flag
    assert strong_plan_exists(made.result.machine, options)


def test_lumping_none_refuses_even_near_symmetric_poses():
    m = build_machine([near_rectangle()], NoSensor(), Uncertainty())
    options = PlanningOptions(lumping="none")
    with pytest.raises(NoStrongPlan) as exc:
        plan(m, options)
    assert exc.value.hint == ""
    assert not strong_plan_exists(m, options)
    assert strong_plan_exists(m)


def _two_parts(alike: bool | None) -> PushAlignMachine:
    """States 0 and 1 of one part (looking alike, or not, or None: not recorded) and state 0
    of another."""

    def look(other: int) -> tuple[int, ...] | None:
        return None if alike is None else (other,) if alike else ()

    states = (
        MachineState(0, 0, 1.0, 1 / 3, (1.0, 1.0), (0,), look_alike=look(1)),
        MachineState(0, 1, 1.0, 1 / 3, (1.0, 1.0), (1,), look_alike=look(0)),
        MachineState(1, 0, 1.0, 1 / 3, (1.0, 1.0), (0,), look_alike=None if alike is None else ()),
    )
    maps = tuple(
        (OutcomeRange(0.0, 180.0, 1 << i), OutcomeRange(180.0, 360.0, 0b111)) for i in range(3)
    )
    return PushAlignMachine(("p", "q"), states, maps, NoSensor())


def test_may_lump_reads_the_record_and_lets_parts_of_a_mix_through():
    alike, unlike, unrecorded = _two_parts(True), _two_parts(False), _two_parts(None)
    rule = Lumping.NEAR_SYMMETRIC
    assert may_lump(alike, 0, 1, rule) and not may_lump(unlike, 0, 1, rule)
    assert may_lump(unrecorded, 0, 1, rule)  # a machine built by hand records nothing
    assert all(may_lump(m, 0, 2, rule) for m in (alike, unlike))  # two parts: a mix's pair
    assert may_lump(unlike, 0, 1, Lumping.ANY) and not may_lump(alike, 0, 1, Lumping.NONE)
    tried = try_lumping(build_machine([chamfered()], NoSensor(), Uncertainty()))
    assert tried.goal is None and tried.decided
    assert tried.unlike == ((0, 2), (1, 3))  # each long side with the other, short with short


# --- strong_plan_exists agrees with plan -----------------------------------------------------


def hand_machine(seed: int) -> PushAlignMachine:
    """A random nondeterministic machine: n - 1 states of one part (those of equal parity
    look alike) and one of another, every state reading alike, most ranges with two
    outcomes (so strong plans often need lumping)."""
    rng = random.Random(seed)
    n = 3 + seed % 3
    parts = [0] * (n - 1) + [1]
    ids = [i if parts[i] == 0 else 0 for i in range(n)]
    states = tuple(
        MachineState(
            parts[i],
            ids[i],
            1.0,
            1.0 / n,
            (1.0, 1.0),
            (ids[i],),
            look_alike=tuple(
                ids[j]
                for j in range(n)
                if j != i and parts[j] == parts[i] and (ids[i] + ids[j]) % 2 == 0
            ),
        )
        for i in range(n)
    )
    maps = []
    for _ in range(n):
        cuts = sorted(rng.sample(range(1, 36), rng.randint(1, 4)))
        los = [0.0] + [10.0 * c for c in cuts]
        ranges = []
        for lo, hi in zip(los, los[1:] + [360.0], strict=True):
            t = 1 << rng.randrange(n)
            if rng.random() < 0.8:
                t |= 1 << rng.randrange(n)
            ranges.append(OutcomeRange(lo, hi, t))
        maps.append(tuple(ranges))
    return PushAlignMachine(("p", "q"), states, tuple(maps), NoSensor())


SEEDS = range(40)


def _planned(m: PushAlignMachine, rule: Lumping) -> str:
    """What ``plan`` makes of ``m``: "-" no strong plan, "L" a plan that lumps, "P" one
    that does not."""
    try:
        result = plan(m, PlanningOptions(lumping=rule))
    except NoStrongPlan:
        return "-"
    return "L" if result.lumped_pairs else "P"


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("rule", list(Lumping), ids=[r.value for r in Lumping])
def test_strong_plan_exists_agrees_with_plan(seed, rule):
    m = hand_machine(seed)
    options = PlanningOptions(lumping=rule)
    try:
        result = plan(m, options)
    except NoStrongPlan:
        assert not strong_plan_exists(m, options)
        return
    assert strong_plan_exists(m, options)
    for i, j in result.lumped_pairs:
        assert may_lump(m, i, j, rule)


def test_the_random_machines_tell_the_rules_apart():
    """The machines above meet every case: plans with no lumping, lumping that the default
    rule allows, and lumping only ``any`` allows (so the agreement test can fail)."""
    rules = (Lumping.NEAR_SYMMETRIC, Lumping.ANY, Lumping.NONE)
    seen = ["".join(_planned(hand_machine(s), r) for r in rules) for s in (0, 1, 15)]
    assert seen == ["PPP", "LL-", "-L-"]


@pytest.mark.parametrize(
    ("pf", "rule", "plans"),
    [
        (near_rectangle(), Lumping.NEAR_SYMMETRIC, True),
        (chamfered(), Lumping.NEAR_SYMMETRIC, False),
        (chamfered(), Lumping.ANY, True),
        (near_rectangle(), Lumping.NONE, False),
    ],
    ids=["near-rect", "chamfer", "chamfer-any", "near-rect-none"],
)
def test_strong_plan_exists_agrees_with_plan_on_parts(pf, rule, plans):
    m = build_machine([pf], ToleranceSensor(0.05), Uncertainty())
    options = PlanningOptions(lumping=rule)
    assert strong_plan_exists(m, options) is plans
    if plans:
        plan(m, options)
    else:
        with pytest.raises(NoStrongPlan):
            plan(m, options)


# --- the command line ----------------------------------------------------------------------


def test_the_command_line_refuses_unlike_poses_with_one_line_and_exit_1(tmp_path, capsys):
    cut = tmp_path / "cut.json"
    pts = [[0, 0], [5, 0], [5, 2.3], [4.8, 2.5], [0, 2.5]]
    cut.write_text(json.dumps({"name": "cut", "vertices": pts}))
    assert main(["plan", str(cut), "--sensorless", "--landings", "up"]) == 1
    *warnings, result = capsys.readouterr().err.strip().splitlines()
    assert result.startswith("result: no strong plan exists")
    # Only the face-down landing --landings leaves out is warned of, each warning one line.
    assert len(warnings) == 1 and warnings[0].startswith("warning: cut also lands down")


def test_the_command_line_plans_the_near_symmetric_part(tmp_path, capsys):
    """Exit 0, the poses listed together."""
    near = tmp_path / "near.json"
    near.write_text(json.dumps({"name": "near", "vertices": RECT, "com": [2.508, 1.25]}))
    assert main(["plan", str(near), "--sensorless", "--landings", "up"]) == 0
    err = capsys.readouterr().err
    assert "results list states together" in err and "not near-symmetric" not in err


# --- bisimilar poses that only behave alike --------------------------------------------------

CATALOG = Path(__file__).resolve().parent.parent / "catalog"


def _leaves(node) -> list[int]:
    """The masks of a plan tree's leaves (each shared subtree walked once)."""
    out, seen, todo = [], set(), [node]
    while todo:
        n = todo.pop()
        if id(n) in seen:
            continue
        seen.add(id(n))
        if isinstance(n, Leaf):
            out.append(n.mask)
        else:
            todo.extend(sub for _b, sub in n.branches)
    return out


def _ideal_classes(pf, sensor) -> dict[int, int]:
    """Each ideal stable state's indistinguishable set on the ideal model (a mask over the
    ideal machine's states, itself included): what the paper lets a result list."""
    ideal = build_machine([pf], sensor, IDEAL)
    masks = search_space(ideal).bisimilar
    return {s.state: masks[i] | 1 << i for i, s in enumerate(ideal.states)}


def _unlike_pairs_in_leaves(machine, pfs, leaves) -> list[tuple[int, int, float]]:
    """Pairs of one part's states some leaf lists together whose poses differ by more than
    ``NEAR_SYMMETRIC_REL`` of the part's size, by the exact pose difference (not the
    machine's record), and that the ideal model does not list together either (each ideal
    member of one indistinguishable from one of the other's)."""
    classes = {p: _ideal_classes(pf, machine.sensor) for p, pf in enumerate(pfs)}
    bad = []
    for mask in leaves:
        idx = [i for i in range(machine.n) if mask >> i & 1]
        for a, i in enumerate(idx):
            for j in idx[a + 1 :]:
                si, sj = machine.states[i], machine.states[j]
                if si.part != sj.part:
                    continue
                pf = pfs[si.part]
                d = poses_difference(pf, si.ideal_states, sj.ideal_states)
                if d <= NEAR_SYMMETRIC_REL * pf.part.size + 1e-9:
                    continue
                cls = classes[si.part]
                twins = all(
                    any(cls[a] >> b & 1 for b in sj.ideal_states) for a in si.ideal_states
                ) and all(any(cls[b] >> a & 1 for a in si.ideal_states) for b in sj.ideal_states)
                if not twins:
                    bad.append((i, j, d))
    return bad


def test_a_large_rotation_error_makes_unlike_poses_bisimilar_but_not_the_goal():
    """At 75 degrees every action can send each pose of an L anywhere: all four are
    bisimilar, and a leaf listing them would not orient the part."""
    pf = push_function(make_part(load_outline_json(CATALOG / "l-bracket.json")))
    m = build_machine([pf], NoSensor(), Uncertainty(75.0))
    space = search_space(m)
    assert all(b == m.all_states & ~(1 << i) for i, b in enumerate(space.bisimilar))
    assert not any(space.inseparable)
    with pytest.raises(NoStrongPlan) as exc:
        plan(m)
    assert "lumping 'any'" in exc.value.hint
    assert not strong_plan_exists(m)
    options = PlanningOptions(lumping="any")
    made = make_plan([pf], NoSensor(), options, uncertainty=Uncertainty(75.0), certify=False)
    assert any("not near-symmetric" in w for w in made.warnings)


@pytest.mark.parametrize(
    "name", ["l-bracket", "rectangle-2x1", "t-clip", "chamfered-plate", "heptagon-fig17"]
)
@pytest.mark.parametrize("error", [1.0, 40.0, 75.0])
@pytest.mark.parametrize("sensor", [NoSensor(), ToleranceSensor(0.2)], ids=["none", "tol"])
def test_no_plan_lists_unlike_poses_of_one_part_together(name, error, sensor):
    """Under the default rule every leaf's poses of one part look alike, whatever the
    rotation error: the plan orients the part up to its (near) symmetry, or none exists."""
    pf = push_function(make_part(load_outline_json(CATALOG / f"{name}.json")))
    m = build_machine([pf], sensor, Uncertainty(error))
    try:
        result = plan(m, PlanningOptions(time_limit_s=30.0))
    except NoStrongPlan:
        return
    assert _unlike_pairs_in_leaves(result.machine, [pf], _leaves(result.root)) == []


def test_a_large_shape_tolerance_does_not_list_unlike_poses_together():
    """2 mm on the 60 mm L with a 0.2 mm sensor: no strong plan, not a one-operation plan
    listing three poses."""
    pf = push_function(make_part(load_outline_json(CATALOG / "l-bracket.json")))
    m = build_machine([pf], ToleranceSensor(0.2), Uncertainty(1.0, shape_tolerance_mm=2.0))
    try:
        result = plan(m, PlanningOptions(time_limit_s=30.0))
    except NoStrongPlan:
        return
    assert _unlike_pairs_in_leaves(result.machine, [pf], _leaves(result.root)) == []


@pytest.mark.parametrize("error", [0.0, 1.0, 75.0])
def test_the_papers_heptagon_lists_its_three_poses_under_any_rotation_error(error):
    """Fig. 17's heptagon without a sensor: three poses that no push tells apart even on the
    ideal model (one push function); the result lists them (the paper's answer) at any
    rotation error. With a sensor their diameters tell them apart at once."""
    pf = push_function(make_part(load_outline_json(CATALOG / "heptagon-fig17.json")))
    model = IDEAL if error == 0.0 else Uncertainty(error)
    blind = plan(build_machine([pf], NoSensor(), model))
    assert blind.length == 1 and _leaves(blind.root) == [0b111]
    read = plan(build_machine([pf], ToleranceSensor(0.0091), model))
    assert read.length == 1 and sorted(_leaves(read.root)) == [0b1, 0b10, 0b100]


def test_a_symmetric_part_still_lists_its_symmetric_poses_at_a_large_rotation_error():
    """A 2 x 1 rectangle at 75 degrees: the reading tells a long side from a short one, and
    each leaf lists a side's two symmetric poses. The catalog's rectangle has its COM at
    (0.8, 0.4), 0.22 mm off the centre (11 % of its size): its poses on one side differ by
    0.45 mm there, so they do not look alike, and no strong plan exists."""
    catalog = make_part(load_outline_json(CATALOG / "rectangle-2x1.json"))
    pf = push_function(make_part(catalog.outline, (1.0, 0.5)))
    result = plan(build_machine([pf], ToleranceSensor(0.2), Uncertainty(75.0)))
    leaves = _leaves(result.root)
    assert sorted(mask.bit_count() for mask in leaves) == [2, 2]
    with pytest.raises(NoStrongPlan):  # without the reading nothing tells the sides apart
        plan(build_machine([pf], NoSensor(), Uncertainty(75.0)))
    with pytest.raises(NoStrongPlan, match="do not look alike"):
        plan(build_machine([push_function(catalog)], ToleranceSensor(0.2), Uncertainty(75.0)))


def test_the_command_line_refuses_a_rotation_error_that_makes_every_pose_alike(capsys):
    """Not a one-operation "plan" listing every pose of the L: no strong plan, exit 1."""
    src = str(CATALOG / "l-bracket.json")
    assert main(["plan", src, "--landings", "up", "--rotation-error", "75"]) == 1
    err = capsys.readouterr().err
    assert "result: no strong plan exists" in err and "largest rotation error" in err


def test_the_alike_record_does_not_depend_on_the_sensor():
    """The sensor design builds its machine once and swaps sensors: the record (and so the
    goal) must be the one a machine built with each sensor has. A finer sensor then never
    loses the plan a coarser one has (the heptagon at a 0.02 mm shape tolerance)."""
    from dataclasses import replace

    pf = push_function(make_part(load_outline_json(CATALOG / "heptagon-fig17.json")))
    model = Uncertainty(1.0, shape_tolerance_mm=0.02)
    blind = build_machine([pf], NoSensor(), model)
    for tol in (0.01, 0.06):
        built = build_machine([pf], ToleranceSensor(tol), model)
        assert [s.look_alike for s in built.states] == [s.look_alike for s in blind.states]
        swapped = replace(blind, sensor=ToleranceSensor(tol))
        assert search_space(swapped).inseparable == search_space(built).inseparable
        assert plan(built).length == 1
