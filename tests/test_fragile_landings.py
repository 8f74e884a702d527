"""Fragile-state warnings in plans over landings: each landing named with its own states.

A chiral flat part's down landing is the mirror image of its up landing: as fragile, but its
stable states are numbered differently. A warning naming the part's fragile states by the up
side's numbers points at a robust state of the down side, so in a plan over landings every
landing is named as the plan's results name it (``bracket-a (down)``) with its own state
numbers, the same words in ``plan``, ``run`` (terminal and ``--json``) and the HTML report.
The down side's fragile state is checked against the mirrored drawing analysed on its own.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import ezdxf
import pytest
from fixtures_cad import prism, write_mesh
from shared import made_as_drawn

from feederkit.cli.app import main
from feederkit.importers import ImportOptions
from feederkit.landing.mesh import landings_of_mesh
from feederkit.landing.plan import load_landings
from feederkit.mechanics.analysis import (
    FRAGILE_LINES,
    fragile_member_warnings,
    fragile_states,
    fragile_warning,
)
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.model import member_fragile_warnings
from feederkit.plans.readplan import plan_from_dict

# An L bracket (legs 60 and 40 mm, 15 mm wide) with two 6.6 mm holes: its short end (edge
# normal 0 deg) is a stable state 0.05 mm from tipping, below the fragile threshold of
# 0.0721 mm (1e-3 of its 72.1 mm size, its diameter); its other states are robust.
L_RING = [(0, 0), (60, 0), (60, 15), (15, 15), (15, 40), (0, 40)]
L_HOLES = [((47.0, 7.5), 3.3), ((7.5, 30.0), 3.3)]


def write_bracket(path: Path, mirror: bool = False) -> Path:
    """The bracket as a DXF drawing in mm; ``mirror``: drawn turned over (x -> -x), as an
    engineer would draw its back side, independently of feederkit's own mirroring."""
    sign = -1.0 if mirror else 1.0
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(sign * x, y) for x, y in L_RING], close=True)
    for (x, y), r in L_HOLES:
        msp.add_circle((sign * x, y), r)
    doc.saveas(path)
    return path


