"""The plan file's contract with the robot controller (design.md, "Plan file"), as the loader
(``plan_from_dict``) enforces it: a file that breaks it is refused with one line (exit 2),
and every plan feederkit itself writes still loads.

Each refusal test loads a plan ``feederkit plan`` wrote, edits one thing, and checks the
message; without the rule the edited file loads (the reviewer's cases exited 0).
"""

from __future__ import annotations

import copy
import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import trimesh
from shared import no_stray_profile, one_line_error  # noqa: F401 (an autouse fixture)

from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.plans.readplan import plan_from_dict, read_plan

ROOT = Path(__file__).resolve().parents[1]
CATALOG = ROOT / "catalog"

Edit = Callable[[dict[str, Any]], object]


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The reviewer's plan: the l-bracket over its two landings, an LED array (0.5 mm
    pitch, 0.1 mm noise)."""
    out = tmp_path_factory.mktemp("plan") / "F.json"
    args = ["plan", str(CATALOG / "l-bracket.json"), "--led-pitch", "0.5", "--noise", "0.1"]
    assert main([*args, "-o", str(out)]) == 0
    return json.loads(out.read_text(encoding="utf-8"))


def edited(plan: dict[str, Any], edit: Edit) -> dict[str, Any]:
    """A deep copy of ``plan`` with ``edit`` applied."""
    out = copy.deepcopy(plan)
    edit(out)
    return out


def refused(plan: dict[str, Any], edit: Edit) -> str:
    """The one-line message the loader refuses the edited plan with."""
    bad = edited(plan, edit)
    with pytest.raises(InputError) as err:
        plan_from_dict(bad, "F.json")
    message = str(err.value)
    assert message.startswith("F.json: ") and "\n" not in message
    return message


def part0(d: dict[str, Any]) -> dict[str, Any]:
    return d["parts"][0]


def test_the_written_plan_loads(written: dict[str, Any]) -> None:
    assert plan_from_dict(written).parts[0].hull == tuple(map(tuple, part0(written)["hull"]))


# ---------------------------------------------------------------- the hull (design.md, Conventions)


def _rotate(d: dict[str, Any]) -> None:
    hull = part0(d)["hull"]
    part0(d)["hull"] = hull[1:] + hull[:1]


def test_a_hull_not_numbered_from_its_lowest_then_leftmost_vertex_is_refused(written) -> None:
    message = refused(written, _rotate)
    assert "part 'l-bracket (up)' hull: vertex 0 (60, 0)" in message
    assert "not the lowest-then-leftmost vertex; vertex 4 (0, 0) is" in message


def test_a_reflex_vertex_is_refused(written) -> None:
    message = refused(written, lambda d: part0(d)["hull"].insert(2, [40.0, 10.0]))
    assert "vertex 2 (40, 10) is no corner: it lies 20 mm inside the line of vertices 1 and 3" in (
        message
    )


@pytest.mark.parametrize(("off", "side"), [(0.0, "on"), (1e-13, "1e-13 mm inside")])
def test_a_vertex_on_or_inside_an_edge_is_refused(written, off: float, side: str) -> None:
    """Edge 0 runs from (0, 0) to (60, 0); the part lies above it."""
    message = refused(written, lambda d: part0(d)["hull"].insert(1, [30.0, off]))
    words = f"vertex 1 (30, {off:g}) is no corner: it lies {side} the line of vertices 0 and 2"
    assert words in message


@pytest.mark.parametrize(
    ("copy_of", "words"),
    [
        ([60.0, 15.0], "vertex 3 (60, 15) repeats vertex 2"),
        ([60.0, 15.000000000001], "vertex 2 (60, 15) is no corner: it lies on the line"),
    ],
)
def test_a_duplicate_vertex_is_refused(written, copy_of: list[float], words: str) -> None:
    assert words in refused(written, lambda d: part0(d)["hull"].insert(2, copy_of))


def test_a_vertex_a_hair_outside_is_not_a_contact_polygon(written) -> None:
    """A vertex 1e-13 mm outside edge 0 is collinear with its neighbours to rounding
    (``hull.COLLINEAR_REL``): no contact polygon feederkit writes has it, and two edges whose
    normals differ by rounding cannot be classified, so the loader refuses it (exit 2)."""

    def hair(d: dict[str, Any]) -> None:
        hull = part0(d)["hull"]  # the new vertex is the lowest: vertex 0
        part0(d)["hull"] = [[30.0, -1e-13], *hull[1:], hull[0]]

    with pytest.raises(InputError, match="not the convex hull of its vertices"):
        plan_from_dict(edited(written, hair))


def test_a_plan_written_at_hull_tolerance_0_loads(tmp_path: Path) -> None:
    """At ``--hull-tolerance 0`` a vertex 1e-14 mm off the line of its neighbours (an outline
    edge split at a point off it by rounding) is collinear and dropped; a vertex a billionth
    of the size off is kept (the test above), and the plan loads and verifies either way."""
    outline = tmp_path / "split.json"
    ring = [[0, 0], [7, -1e-14], [20, 0], [40, 0], [40, 20], [0, 20]]
    outline.write_text(json.dumps({"name": "split", "units": "mm", "vertices": ring}))
    path = tmp_path / "split.plan.json"
    args = ["plan", str(outline), "--tolerance", "0.5", "--hull-tolerance", "0", "-o", str(path)]
    assert main(args) in (0, 1)  # 1: its two sides cannot be told apart
    plan = read_plan(path)
    assert plan.parts[0].hull[0] == (0.0, 0.0) and len(plan.parts[0].hull) == 4
    assert main(["run", str(path), "--all"]) == 0


def test_a_hull_breaking_the_contract_exits_2_from_run(written, tmp_path, capsys) -> None:
    path = tmp_path / "F.json"
    path.write_text(json.dumps(edited(written, _rotate)), encoding="utf-8")
    err = one_line_error(capsys, ["run", str(path), "--all"])
    assert "lowest-then-leftmost" in err and "l-bracket (up)" in err


# ---------------------------------------------------------------- every plan feederkit writes loads


GOLDEN = sorted(
    p
    for p in (ROOT / "tests").rglob("*.json")
    if '"feederkit-plan"' in p.read_text(encoding="utf-8")[:200]
)


@pytest.mark.parametrize("path", GOLDEN, ids=lambda p: str(p.relative_to(ROOT / "tests")))
def test_every_stored_plan_loads(path: Path) -> None:
    read_plan(path)


L_RING = [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)]


@pytest.fixture(scope="module")
def plans_written(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """Plans the commands write: ``plan`` for every catalog part (sensorless and with an
    LED array), a DXF plate with arcs (a simplified hull), a box and an L prism as meshes
    (their resting poses), ``changeover compile`` over a catalog and ``demo``."""
    import fixtures_cad as fx

    tmp = tmp_path_factory.mktemp("written")
    out: list[Path] = []

    def plan(name: str, *args: str) -> None:
        path = tmp / f"{name}.plan.json"
        assert main(["plan", *args, "-o", str(path)]) in (0, 1)
        out.append(path)

    for src in sorted(CATALOG.glob("*.json")):
        plan(src.stem, str(src))
        plan(f"{src.stem}-led", str(src), "--led-pitch", "0.5", "--noise", "0.1")
    plate = fx.write_plate(tmp / "plate.dxf")
    # Its hole and slot swap ends between its two long-side poses: only lumping "any" lists
    # them together (near-symmetric lumping compares the outlines, not only the hulls).
    plan("plate", str(plate), "--tolerance", "0.5", "--lumping", "any")
    box = tmp / "box.stl"
    trimesh.creation.box((10.0, 20.0, 30.0)).export(box)
    plan("box", str(box), "--tolerance", "0.5")
    ell = fx.write_mesh(fx.prism(L_RING, 3.0), tmp / "ell.stl")
    # Its side landings (the leg standing at one end) have no strong plan: the flat ones.
    plan("ell", str(ell), "--tolerance", "0.5", "--landings", "0,1")

    db = tmp / "parts.db"
    assert main(["catalog", "init", "--catalog", str(db)]) == 0
    assert main(["catalog", "import", str(CATALOG), "--catalog", str(db)]) in (0, 1)
    mix = ["changeover", "compile", "mix", "--mix", "t-clip,l-bracket,isosceles-right-triangle"]
    compiled = tmp / "mix.plan.json"
    assert main([*mix, "--tolerance", "0.1", "-o", str(compiled), "--catalog", str(db)]) == 0
    out.append(compiled)

    parts = tmp / "few"
    parts.mkdir()
    for name in ("isosceles-right-triangle", "octagon", "quadrilateral", "rectangle-2x1"):
        shutil.copy(CATALOG / f"{name}.json", parts)
    demo = tmp / "demo"
    assert main(["demo", "--catalog-dir", str(parts), "-o", str(demo), "--json"]) == 0
    out += sorted(demo.rglob("*.json"))
    return out


def test_every_plan_the_commands_write_loads(plans_written: list[Path]) -> None:
    names = {p.name for p in plans_written}
    assert {"plate.plan.json", "box.plan.json", "ell.plan.json", "mix.plan.json"} <= names
    loaded = 0
    for path in plans_written:
        data = json.loads(path.read_text(encoding="utf-8"))
        if data.get("format") == "feederkit-plan":
            plan_from_dict(data, str(path))
            loaded += 1
    assert loaded >= 25


def test_a_hull_a_billionth_of_its_size_off_a_line_is_written_and_loads() -> None:
    """The closest call the writer makes: a 2 x 1 rectangle whose bottom sags by 1e-8 mm
    keeps a vertex 1.9e-9 mm off the line of its neighbours (below its own cleaning
    tolerance, which measures against the original points), far above the loader's."""
    import math

    from feederkit.mechanics.push import push_function
    from feederkit.outline import make_outline
    from feederkit.part import make_part
    from feederkit.plans.make import make_plan
    from feederkit.sensors import ToleranceSensor
    from feederkit.uncertainty import Uncertainty

    bottom = [(2.0 * i / 40, -1e-8 * math.sin(math.pi * i / 40)) for i in range(41)]
    part = make_part(make_outline("bulge", [*bottom, (2.0, 1.0), (0.0, 1.0)]))
    made = make_plan([push_function(part)], ToleranceSensor(0.1), uncertainty=Uncertainty(0.0))
    assert len(made.plan["parts"][0]["hull"]) == 7
    plan_from_dict(made.plan)


