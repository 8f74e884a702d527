"""Physical resting states under a shape tolerance (docs/uncertainty.md, the merge rule): two
states are one only where a part at rest anywhere in one may cross to the other; a result
holding unlike poses a part may wander between is not an oriented part."""

from __future__ import annotations

import pytest
from shapely.geometry import Polygon

from feederkit.machine import build_machine, members
from feederkit.machine.build import unlike_members
from feederkit.mechanics import push_function
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan, strong_plan_exists
from feederkit.planning.options import Lumping, PlanningOptions
from feederkit.planning.solvable import NoStrongPlan
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import Uncertainty


def filleted_bracket(quad_segs: int = 16):
    """A 60 x 40 mm L-bracket with R3 fillets on its convex corners (arcs as short chords)."""
    ell = Polygon([(0, 0), (60, 0), (60, 15), (15, 15), (15, 40), (0, 40)])
    rounded = ell.buffer(-3, quad_segs=quad_segs).buffer(3, quad_segs=quad_segs)
    return make_part(make_outline("lbf", list(rounded.exterior.coords)[:-1]))


def quadrilateral():
    pts = [(0.0, 0.0), (2.0, 0.0), (2.4, 1.6), (0.3, 2.0)]
    return make_part(make_outline("quad", pts))


@pytest.mark.parametrize("quad_segs", [8, 16, 32])
@pytest.mark.parametrize("t", [0.03, 0.05])
def test_fillet_chords_near_a_hilltop_do_not_merge_deep_wells(quad_segs, t):
    # The fillets' short chords may tilt by asin(2t / chord) and rest near each hilltop, so a
    # push ending there may end beyond it; the wells themselves (barriers of 2-15 mm) hold.
    part = filleted_bracket(quad_segs)
    mech = uncertain_mechanics(part, Uncertainty(1.0, t, 0.0))
    assert all(len(s.members) == 1 for s in mech.states)
    assert len(mech.states) == push_function(part).n
    # ... and the neighbours beyond those hilltops are among the outcomes (conservative).
    assert any(len(d) > 1 for d in mech.destinations)


def test_the_filleted_bracket_gets_no_plan_listing_unlike_poses():
    pf = push_function(filleted_bracket())
    m = build_machine([pf], ToleranceSensor(0.1), Uncertainty(1.0, 0.03, 0.0))
    try:
        result = plan(m)
    except NoStrongPlan:
        return
    for node in _leaves(result.root):
        assert len(node) == 1 or all(m.states[i].alike(m.states[j]) for i in node for j in node)


def _leaves(root):
    from feederkit.machine import members
    from feederkit.planning.tree import Leaf

    todo, out = [root], []
    while todo:
        node = todo.pop()
        if isinstance(node, Leaf):
            out.append(members(node.mask))
        else:
            todo.extend(child for _b, child in node.branches)
    return out


def test_a_small_part_whose_wells_all_wander_is_not_oriented():
    # 2 mm across, t = 0.1 and c = 0.2 mm: every barrier lies below 2 (t + c) plus the
    # vibration, so the part at rest may wander between four unlike poses.
    pf = push_function(quadrilateral())
    unc = Uncertainty(1.0, 0.1, 0.2)
    mech = uncertain_mechanics(pf.part, unc)
    assert [len(s.members) for s in mech.states] == [pf.n]
    assert unlike_members(pf, mech) == {0}
    m = build_machine([pf], NoSensor(), unc)
    assert m.states[0].unlike_members
    with pytest.raises(NoStrongPlan, match="wanders between unlike poses"):
        plan(m)
    with pytest.raises(NoStrongPlan, match="no result may hold a state where the part at rest"):
        plan(m, PlanningOptions(lumping=Lumping.NONE))
    assert not strong_plan_exists(m)
    # The catalog screen and the sensor design answer as plan does.
    from feederkit.design.strong import StrongLengthOracle, StrongMix
    from feederkit.mix.strongpairs import check_alone

    assert not check_alone(pf, NoSensor(), unc).orients
    assert StrongLengthOracle(StrongMix([pf], unc)).length(0.05) is None
    lumped = plan(m, PlanningOptions(lumping=Lumping.ANY))
    assert lumped.length == 1
    assert strong_plan_exists(m, PlanningOptions(lumping=Lumping.ANY))


def fan(span_deg: float = 100.0):
    """A fan: a 20 mm arc of ``span_deg`` centred on the COM (one chord per 2 degrees), closed
    by two flat sides. The part at rest may wander along the arc (its wells are flat)."""
    import math

    a0 = -90.0 - span_deg / 2.0
    n = int(span_deg / 2)
    arc = [
        (
            20 * math.cos(math.radians(a0 + span_deg * k / n)),
            20 * math.sin(math.radians(a0 + span_deg * k / n)),
        )
        for k in range(n + 1)
    ]
    return make_part(
        make_outline(f"fan{span_deg:g}", [*arc, (22.0, 12.0), (-10.0, 16.0)], com=(0, 0))
    )


def _shortest_avoiding(m, wandering: int, cap: int = 6) -> int | None:
    """Brute force: the fewest operations (first alignment counted) of a strong plan whose
    results hold no state of ``wandering`` (a mask), every overlap range, exact readings."""
    from feederkit.machine import branches, is_goal, overlap_ranges, search_space

    insep = search_space(m).inseparable
    memo: dict[tuple[int, int], bool] = {}

    def within(mask: int, k: int) -> bool:
        if not mask & wandering and is_goal(insep, mask):
            return True
        if k == 0:
            return False
        if (mask, k) not in memo:
            memo[(mask, k)] = any(
                all(within(b.mask, k - 1) for b in branches(m, a.image))
                for a in overlap_ranges(m, mask)
            )
        return memo[(mask, k)]

    worst = 0
    for b in branches(m, m.all_states):
        k = next((k for k in range(cap + 1) if within(b.mask, k)), None)
        if k is None:
            return None
        worst = max(worst, k)
    return 1 + worst