def _cli(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[str, str]:
    assert main(args) == 0
    captured = capsys.readouterr()
    return captured.out, captured.err


def _fragile_lines(err: str) -> list[str]:
    return [ln.removeprefix("warning: ") for ln in err.splitlines() if ": fragile states " in ln]


def _analysis(path: Path, capsys: pytest.CaptureFixture[str]) -> dict:
    out, _ = _cli(["part", "analyze", str(path), "--json"], capsys)
    (part,) = json.loads(out)
    return part


def _signature(state: dict) -> tuple[float, float]:
    """A state by its geometry, whatever its number: diameter and resting range width."""
    lo, hi = state["resting_range_deg"]
    return (round(state["diameter"], 6), round(hi - lo, 6))


@pytest.fixture()
def bracket(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> dict:
    """The bracket's plan over both landings (the default), the warnings ``plan`` printed,
    and the fragile state of each landing found independently: the drawing face up and the
    drawing turned over, each analysed on its own by ``part analyze``, the down one found in
    the plan's down member by its geometry (not by its number)."""
    up = write_bracket(tmp_path / "bracket-a.dxf")
    back = write_bracket(tmp_path / "bracket-a-back.dxf", mirror=True)
    path = tmp_path / "bracket.plan.json"
    _, err = _cli(["plan", str(up), "--tolerance", "0.2", "-o", str(path)], capsys)
    plan = json.loads(path.read_text())
    members = {p["landing"]: p for p in plan["parts"]}
    assert set(members) == {"up", "down"}
    (up_id,) = _analysis(up, capsys)["fragile_states"]  # one fragile state, the short end
    turned = _analysis(back, capsys)
    (back_id,) = turned["fragile_states"]
    fragile = next(s for s in turned["stable_states"] if s["id"] == back_id)
    (down_id,) = [
        s["id"] for s in members["down"]["stable_states"] if _signature(s) == _signature(fragile)
    ]
    return {
        "source": up,
        "plan_path": path,
        "plan": plan,
        "up_id": up_id,
        "down_id": down_id,
        "warnings": _fragile_lines(err),
    }


def test_the_down_landing_is_warned_about_with_its_own_fragile_state(bracket):
    up_id, down_id = bracket["up_id"], bracket["down_id"]
    assert (up_id, down_id) == (1, 3)  # the point: face down, state 1 is another state
    (line,) = bracket["warnings"]
    assert line.startswith(
        f"bracket-a (up): fragile states {up_id}; bracket-a (down): fragile states {down_id} "
        "(barrier below 0.0721 mm): the part may settle on a neighbour"
    )
    assert "bracket-a: " not in line  # never the bare part name, with the up side's numbers
    # The down landing's state 1 is robust: a result names it, and no warning does.
    leaves = plan_from_dict(bracket["plan"]).leaves()
    assert ("bracket-a", "down", up_id) in [
        (e.part, e.landing, e.state) for n in leaves for e in n.results
    ]


def test_run_and_the_report_say_the_same_per_landing(bracket, tmp_path, capsys):
    (line,) = bracket["warnings"]
    out, _ = _cli(["run", str(bracket["plan_path"]), "--all", "--json"], capsys)
    assert json.loads(out)["warnings"] == [line]
    _, err = _cli(["run", str(bracket["plan_path"]), "--start-deg", "10"], capsys)
    assert f"warning: {line}" in err.splitlines()  # one line on stderr
    report = tmp_path / "bracket.html"
    _cli(["report", str(bracket["plan_path"]), "-o", str(report)], capsys)
    page = report.read_text(encoding="utf-8")
    banner = page.split('id="fragile-states">', 1)[1].split("</div>", 1)[0]
    assert banner == f"Warning: {line}."  # nothing in it to escape


def test_plan_face_down_only_names_the_down_state(bracket, capsys):
    args = ["plan", str(bracket["source"]), "--tolerance", "0.2", "--landings", "down", "--json"]
    _, err = _cli(args, capsys)
    (line,) = _fragile_lines(err)
    assert line.startswith(f"bracket-a (down): fragile states {bracket['down_id']} (barrier")


BENT = 20.0 * math.tan(math.radians(0.5))
BENT_BAR = [(0, 0), (20, -BENT), (40, 0), (40, 10), (0, 10)]
"""A 40 x 10 bar whose bottom bends by 0.5 degrees: mirror-symmetric, two fragile states."""


def test_a_plan_not_over_landings_keeps_the_part_name(tmp_path, capsys):
    src = tmp_path / "bent-bar.json"
    src.write_text(json.dumps({"name": "bent-bar", "units": "mm", "vertices": BENT_BAR}))
    expected = fragile_warning(push_function(make_part(make_outline("bent-bar", BENT_BAR))))
    assert expected is not None and expected.startswith("bent-bar: fragile states ")
    plan = tmp_path / "bar.plan.json"
    _, err = _cli(["plan", str(src), "--tolerance", "0.5", "-o", str(plan)], capsys)
    assert made_as_drawn(plan.read_text())  # one landing: the plan of the part itself
    assert _fragile_lines(err) == [expected]
    out, _ = _cli(["run", str(plan), "--all", "--json"], capsys)
    assert json.loads(out)["warnings"] == [expected]
    # Named landings make a plan over landings, even of one: the label names it.
    _, err = _cli(["plan", str(src), "--tolerance", "0.5", "--landings", "up", "--json"], capsys)
    assert _fragile_lines(err) == [expected.replace("bent-bar:", "bent-bar (up):", 1)]


def test_each_mesh_pose_is_named_as_the_plan_names_it(tmp_path, capsys):
    # The bracket's plate extruded 3 mm: its two big faces are the flat part's two sides.
    path = write_mesh(prism(L_RING, 3.0), tmp_path / "lplate.stl")
    poses = {x.name: x for x in landings_of_mesh(path, ImportOptions(), "lplate")}
    expected = {
        name: fragile_states(push_function(poses[name].part)) for name in ("pose-0", "pose-1")
    }
    assert all(expected.values())
    _, err = _cli(["plan", str(path), "--tolerance", "0.2", "--landings", "0,1", "--json"], capsys)
    (line,) = _fragile_lines(err)
    named = "; ".join(
        f"lplate ({name}): fragile states {', '.join(map(str, ids))}"
        for name, ids in expected.items()
    )
    assert line.startswith(named + " (barrier below")
    assert "lplate/" not in line  # not the landing's part name


def test_members_of_different_sizes_give_each_its_barrier_and_a_large_mix_counts_parts():
    def bar(name: str, scale: float):
        ring = [(x * scale, y * scale) for x, y in BENT_BAR]
        return push_function(make_part(make_outline(name, ring)))

    small, large = bar("s", 1.0), bar("l", 2.0)
    (line,) = fragile_member_warnings([[("box (pose-0)", small), ("box (pose-1)", large)]])
    assert line.startswith("box (pose-0): fragile states ")
    assert "(barrier below 0.0412 mm); box (pose-1): fragile states " in line
    assert line.endswith(
        "(barrier below 0.0825 mm): the part may settle on a neighbour; check the plan with "
        "feederkit simulate"
    )
    many = [[(f"p{k} (up)", small), (f"p{k} (down)", small)] for k in range(FRAGILE_LINES + 1)]
    (line,) = fragile_member_warnings(many)
    assert line.startswith(f"{FRAGILE_LINES + 1} parts have fragile states")
    assert "p0 (up) (" in line and "p0 (down) (" in line


def test_changeover_compile_says_the_same_per_landing(bracket, tmp_path, capsys):
    """The changeover's warnings (terminal and --json) are plan's words, not the part's."""
    (line,) = bracket["warnings"]
    db = str(tmp_path / "c.db")
    _cli(["catalog", "init", "--catalog", db], capsys)
    _cli(["catalog", "add", str(bracket["source"]), "--catalog", db], capsys)
    args = ["changeover", "compile", "line", "--mix", "bracket-a", "--tolerance", "0.2"]
    out, err = _cli([*args, "--json", "--catalog", db], capsys)
    assert [w for w in json.loads(out)["warnings"] if "fragile" in w] == [line]
    assert _fragile_lines(err) == [line]


def test_design_sensor_says_the_same_per_landing(bracket, capsys):
    """The sensor design over both landings warns as plan does (it printed the part's lines,
    numbered as drawn, before)."""
    (line,) = bracket["warnings"]
    args = ["design", "sensor", str(bracket["source"]), "--rotation-error", "0", "--json"]
    main(args)
    assert _fragile_lines(capsys.readouterr().err) == [line]


def _lplate_with_com(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[str, str]:
    """The 3 mm L plate as a catalog part added with ``--com``: its one landing is the pose
    imported, so plans for it are not over landings. The catalog and the line
    ``part analyze`` gives its one fragile state."""
    path = write_mesh(prism(L_RING, 3.0), tmp_path / "lplate.stl")
    db = str(tmp_path / "c.db")
    _cli(["catalog", "init", "--catalog", db], capsys)
    com = make_part(make_outline("lplate", L_RING)).com
    _cli(["catalog", "add", str(path), "--com", *map(str, com), "--catalog", db], capsys)
    out, err = _cli(["part", "analyze", "lplate", "--catalog", db, "--json"], capsys)
    assert json.loads(out)[0]["fragile_states"] == [1]
    (line,) = _fragile_lines(err)
    assert line.startswith("lplate: fragile states 1 (barrier")
    return db, line


def test_a_mesh_with_one_landing_names_its_fragile_state_once_by_the_part_name(tmp_path, capsys):
    """Not over landings, the plan's member is the part: its fragile states are said once,
    by the part's name (they were said again under the pose's part name, ``lplate/pose-0``)."""
    db, line = _lplate_with_com(tmp_path, capsys)
    plan = tmp_path / "lplate.plan.json"
    _, err = _cli(
        ["plan", "lplate", "--catalog", db, "--tolerance", "0.2", "-o", str(plan)], capsys
    )
    assert made_as_drawn(plan.read_text())
    assert _fragile_lines(err) == [line]
    out, _ = _cli(["run", str(plan), "--all", "--json"], capsys)
    assert json.loads(out)["warnings"] == [line]
    args = ["changeover", "compile", "line", "--mix", "lplate", "--tolerance", "0.2"]
    out, err = _cli([*args, "--json", "--catalog", db], capsys)
    assert [w for w in json.loads(out)["warnings"] if "fragile" in w] == [line]
    assert _fragile_lines(err) == [line]
    # Named, the one landing makes a plan over landings: its line names it, once.
    _, err = _cli(["plan", "lplate", "--catalog", db, "--landings", "0", "--json"], capsys)
    assert _fragile_lines(err) == [line.replace("lplate:", "lplate (pose-0):", 1)]


def test_over_landings_the_loaded_fragile_lines_give_way_to_the_landings_own(bracket, tmp_path):
    """The loading keeps its fragile lines apart from the imports' warnings: a plan of the
    parts themselves says both, a plan over landings every import warning, in order, then
    each landing's fragile states, and no line numbered as a part is drawn."""
    mesh = write_mesh(prism(L_RING, 3.0), tmp_path / "lplate.stl")
    found = load_landings([str(bracket["source"]), str(mesh)])
    loaded = found.parts
    (note,) = loaded.import_warnings
    assert note.startswith(f"{mesh}: the file carries no units: read as mm, the part is")
    assert [w.split(":", 1)[0] for w in loaded.fragile_warnings] == ["bracket-a", "lplate"]
    assert loaded.warnings == loaded.import_warnings + loaded.fragile_warnings
    assert found.warnings(over_landings=False) == list(loaded.warnings)
    over = found.warnings(over_landings=True)
    members = [(x.part_name, x.name, push_function(x.part)) for x in found.all]
    assert over == [*loaded.import_warnings, *member_fragile_warnings(members)]
    assert not set(over) & set(loaded.fragile_warnings)
    (bracket_line, lplate_line) = over[1:]
    assert bracket_line.startswith("bracket-a (up): fragile states 1; bracket-a (down): ")
    assert lplate_line.startswith("lplate (pose-0): fragile states 1")
    assert "lplate/" not in lplate_line