# ---------------------------------------------------------------- numbers no part has


def state0(d: dict[str, Any]) -> dict[str, Any]:
    return part0(d)["stable_states"][0]


def first_result(d: dict[str, Any]) -> dict[str, Any]:
    """The first result node of the plan, the shared subplans' included."""
    stack = [d["root"], *d.get("nodes", {}).values()]
    while stack:
        node = stack.pop(0)
        if "result" in node:
            return node
        stack += [b["next"] for b in node.get("branches", [])]
    raise AssertionError("the plan has no result")


def test_a_diameter_wider_than_the_part_is_refused_and_report_says_so(
    written, tmp_path, capsys
) -> None:
    """A hand-edited diameter of 1e308 made ``report`` fail with an overflow in the LED
    counts; the part (60 x 40 mm) is at most 72.111 mm across."""
    edit = lambda d: state0(d).update(diameter=1e308)  # noqa: E731
    message = refused(written, edit)
    assert "part 'l-bracket (up)' stable state 0 diameter 1e+308 mm is not in (0, 72.111]" in (
        message
    )
    path = tmp_path / "F.json"
    path.write_text(json.dumps(edited(written, edit)), encoding="utf-8")
    err = one_line_error(capsys, ["report", str(path), "-o", str(tmp_path / "r.html")])
    assert "stable state 0 diameter" in err and "too large" not in err


