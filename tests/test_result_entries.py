"""A result names only what ends there (docs/plans.md, "Result entries"): ``make_plan`` prunes
each result of the file to the (member, state) pairs some start, outcome or reading ends in,
and both verifiers refuse an entry of a part or landing none of whose states ends at a result
something else ends in, wherever a plan is loaded (``verify_declared``: ``run``, ``report``,
``simulate``)."""

from __future__ import annotations

import copy
import json
import random

import pytest
from fixtures_cad import d_shape_outline
from shared import run_cli, small_mix

from feederkit.design.critical import mix_critical_tolerance
from feederkit.errors import CheckFailed
from feederkit.mechanics.push import push, push_function, rotation_after
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.tree import leaf_masks
from feederkit.plans import plan_json
from feederkit.plans.fileformat import result_nodes
from feederkit.plans.make import make_plan
from feederkit.plans.model import PlanMember
from feederkit.plans.verify import check_declared, verify_declared
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

UP = [(0.0, 0.0), (4.0, 0.0), (0.0, 3.0)]
DOWN = [(-x, y) for x, y in UP]  # mirrored about the part frame's y axis


def _tri_pfs():
    return [
        push_function(make_part(make_outline(f"tri/{side}", pts)))
        for side, pts in (("up", UP), ("down", DOWN))
    ]


def _d_and_rect():
    """A D-shaped plate whose hull simplifies its arc and a rectangle as wide as the arc."""
    d = push_function(make_part(d_shape_outline(), hull_tolerance=0.05))
    rect = make_outline("rect", [(0.0, 0.0), (40.0, 0.0), (40.0, 20.0), (0.0, 20.0)])
    return [d, push_function(make_part(rect))]


def _entries(node):
    return {(e["part"], e.get("landing"), e["state"]) for e in node["result"]}


def _foreign(data):
    """A copy of ``data`` with one result given an entry of a member none of whose states
    ends there (a member the result does not name at all), and that entry."""
    out = copy.deepcopy(data)
    members = [(p["name"], p.get("landing")) for p in out["parts"]]
    for node in result_nodes(out):
        named = {(e["part"], e.get("landing")) for e in node["result"]}
        other = next((m for m in members if m not in named), None)
        if other is not None and not node.get("reject"):
            entry = {"part": other[0]}
            if other[1] is not None:
                entry["landing"] = other[1]
            part = next(p for p in out["parts"] if (p["name"], p.get("landing")) == other)
            state = part["stable_states"][0]
            entry.update(state=state["id"], pose_deg=state["pose_deg"])
            node["result"].append(entry)
            return out, entry
    raise AssertionError("every result names every member")


@pytest.fixture(scope="module")
def mix_plan():
    """An ideal plan of three parts read within 3 mm."""
    return make_plan(small_mix(3, 7), ToleranceSensor(3.0), uncertainty=IDEAL, certify=False).plan


@pytest.fixture(scope="module")
def strong_mix_plan():
    """The same at the default uncertainty (a strong plan)."""
    return make_plan(small_mix(3, 7), ToleranceSensor(3.0), certify=False).plan


@pytest.fixture(scope="module")
def landing_plan():
    """An ideal plan over both landings of a triangle, both accepted."""
    members = (PlanMember("tri", "up", 0.5), PlanMember("tri", "down", 0.5))
    pfs = _tri_pfs()
    return make_plan(pfs, ToleranceSensor(0.1), uncertainty=IDEAL, members=members).plan


@pytest.mark.parametrize("kind", ["mix_plan", "strong_mix_plan", "landing_plan"])
def test_an_entry_of_a_member_that_never_ends_there_is_refused(kind, request):
    data = request.getfixturevalue(kind)
    assert verify_declared(data).ok
    bad, entry = _foreign(data)
    problem = verify_declared(bad).first_problem()
    label = entry["part"] if "landing" not in entry else f"{entry['part']} ({entry['landing']})"
    assert problem is not None
    assert f"a result lists {label} state {entry['state']}" in problem
    assert f"no start, outcome or reading of {label} ends there" in problem
    assert "a plan written by an earlier feederkit may list it: make the plan again" in problem


