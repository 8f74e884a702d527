"""Plans across landings (docs/landings.md): shares, reject leaves, the plan command.

Every landing of a part (face up and face down, a mesh's resting poses) is one member of a
mix (section 8 of the paper) with its prior share; landings the next station cannot take end
in reject leaves as soon as the plan knows.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import pytest
import trimesh
from shared import made_as_drawn, one_line_error

from feederkit.angles import ActionRange
from feederkit.cli.app import main
from feederkit.errors import InputError, PlanningError
from feederkit.landing import landings_of_outline
from feederkit.landing.mesh import landings_of_mesh
from feederkit.landing.plan import landing_members, load_landings, plan_landings
from feederkit.machine import MachineState, PushAlignMachine, build_machine, search_space
from feederkit.machine.weights import normalised_shares, weigh_members
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.stats import expected_operations
from feederkit.planning.tree import Leaf as TreeLeaf
from feederkit.plans.make import make_plan
from feederkit.plans.model import PlanMember
from feederkit.plans.readplan import plan_from_dict
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL

ELL_RING = [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)]
ELL_HOLE = [(30, 3), (34, 3), (34, 7), (30, 7)]


def ell():
    """An L with unequal legs (40 and 25) and an off-centre hole: a chiral part."""
    return make_part(make_outline("ell", ELL_RING, [ELL_HOLE]))


def write_outline(tmp_path, name, vertices, holes=()):
    data = {"name": name, "units": "mm", "vertices": vertices, "holes": list(holes)}
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(data))
    return str(path)


@pytest.fixture(scope="module")
def box_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("box") / "box.stl"
    trimesh.creation.box((10.0, 20.0, 30.0)).export(path)
    return path


@pytest.fixture(scope="module")
def box_landings(box_path):
    return landings_of_mesh(box_path, name="box")


def leaves(plan: dict) -> list:
    return plan_from_dict(plan).leaves()


# ---------------------------------------------------------------- the machine


def test_shares_rescale_each_members_weights_and_keep_their_proportions():
    pfs = [push_function(x.part) for x in landings_of_outline(ell())]
    machine = build_machine(pfs, ToleranceSensor(0.5), IDEAL)
    weighted = weigh_members(machine, [3.0, 1.0])
    for p, share in ((0, 0.75), (1, 0.25)):
        before = [s.weight for s in machine.states if s.part == p]
        after = [s.weight for s in weighted.states if s.part == p]
        assert math.fsum(after) == pytest.approx(share, abs=1e-12)
        assert [a / sum(after) for a in after] == pytest.approx([b / sum(before) for b in before])
    assert weigh_members(machine) is machine
    assert normalised_shares([0.25, 0.75], 2) == (0.25, 0.75)
    for bad in ([1.0], [0.0, 1.0], [float("nan"), 1.0], [True, 1.0]):
        with pytest.raises(InputError):
            normalised_shares(bad, 2)
    with pytest.raises(InputError, match="no member 2"):
        weigh_members(machine, rejected={2})


def test_a_set_of_rejected_states_only_is_a_goal_and_nothing_else_changes():
    # Two toy members whose states read alike: a set of both members' states is no goal,
    # but once the second member is rejected its states alone are one (a reject leaf).
    states = tuple(MachineState(p, s, 1.0 + s, 0.25) for p in (0, 1) for s in (0, 1))
    maps = tuple((ActionRange(0.0, 360.0, i),) for i in range(4))
    machine = PushAlignMachine(("a", "b"), states, maps, ToleranceSensor(0.1))
    rejected = weigh_members(machine, rejected={1})
    plain, goal = search_space(machine), search_space(rejected)
    assert goal.rejected == 0b1100
    assert goal.bisimilar == plain.bisimilar
    assert not plain.is_goal(0b1100) and goal.is_goal(0b1100)
    assert not goal.is_goal(0b0011) and not goal.is_goal(0b0110)


# ---------------------------------------------------------------- flat parts


def test_chiral_part_has_two_landings_told_apart_and_the_plan_names_the_side():
    landings = landings_of_outline(ell(), 0.7)
    assert [x.name for x in landings] == ["up", "down"]
    planned = plan_landings(landings, ToleranceSensor(0.5), uncertainty=IDEAL)
    assert planned.indistinguishable == ()
    plan = planned.made.plan
    assert [(p["name"], p["landing"]) for p in plan["parts"]] == [("ell", "up"), ("ell", "down")]
    assert [p["share"] for p in plan["parts"]] == pytest.approx([0.7, 0.3])
    seen = set()
    for leaf in planned.leaves():
        assert not leaf.reject
        assert len({r.landing for r in leaf}) == 1  # each result names one side
        seen |= {r.landing for r in leaf}
    assert seen == {"up", "down"}
    assert planned.made.report.ok


def test_mirror_symmetric_part_has_one_landing_and_plans_as_before(tmp_path):
    bar = make_part(make_outline("bar", [(0, 0), (30, 0), (30, 10), (0, 10)]))
    (only,) = landings_of_outline(bar)
    assert (only.name, only.probability, only.merged) == ("up", 1.0, ("down",))
    plain = make_plan([push_function(bar)], ToleranceSensor(0.5), uncertainty=IDEAL)
    same = make_plan(
        [push_function(bar)],
        ToleranceSensor(0.5),
        uncertainty=IDEAL,
        members=[PlanMember("bar")],
    )
    assert same.plan == plain.plan  # members that change nothing write today's file
    assert made_as_drawn(plain.plan)


def test_rejected_landing_never_reaches_an_accept_leaf_and_costs_no_extra_length():
    landings = landings_of_outline(ell())
    for unc in (IDEAL, None):
        every = plan_landings(landings, ToleranceSensor(0.5), uncertainty=unc)
        planned = plan_landings(landings, ToleranceSensor(0.5), uncertainty=unc, accept={"up"})
        assert planned.made.report.ok
        assert planned.made.plan["stats"]["length"] <= every.made.plan["stats"]["length"]
        kinds = {(r.landing, leaf.reject) for leaf in planned.leaves() for r in leaf}
        assert kinds == {("up", False), ("down", True)}
        # As early as the plan can know: no operation follows a set of rejected states only.
        result = planned.made.result
        rejected = search_space(result.machine).rejected
        stack = [result.root]
        while stack:
            node = stack.pop()
            for b, sub in node.branches:
                if not isinstance(sub, TreeLeaf):
                    assert b.mask & ~rejected, "an operation spent on a part to be rejected"
                    stack.append(sub)


def test_accepting_one_of_two_landings_no_plan_tells_apart_is_refused():
    with pytest.raises(PlanningError, match=r"ell \(up\) is accepted and ell \(down\) rejected"):
        plan_landings(landings_of_outline(ell()), NoSensor(), uncertainty=IDEAL, accept={"up"})
    with pytest.raises(InputError, match="no landing pose-3 to accept"):
        plan_landings(landings_of_outline(ell()), ToleranceSensor(0.5), accept={"pose-3"})
    pfs = [push_function(x.part) for x in landings_of_outline(ell())]
    nobody = [PlanMember("ell", "up", accept=False), PlanMember("ell", "down", accept=False)]
    with pytest.raises(InputError, match="every member is rejected"):
        make_plan(pfs, ToleranceSensor(0.5), uncertainty=IDEAL, members=nobody)
    with pytest.raises(InputError, match="ell \\(up\\) is a member twice"):
        make_plan(pfs, ToleranceSensor(0.5), members=[PlanMember("ell", "up")] * 2)


def test_members_split_each_parts_share_by_its_landing_probabilities():
    a = landings_of_outline(ell(), 0.8)
    b = landings_of_outline(make_part(make_outline("bar", [(0, 0), (30, 0), (30, 10), (0, 10)])))
    members = landing_members([*a, *b], accept={"up", "down"})
    assert [(m.name, m.landing, m.accept) for m in members] == [
        ("ell", "up", True),
        ("ell", "down", True),
        ("bar", "up", True),
    ]
    assert [m.share for m in members] == pytest.approx([0.4, 0.1, 0.5])
    # "down" of the symmetric bar is its one landing "up": accepting down accepts it.
    assert [m.accept for m in landing_members(b, accept={"down"})] == [True]
    weighted = landing_members([*a, *b], part_shares=[3.0, 1.0])
    assert [m.share for m in weighted] == pytest.approx([0.6, 0.15, 0.25])


def test_weights_alone_are_a_mixs_part_shares():
    bar = make_part(make_outline("bar", [(0, 0), (30, 0), (30, 10), (0, 10)]))
    tri = make_part(make_outline("tri", [(0, 0), (30, 0), (0, 20)]))
    pfs = [push_function(bar), push_function(tri)]
    made = make_plan(pfs, ToleranceSensor(0.5), uncertainty=IDEAL, weights=[1.0, 3.0])
    assert [(p["name"], p.get("landing"), p["share"]) for p in made.plan["parts"]] == [
        ("bar", None, 0.25),
        ("tri", None, 0.75),
    ]
    weight = [
        math.fsum(s.weight for s in made.result.machine.states if s.part == p) for p in (0, 1)
    ]
    assert weight == pytest.approx([0.25, 0.75], abs=1e-12)


# ---------------------------------------------------------------- meshes


def alone_expected(made, members):
    """Each member's expected operations on the plan's tree, from its own states alone."""
    machine, root = made.result.machine, made.result.root
    out = []
    for p in range(members):
        total = sum(s.weight for s in machine.states if s.part == p)
        states = tuple(
            replace(s, weight=s.weight / total if s.part == p else 0.0) for s in machine.states
        )
        out.append(expected_operations(replace(machine, states=states), root))
    return out


def test_box_poses_are_told_apart_and_the_expected_length_uses_their_probabilities(
    box_landings,
):
    planned = plan_landings(box_landings, ToleranceSensor(0.5), uncertainty=IDEAL)
    assert planned.indistinguishable == ()
    for leaf in planned.leaves():
        assert len({r.landing for r in leaf}) == 1
    plan = planned.made.plan
    probabilities = [x.probability for x in box_landings]
    assert [p["share"] for p in plan["parts"]] == pytest.approx(probabilities, abs=1e-12)
    machine = planned.made.result.machine
    for p, share in enumerate(probabilities):
        weight = math.fsum(s.weight for s in machine.states if s.part == p)
        assert weight == pytest.approx(share, abs=1e-12)
    alone = alone_expected(planned.made, 3)
    weighted = math.fsum(w * e for w, e in zip(probabilities, alone, strict=True))
    assert plan["stats"]["expected_length"] == pytest.approx(weighted, rel=1e-9)


@pytest.mark.slow
def test_expected_length_weights_poses_that_take_different_numbers_of_operations(tmp_path):
    # The extruded L: its big faces (pose-0, pose-1) are oriented sooner on average than its
    # thin side faces, so the shares move the expected length.
    import fixtures_cad as fx

    path = fx.write_mesh(fx.prism(ELL_RING, 3.0), tmp_path / "ell.stl")
    landings = landings_of_mesh(path, name="ell")
    planned = plan_landings(landings, ToleranceSensor(0.5), uncertainty=IDEAL)
    alone = alone_expected(planned.made, len(landings))
    shares = [x.probability for x in landings]
    weighted = math.fsum(w * e for w, e in zip(shares, alone, strict=True))
    equal = math.fsum(alone) / len(alone)
    assert planned.made.plan["stats"]["expected_length"] == pytest.approx(weighted, rel=1e-9)
    assert abs(weighted - equal) > 0.1


# ---------------------------------------------------------------- the plan command


def plan_cli(tmp_path, capsys, args, code=0, name="plan.json"):
    out = tmp_path / name
    rc = main(["plan", *args, "-o", str(out)])
    captured = capsys.readouterr()
    assert rc == code, captured.err
    return json.loads(out.read_text()), captured


def run_all(path, capsys):
    rc = main(["run", str(path), "--all"])
    captured = capsys.readouterr()
    assert rc == 0, captured.err
    return captured.out


def test_plan_covers_both_sides_of_a_chiral_outline_by_default(tmp_path, capsys):
    src = write_outline(tmp_path, "ell", ELL_RING, [ELL_HOLE])
    plan, cap = plan_cli(tmp_path, capsys, [src, "--tolerance", "0.5"])
    assert [(p["name"], p["landing"]) for p in plan["parts"]] == [("ell", "up"), ("ell", "down")]
    assert "landings (share): ell (up) 0.5 accepted, ell (down) 0.5 accepted" in cap.out
    for leaf in leaves(plan):
        assert len({e.landing for e in leaf.results}) == 1
    out = run_all(tmp_path / "plan.json", capsys)
    assert "down" in out


def test_plan_with_accept_ends_the_other_side_in_reject_results(tmp_path, capsys):
    src = write_outline(tmp_path, "ell", ELL_RING, [ELL_HOLE])
    plan, cap = plan_cli(tmp_path, capsys, [src, "--tolerance", "0.5", "--accept", "up"])
    assert "ell (down) 0.5 rejected" in cap.out
    for leaf in leaves(plan):
        assert leaf.reject == all(e.landing == "down" for e in leaf.results)
        assert {e.landing for e in leaf.results} in ({"up"}, {"down"})
    run_all(tmp_path / "plan.json", capsys)


def test_landings_option_picks_one_side(tmp_path, capsys):
    src = write_outline(tmp_path, "ell", ELL_RING, [ELL_HOLE])
    plan, _ = plan_cli(tmp_path, capsys, [src, "--tolerance", "0.5", "--landings", "down"])
    assert [(p["name"], p["landing"], p["share"]) for p in plan["parts"]] == [("ell", "down", 1.0)]
    assert {e.landing for leaf in leaves(plan) for e in leaf.results} == {"down"}


def test_sides_no_plan_tells_apart_exit_1_and_the_plan_is_still_written(tmp_path, capsys):
    src = write_outline(tmp_path, "ell", ELL_RING, [ELL_HOLE])
    plan, cap = plan_cli(tmp_path, capsys, [src, "--rotation-error", "0"], code=1)
    assert "recognizes ell but not which side is up: ell/up & ell/down" in cap.err
    assert any({e.landing for e in leaf.results} == {"up", "down"} for leaf in leaves(plan))


def test_a_symmetric_outline_plans_exactly_as_before(tmp_path, capsys):
    src = write_outline(tmp_path, "bar", [[0, 0], [30, 0], [30, 10], [0, 10]])
    plan, _ = plan_cli(tmp_path, capsys, [src, "--tolerance", "0.5"])
    assert made_as_drawn(plan)


def test_box_mesh_plan_names_its_poses_and_runs_on_every_one(tmp_path, capsys, box_path):
    plan, _ = plan_cli(tmp_path, capsys, [str(box_path), "--tolerance", "0.5"])
    assert [p["landing"] for p in plan["parts"]] == ["pose-0", "pose-2", "pose-4"]
    run_all(tmp_path / "plan.json", capsys)


def test_run_checks_every_landing_for_fragile_states_each_named_as_the_plan_names_it(
    tmp_path, capsys, box_path, monkeypatch
):
    """``Plan.fragile_warnings`` (what ``run`` repeats of ``plan``'s warnings): every landing
    says its own, labelled as the results name it, grouped by part: a mesh's poses are
    different shapes on the belt, and a flat part's two sides, though mirror images, number
    their states differently."""
    import feederkit.plans.model as plan_model

    seen: list[list[list[str]]] = []
    real = plan_model.fragile_member_warnings

    def spy(parts):
        seen.append([[label for label, _ in members] for members in parts])
        return real(parts)

    monkeypatch.setattr(plan_model, "fragile_member_warnings", spy)
    box, _ = plan_cli(tmp_path, capsys, [str(box_path), "--tolerance", "0.5"], name="box.json")
    assert seen == [[["box (pose-0)", "box (pose-2)", "box (pose-4)"]]]  # what plan said
    seen.clear()
    assert plan_from_dict(box).fragile_warnings() == []
    assert seen == [[["box (pose-0)", "box (pose-2)", "box (pose-4)"]]]  # what run says
    src = write_outline(tmp_path, "ell", [[0, 0], [30, 0], [30, 8], [8, 8], [8, 20], [0, 20]])
    ell, _ = plan_cli(tmp_path, capsys, [src, "--tolerance", "0.5"], name="ell.plan.json")
    assert [p["landing"] for p in ell["parts"]] == ["up", "down"]
    seen.clear()
    plan_from_dict(ell).fragile_warnings()
    assert seen == [[["ell (up)", "ell (down)"]]]


def test_box_mesh_plan_rejects_the_poses_not_accepted(tmp_path, capsys, box_path):
    plan, _ = plan_cli(tmp_path, capsys, [str(box_path), "--tolerance", "0.5", "--accept", "0"])
    rejected = {e.landing for leaf in leaves(plan) if leaf.reject for e in leaf.results}
    accepted = {e.landing for leaf in leaves(plan) if not leaf.reject for e in leaf.results}
    assert (rejected, accepted) == ({"pose-2", "pose-4"}, {"pose-0"})
    run_all(tmp_path / "plan.json", capsys)


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--landings", "pose-7"], "ell has no landing pose-7"),
        (["--landings", "sideways"], "invalid landing"),
        (["--landings", "up,,down"], "empty landing name"),
        (["--accept", "pose-1"], "--accept: no landing pose-1 is planned"),
        (["--accept", "down", "--landings", "up"], "--accept: no landing down is planned"),
    ],
)
def test_bad_landing_options_are_one_line_and_exit_2(tmp_path, capsys, args, words):
    src = write_outline(tmp_path, "ell", ELL_RING, [ELL_HOLE])
    err = one_line_error(capsys, ["plan", src, "--tolerance", "0.5", *args])
    assert words in err


def test_accepting_one_side_without_a_sensor_exits_1_in_one_line(tmp_path, capsys):
    from feederkit.cli.app import main

    src = write_outline(tmp_path, "ell", ELL_RING, [ELL_HOLE])
    rc = main(["plan", src, "--rotation-error", "0", "--accept", "up"])
    err = capsys.readouterr().err
    # Its fragile states are warned about first (a line each); the refusal is one line.
    (line,) = [x for x in err.strip().splitlines() if not x.startswith("warning:")]
    assert rc == 1 and "Traceback" not in err
    assert "ell (up) is accepted and ell (down) rejected" in line and "--accept" in line


def test_load_landings_of_a_mesh_and_of_an_outline(tmp_path, box_path):
    src = write_outline(tmp_path, "ell", ELL_RING, [ELL_HOLE])
    found = load_landings([src, str(box_path)], which="all")
    assert [[x.name for x in lands] for lands in found.landings] == [
        ["up", "down"],
        ["pose-0", "pose-2", "pose-4"],
    ]
    assert found.several and len(found.all) == 5


def test_a_changeover_over_landings_is_stored_with_its_landings(tmp_path):
    import feederkit.catalog as cat
    from feederkit.mix.changeover import compile_changeover, load_changeover

    db = tmp_path / "c.db"
    cat.add_outline(db, make_outline("ell", ELL_RING, [ELL_HOLE]))
    compiled = compile_changeover(
        db, "ell-up", ["ell"], ToleranceSensor(0.5), landings="all", accept={"up"}
    )
    assert [pf.part.name for pf in compiled.parts] == ["ell/up", "ell/down"]
    plan = compiled.plan
    assert [(p["name"], p["revision"], p["landing"]) for p in plan["parts"]] == [
        ("ell", "1", "up"),
        ("ell", "1", "down"),
    ]
    kinds = {(e.landing, leaf.reject) for leaf in leaves(plan) for e in leaf.results}
    assert kinds == {("up", False), ("down", True)}
    stored = load_changeover(db, "ell-up")
    assert [pf.part.name for pf in stored.parts] == ["ell/up", "ell/down"]
    assert stored.witnesses() == []
    assert stored.rejected == {"ell/down"}
    # The default is every landing, too (design.md): the same members, all accepted.
    default = compile_changeover(db, "ell", ["ell"], ToleranceSensor(0.5))
    assert [(p["landing"], p["share"]) for p in default.plan["parts"]] == [
        ("up", 0.5),
        ("down", 0.5),
    ]
    assert default.rejected == frozenset()


def test_a_plan_over_landings_restates_what_they_are_in_its_conventions(tmp_path, capsys):
    src = write_outline(tmp_path, "ell", ELL_RING, [ELL_HOLE])
    plan, _ = plan_cli(tmp_path, capsys, [src, "--tolerance", "0.5", "--accept", "up"])
    text = json.loads((tmp_path / "plan.json").read_text())["conventions"]
    assert "'down' mirrored about the part frame's y axis" in text and '"reject": true' in text
    bar = write_outline(tmp_path, "bar", [[0, 0], [30, 0], [30, 10], [0, 10]])
    plan_cli(tmp_path, capsys, [bar, "--tolerance", "0.5"])
    assert "Landings:" not in json.loads((tmp_path / "plan.json").read_text())["conventions"]