def test_a_diameter_the_part_could_have_is_the_verifiers_question(written) -> None:
    """A plan whose listed states disagree with its own hull and COM fails verification
    (exit 1; ``report`` draws it under a red banner), as docs/plans.md says: the loader
    refuses only numbers no part of that hull has."""
    from feederkit.plans.verify import verify_declared

    plan = plan_from_dict(edited(written, lambda d: state0(d).update(diameter=45.0)))
    assert "diameter 45" in verify_declared(plan).first_problem()


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda d: state0(d).update(normal_deg=360.0), "stable state 0 normal_deg 360 is not"),
        (lambda d: state0(d).update(pose_deg=-90.0), "stable state 0 pose_deg -90 is not"),
        (lambda d: first_result(d)["result"][0].update(pose_deg=720.0), "pose_deg 720 is not"),
    ],
    ids=["normal", "pose", "result pose"],
)
def test_an_angle_outside_0_360_is_refused(written, edit: Edit, words: str) -> None:
    message = refused(written, edit)
    assert words in message and "in [0, 360)" in message


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda d: d["root"]["branches"][2].update(reading=[59.5, 1e308]), "[59.5, 1e+308]"),
        (lambda d: d["sensor"].update(noise_mm=1e308), "sensor noise_mm 1e+308"),
        (lambda d: d["sensor"].update(pitch_mm=5e-324), "pitch_mm 4.94066e-324"),
        (lambda d: d["sensor"].update(noise_mm=0.0, pitch_mm=1e-300), "diameter 40 mm"),
    ],
    ids=["reading", "noise", "pitch", "pitch for a diameter"],
)
def test_an_led_width_of_more_than_2_53_beams_is_refused(written, edit: Edit, words: str) -> None:
    """Beam counts of absurd widths overflowed (``run --all`` and ``report``, exit 2 with
    'a number is too large to compute with')."""
    message = refused(written, edit)
    assert words in message and "more than 2**53 beams" in message


