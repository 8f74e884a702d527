"""``run PLAN SOURCE`` takes a SOURCE as the plan's part within the shape and COM tolerances
the plan declares (design.md, "Uncertainty": the plan holds for every such part), and when it
refuses one says how far it lies and, for the part in another frame or other units, so
(``simulate --part``'s words): it used to refuse a revision whose COM moved 0.008 mm under
a declared 0.02 mm, and to blame the file's name for the part moved in its drawing."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from shared import one_line_error

from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def outline(tmp_path: Path, name: str, move=(0.0, 0.0), scale=1.0) -> str:
    data = json.loads((CATALOG / "l-bracket.json").read_text())
    data["name"] = name

    def moved(p):
        return [scale * (p[0] + move[0]), scale * (p[1] + move[1])]

    data["vertices"] = [moved(p) for p in data["vertices"]]
    data["holes"] = [[moved(p) for p in h] for h in data.get("holes", [])]
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(data))
    return str(path)


@pytest.fixture(scope="module")
def planned(tmp_path_factory) -> tuple[Path, list[float]]:
    folder = tmp_path_factory.mktemp("lb")
    plan = folder / "lb.plan.json"
    args = ["plan", str(CATALOG / "l-bracket.json"), "--tolerance", "0.2", "--landings", "up"]
    assert main([*args, "--com-tolerance", "0.02", "-o", str(plan)]) == 0
    com = json.loads(plan.read_text())["parts"][0]["com"]
    return plan, com


def with_com(tmp_path: Path, com: list[float], dx: float) -> str:
    data = json.loads((CATALOG / "l-bracket.json").read_text())
    data["com"] = [com[0] + dx, com[1]]
    path = tmp_path / "l-bracket.json"
    path.write_text(json.dumps(data))
    return str(path)


def test_a_part_within_the_declared_com_tolerance_is_the_plan_s(planned, tmp_path, capsys):
    plan, com = planned
    assert main(["run", str(plan), with_com(tmp_path, com, 0.008), "--all"]) == 0
    assert "end in their result" in " ".join(capsys.readouterr().out.split())


def test_a_part_beyond_it_is_refused_with_the_distances(planned, tmp_path, capsys):
    plan, com = planned
    err = one_line_error(capsys, ["run", str(plan), with_com(tmp_path, com, 0.05), "--all"])
    assert "COM 0.05 mm off; the plan declares shape tolerance 0 mm, COM tolerance 0.02 mm" in err


def test_the_part_moved_in_its_drawing_is_named_as_such(planned, tmp_path, capsys):
    plan, _ = planned
    source = outline(tmp_path, "lb-moved", move=(100.0, 50.0))
    err = one_line_error(capsys, ["run", str(plan), source, "--all"])
    assert "moved by (-100, -50) mm, its hull is the plan's" in err
    assert "the part's frame differs from the plan's" in err


def test_the_part_in_inches_is_named_as_such(planned, tmp_path, capsys):
    plan, _ = planned
    source = outline(tmp_path, "lb-inch", scale=1 / 25.4)
    err = one_line_error(capsys, ["run", str(plan), source, "--all"])
    assert "likely in inches, read as millimetres" in err and "give NAME as the SOURCE" in err