def test_every_loader_refuses_a_hand_added_entry(mix_plan, tmp_path, capsys):
    bad, entry = _foreign(mix_plan)
    path = tmp_path / "bad.plan.json"
    path.write_text(plan_json(bad))
    words = f"no start, outcome or reading of {entry['part']} ends there"
    for args in (
        ["run", str(path), "--all"],
        ["report", str(path), "-o", str(tmp_path / "r.html")],
        ["simulate", str(path), "--trials", "5", "--ideal"],
    ):
        code, _out, err = run_cli(capsys, *args)
        assert code == 1 and words in err, (args, code, err)
    good = tmp_path / "good.plan.json"
    good.write_text(plan_json(mix_plan))
    assert run_cli(capsys, "run", str(good), "--all")[0] == 0
    with pytest.raises(CheckFailed, match=words):
        check_declared(bad)


def test_a_hand_added_landing_is_refused_in_a_plan_over_landings(landing_plan):
    bad, entry = _foreign(landing_plan)
    assert entry["part"] == "tri" and entry["landing"] in ("up", "down")
    assert "of tri (" in verify_declared(bad).first_problem()


@pytest.mark.parametrize("unc", [IDEAL, Uncertainty()], ids=["ideal", "strong"])
def test_a_design_at_a_critical_tolerance_is_pruned_to_what_ends_there(unc):
    # Just past the critical tolerance a reading set follows a larger set's subplan, whose
    # result also names a D-shape state no path of it ends in: pruned, the plan passes the
    # strict check (unpruned it did not).
    pfs = _d_and_rect()
    x = mix_critical_tolerance(pfs).pairs[0].critical_tolerance
    made = make_plan(pfs, ToleranceSensor(x * (1 + 1e-6)), uncertainty=unc, certify=False)
    assert verify_declared(made.plan).ok
    assert all(node["result"] for node in result_nodes(made.plan))
    # the planner's masks say what the file's results say (the warnings read them)
    machine = made.result.machine
    # every result entry names its landing: "up" in a plan not made over landings
    names = [(p["name"], p.get("landing", "up")) for p in made.plan["parts"]]
    masks = {
        frozenset(
            (*names[machine.states[i].part], m)
            for i in range(machine.n)
            if mask >> i & 1
            for m in machine.states[i].ideal_states
        )
        for mask in leaf_masks(made.result.root)
    }
    assert masks == {frozenset(_entries(node)) for node in result_nodes(made.plan)}
    if unc.is_ideal:  # each result lists exactly what a brute-force follow ends in there
        ended: dict[int, set] = {}
        for p, pf in enumerate(pfs):
            for leaf, state in _follow(made.plan, p, pf, x * (1 + 1e-6)):
                ended.setdefault(leaf, set()).add((pf.part.name, "up", state))
        for node in result_nodes(made.plan):
            assert _entries(node) == ended[id(node)]


@pytest.mark.parametrize(
    "sensor, unc",
    [
        (ToleranceSensor(0.5), IDEAL),
        (ToleranceSensor(0.5), Uncertainty()),
        (ToleranceSensor(0.003), IDEAL),  # a branch only the D-shape's own widths lead to
        (ToleranceSensor(0.003), Uncertainty()),
    ],
)
def test_the_planners_own_plans_pass_the_strict_check(sensor, unc):
    made = make_plan(_d_and_rect(), sensor, uncertainty=unc)
    assert verify_declared(made.plan).ok, verify_declared(made.plan).first_problem()