@pytest.mark.parametrize("noise", [1e7, 1e15])
def test_an_led_noise_of_more_than_a_thousand_pitches_is_refused(written, noise: float) -> None:
    """Reading branches are made one beam count at a time: 10^7 exhausted the memory."""
    message = refused(written, lambda d: d["sensor"].update(noise_mm=noise))
    assert f"sensor noise_mm {noise:g}" in message and "1000 beam pitches" in message


# ---------------------------------------------------------------- the grammar (design.md)


def test_a_result_that_is_also_an_operation_is_refused(written) -> None:
    def both(d: dict[str, Any]) -> None:
        first_result(d).update(action_deg=90.0, margin_deg=1.0, branches=[])

    message = refused(written, both)
    assert "has 'action_deg', but a result has only 'result', 'reject'" in message


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda d: d["root"].update(reject=False), "the root has 'reject', but an operation"),
        (lambda d: d["root"]["branches"][0].update(note="x"), "branch 0 has 'note', but a branch"),
        (
            lambda d: first_result(d)["result"][0].update(edge=0),
            "result entry has 'edge', but an entry has only 'part', 'landing', 'state'",
        ),
    ],
    ids=["operation", "branch", "result entry"],
)
def test_a_key_outside_a_nodes_form_is_refused(written, edit: Edit, words: str) -> None:
    assert words in refused(written, edit)


@pytest.mark.parametrize("value", [0, 9])
def test_a_polygon_class_outside_1_8_is_refused(written, value: int) -> None:
    message = refused(written, lambda d: d["stats"].update({"class": value}))
    assert f"stats class {value} is not a polygon class 1-8" in message


def test_an_unknown_objective_is_refused(written) -> None:
    message = refused(written, lambda d: d["stats"].update(objective="fastest"))
    assert "stats objective 'fastest' is not one of worst, expected, time, worst-time" in message