def test_a_plan_passes_through_a_wandering_state_and_ends_elsewhere():
    # The fan's arc is one physical state over unlike poses: no result may hold it, yet a
    # push sends a part resting there onto a flat side. The planner used to refuse the plan
    # it found (its result held the arc); it now finds the shortest that avoids it.
    m = build_machine([push_function(fan())], ToleranceSensor(0.5), Uncertainty())
    wandering = sum(1 << i for i, s in enumerate(m.states) if s.unlike_members)
    assert wandering
    result = plan(m)
    assert result.length == _shortest_avoiding(m, wandering) == 3
    assert all(not (set(leaf) & set(members(wandering))) for leaf in _leaves(result.root))
    assert strong_plan_exists(m)
    # Lumping 'any' may still end on the arc; the plan file of the default is verified.
    from feederkit.plans.make import make_plan

    made = make_plan([push_function(fan())], ToleranceSensor(0.5), certify=False)
    assert made.report.ok and made.plan["stats"]["length"] == 3 and made.unoriented is None


def test_merged_poses_that_look_alike_are_an_oriented_part():
    # A regular octagon 1.8 mm across at t = 0.01, c = 0.02: its eight states are one (the
    # barriers of about 0.07 mm wander), and its poses are congruent: a result may list them.
    import math

    pts = [(0.9 * math.cos(math.pi * k / 4), 0.9 * math.sin(math.pi * k / 4)) for k in range(8)]
    pf = push_function(make_part(make_outline("oct", pts)))
    unc = Uncertainty(1.0, 0.01, 0.02)
    mech = uncertain_mechanics(pf.part, unc)
    assert len(mech.states) == 1 and unlike_members(pf, mech) == set()
    assert plan(build_machine([pf], NoSensor(), unc)).length == 1


def test_a_result_on_a_merged_arc_names_the_spread_it_leaves():
    import math
    from pathlib import Path

    from feederkit.outline import load_outline_json
    from feederkit.plans.make import make_plan

    catalog = Path(__file__).resolve().parents[1] / "catalog"
    washer = push_function(make_part(load_outline_json(catalog / "d-washer.json")))
    made = make_plan([washer], NoSensor(), certify=False)
    (words,) = [w for w in made.warnings if "several stable states" in w]
    assert "d-washer states 1, 2, 3, 4, 5, 6, 7, 8 over 28 degrees" in words
    # Congruent merged poses (a small regular octagon under tolerances) are oriented: no word.
    pts = [(0.9 * math.cos(math.pi * k / 4), 0.9 * math.sin(math.pi * k / 4)) for k in range(8)]
    octagon = push_function(make_part(make_outline("oct", pts)))
    made = make_plan([octagon], NoSensor(), uncertainty=Uncertainty(1.0, 0.01, 0.02), certify=False)
    assert not [w for w in made.warnings if "several stable states" in w]


def test_no_plan_under_a_shape_tolerance_names_a_finely_drawn_arc():
    from feederkit.errors import PlanningError
    from feederkit.plans.advice import short_chords_words
    from feederkit.plans.make import make_plan

    box = Polygon([(0, 0), (40, 0), (40, 25), (0, 25)])
    rounded = box.buffer(-2, quad_segs=16).buffer(2, quad_segs=16)
    pf = push_function(make_part(make_outline("rr", list(rounded.exterior.coords)[:-1])))
    with pytest.raises(PlanningError, match=r"edges as short as 0\.196 mm .* tilt by 17\.8"):
        make_plan([pf], ToleranceSensor(0.1), uncertainty=Uncertainty(1.0, 0.03, 0.0))
    assert short_chords_words([pf], 0.0) == ""
    assert short_chords_words([pf], 0.0005) == ""  # 0.3 degrees: not named


def test_the_goal_relation_stays_the_machines_own_when_a_state_gets_a_twin():
    # X and Y look alike; both may be pushed into the wandering state w, which merges them
    # there, and from w on into Z1 or Z2. On the machine X and Y are not inseparable; a twin
    # of w (a copy nature could keep apart from w) must not make them so: a result listing
    # X and Y would claim no plan tells them apart.
    from feederkit.machine import MachineState, OutcomeRange, PushAlignMachine, search_space
    from feederkit.planning.tree import leaf_masks

    def state(s, d, alike, **kw):
        return MachineState(0, s, d, 0.2, members=(s,), look_alike=alike, **kw)

    states = (
        state(0, 10.0, (1,)),
        state(1, 10.0, (0,)),
        MachineState(0, 2, 20.0, 0.2, members=(2, 5), look_alike=(), unlike_members=True),
        state(3, 20.0, (4,)),
        state(4, 20.0, (3,)),
    )
    maps = (
        (OutcomeRange(0.0, 180.0, 0b00100), OutcomeRange(180.0, 360.0, 0b01000)),
        (OutcomeRange(0.0, 180.0, 0b00100), OutcomeRange(180.0, 360.0, 0b10000)),
        (OutcomeRange(0.0, 360.0, 0b11000),),
        (OutcomeRange(0.0, 360.0, 0b01000),),
        (OutcomeRange(0.0, 360.0, 0b10000),),
    )
    m = PushAlignMachine(("toy",), states, maps, ToleranceSensor(0.5), Uncertainty(1.0))
    goal = search_space(m).inseparable
    result = plan(m)
    for mask in leaf_masks(result.root):
        idx = members(mask)
        assert 2 not in idx
        assert all(goal[i] >> j & 1 for i in idx for j in idx if i != j), idx
    assert strong_plan_exists(m)