def test_a_single_parts_plan_passes_and_a_foreign_state_is_refused():
    pf = push_function(make_part(make_outline("tri", UP)))
    made = make_plan([pf], ToleranceSensor(0.1), uncertainty=IDEAL)
    assert verify_declared(made.plan).ok
    # a state the part never ends in at a result, unlike every state that does
    bad = copy.deepcopy(made.plan)
    node = next(n for n in result_nodes(bad) if len(n["result"]) == 1)
    other = next(
        s for s in bad["parts"][0]["stable_states"] if s["id"] != node["result"][0]["state"]
    )
    node["result"].append({"part": "tri", "state": other["id"], "pose_deg": other["pose_deg"]})
    assert "looks like none that does" in verify_declared(bad).first_problem()


# --- pruning never drops what ends there: a brute-force follow of the plan ----------------------

GRID = 64
"""Rotations tried across each overlap range and readings across each reading interval."""


def _follow(data, p, pf, tolerance):
    """The (result id, state) pairs part ``p`` ends in, found by trying each start, ``GRID``
    rotations across each margin and ``GRID`` readings across each reading interval, with
    the plain push function (no interval arithmetic: independent of the verifier)."""
    shared = data.get("nodes") or {}
    out, seen = set(), set()
    stack = [(data["root"], s) for s in pf.states]
    while stack:
        node, state = stack.pop()
        while "ref" in node:
            node = shared[node["ref"]]
        if (id(node), state.id) in seen:
            continue
        seen.add((id(node), state.id))
        if "result" in node:
            out.add((id(node), state.id))
            continue
        lo, hi = state.diameter - tolerance, state.diameter + tolerance
        readings = [lo + (hi - lo) * (k + 0.5) / GRID for k in range(GRID)]
        ends = {x for b in node["branches"] for x in b["reading"] if lo < x < hi}
        readings += [*ends, *(x - 1e-9 for x in ends), *(x + 1e-9 for x in ends)]
        for b in node["branches"]:
            nxt = b["next"]
            if not any(b["reading"][0] <= r <= b["reading"][1] for r in readings):
                continue
            while "ref" in nxt:
                nxt = shared[nxt["ref"]]
            if "result" in nxt:
                stack.append((nxt, state))
                continue
            a, m = nxt["action_deg"], nxt["margin_deg"]
            for k in range(GRID):
                turn = a - m + 2.0 * m * (k + 0.5) / GRID
                stack.append((nxt, push(pf, rotation_after(state.normal_deg, turn))))
    return out


@pytest.mark.parametrize("seed", range(6))
def test_pruning_keeps_every_state_a_brute_force_follow_ends_in(seed):
    rng = random.Random(seed)
    pfs = small_mix(rng.randint(2, 4), 200 + 10 * seed)
    tolerance = rng.choice([0.5, 1.0, 2.0, 4.0])
    made = make_plan(pfs, ToleranceSensor(tolerance), uncertainty=IDEAL, certify=False)
    data = json.loads(plan_json(made.plan))  # as a controller reads it
    nodes = {id(n): n for n in result_nodes(data)}
    for p, pf in enumerate(pfs):
        name = data["parts"][p]["name"]
        for leaf, state in _follow(data, p, pf, tolerance):
            assert (name, "up", state) in _entries(nodes[leaf]), (name, state)
    assert verify_declared(data).ok


@pytest.mark.parametrize("unc", [IDEAL, Uncertainty()], ids=["ideal", "strong"])
def test_the_report_made_with_a_plan_counts_what_its_file_ends_in(unc):
    """The verifiers count the runs that end at a result naming several members before they
    prune; the report returned with the plan is the written file's (it said 73 where the
    file's own check says 71: pruning leaves some results naming one member)."""
    pfs = _d_and_rect()
    x = mix_critical_tolerance(pfs).pairs[0].critical_tolerance
    made = make_plan(pfs, ToleranceSensor(x * (1 + 1e-6)), uncertainty=unc, certify=False)
    again = verify_declared(made.plan)
    assert made.report.unrecognized == again.unrecognized > 0
    assert [c.unrecognized for c in made.report.parts] == [c.unrecognized for c in again.parts]