def test_class_and_objective_may_be_null_or_any_of_design_mds(written) -> None:
    """Null: a mix's plan has no class; the objectives are the planner's (``--objective``)."""
    from feederkit.planning.options import Objective
    from feederkit.plans.readplan import OBJECTIVES

    assert set(OBJECTIVES) == {o.value for o in Objective}
    for objective in (None, *OBJECTIVES):
        for value in (None, 1, 8):
            plan = copy.deepcopy(written)
            plan["stats"].update({"class": value, "objective": objective})
            plan_from_dict(plan)


def test_a_part_without_a_revision_is_refused_and_null_is_one(written) -> None:
    message = refused(written, lambda d: part0(d).pop("revision"))
    assert "part 'l-bracket (up)' has no 'revision' (null when the part has none)" in message
    assert part0(written)["revision"] is None
    plan_from_dict(written)


@pytest.mark.parametrize(
    ("sensor", "words"),
    [
        (
            {"model": "led", "pitch_mm": 0.5, "noise_mm": 0.1, "tolerance_mm": 0.2},
            "'sensor' has 'tolerance_mm', but the 'led' sensor has only 'model', 'pitch_mm'",
        ),
        ({"model": "none", "pitch_mm": 0.5}, "but the 'none' sensor has only 'model'"),
    ],
)
def test_a_sensor_key_of_another_model_is_refused(written, sensor: dict, words: str) -> None:
    assert words in refused(written, lambda d: d.update(sensor=sensor))


def test_the_sensor_parameters_are_the_ones_the_models_write() -> None:
    from feederkit.plans.readplan import SENSOR_PARAMETERS
    from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor

    for sensor in (NoSensor(), ToleranceSensor(0.1), LedSensor(0.5, 0.1)):
        written_keys = sensor.to_dict()
        assert set(written_keys) == {"model", *SENSOR_PARAMETERS[written_keys["model"]]}


def test_a_version_1_file_still_loads() -> None:
    """design.md: version-1 files stay readable (no declared uncertainty, no landings)."""
    plan = read_plan(ROOT / "tests" / "golden" / "v1" / "equilateral-triangle.tolerance.json")
    assert not plan.uncertainty_declared


# ---------------------------------------------------------------- what feederkit writes


def test_a_plan_its_own_loader_refuses_is_never_written(written, tmp_path, monkeypatch) -> None:
    """Every written plan is read back as a reader will before anything is written: a file
    the loader refuses is a bug (exit 70) and no file, not a written plan that ``run`` then
    refuses."""
    from feederkit.plans.readplan import plan_from_text
    from feederkit.plans.writeplan import plan_file_text

    assert plan_from_text(plan_file_text(written)).parts[0].name == "l-bracket"
    with pytest.raises(AssertionError, match="its own loader refuses: .*revision"):
        plan_file_text(edited(written, lambda d: part0(d).pop("revision")))

    import feederkit.plans.make as make

    real = make._plan_dict

    def without_revision(*args, **kwargs):
        data = real(*args, **kwargs)
        for part in data["parts"]:
            part.pop("revision")
        return data

    monkeypatch.setattr(make, "_plan_dict", without_revision)
    out, report = tmp_path / "P.json", tmp_path / "P.html"
    args = ["plan", str(CATALOG / "t-clip.json"), "--tolerance", "0.5"]
    assert main([*args, "-o", str(out), "--report", str(report)]) == 70
    assert not out.exists() and not report.exists()


def test_a_plan_as_deep_as_the_loader_takes_parses() -> None:
    """A stored changeover's plan is parsed as deep as a plan file may be (three JSON levels
    per operation), not to the JSON files' general limit."""
    from feederkit.jsonio import MAX_JSON_DEPTH, parse_json
    from feederkit.plans.readplan import parse_plan_text

    text = "[" * (MAX_JSON_DEPTH + 50) + "]" * (MAX_JSON_DEPTH + 50)
    with pytest.raises(InputError):
        parse_json(text, "deep")
    assert isinstance(parse_plan_text(text, "deep"), list)
