"""A mesh part whose most probable pose pushing cannot orient (a cylinder on its round end)
is still planned over the landings that can be, from its file and from the catalog."""

from __future__ import annotations

import math

from fixtures_cad import prism, write_mesh

from feederkit.cli.app import main


def cylinder(tmp_path):
    """A 64-facet cylinder, 20 mm across and 30 mm long: each round end is a likelier pose
    than any one of its sides, all 64 sides together much likelier."""
    ring = [
        (10 * math.cos(2 * math.pi * k / 64), 10 * math.sin(2 * math.pi * k / 64))
        for k in range(64)
    ]
    return write_mesh(prism(ring, 30.0), tmp_path / "cyl.ply")


def test_a_cylinder_file_plans_over_its_landings(tmp_path, capsys):
    path = cylinder(tmp_path)
    assert main(["plan", str(path), "--tolerance", "0.1"]) == 0
    err = " ".join(capsys.readouterr().err.split())
    assert "the imported pose is not orientable by pushing" in err


def test_a_cylinder_in_the_catalog_plans_its_side_landing(tmp_path, capsys):
    path = cylinder(tmp_path)
    db = tmp_path / "parts.db"
    assert main(["catalog", "add", str(path), "--catalog", str(db)]) == 0
    capsys.readouterr()
    assert main(["plan", "cyl", "--catalog", str(db), "--tolerance", "0.1", "--json"]) == 0
    out = capsys.readouterr().out
    assert '"pose-0"' in out  # the round end, its own landing


def test_a_cylinder_plan_file_runs(tmp_path, capsys):
    """The file's diameters are as planned on: snapped within DIAMETER_REL_EPS of the
    largest landing (60 mm lying down), further than that share of the round end's own
    size from what its hull gives; every reader of the file accepts them."""
    path = cylinder(tmp_path)
    out = tmp_path / "cyl.plan.json"
    assert main(["plan", str(path), "--tolerance", "0.1", "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["run", str(out), "--all"]) == 0, capsys.readouterr().out
