"""The catalog judges a mesh orientable by its landings, as ``plan`` does.

A cylinder (64 sections, 20 x 30 mm) lands on its side in 83 % of drops and on an end, a
disk, in 17 %; its imported pose is the likeliest single facet, an end, so the catalog stored
and listed it as not orientable ("disk-like") while ``plan`` oriented it in 2 operations:
a user filtering the catalog on its orientable column dropped parts that feed fine.
"""

from __future__ import annotations

import json
from pathlib import Path

import trimesh

from feederkit.cli.app import main


def test_a_cylinder_is_orientable_on_its_side(tmp_path: Path, capsys) -> None:
    path = tmp_path / "cylinder.stl"
    trimesh.creation.cylinder(radius=10.0, height=30.0, sections=64).export(path)
    db = str(tmp_path / "c.db")
    assert main(["catalog", "add", str(path), "--units", "mm", "--catalog", db]) == 0
    capsys.readouterr()
    assert main(["catalog", "show", "cylinder", "--json", "--catalog", db]) == 0
    shown = json.loads(capsys.readouterr().out)
    assert shown["orientable_ideal"] is True
    (note,) = [w for w in shown["warnings"] if "not orientable by pushing" in w]
    assert note.startswith("pose-0 (") and "a plan orients the part by them" in note


def test_a_flat_disk_stays_not_orientable(tmp_path: Path, capsys) -> None:
    import ezdxf

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_circle((0, 0), 10)
    path = tmp_path / "disk.dxf"
    doc.saveas(path)
    db = str(tmp_path / "d.db")
    assert main(["catalog", "add", str(path), "--catalog", db]) == 0
    capsys.readouterr()
    assert main(["catalog", "show", "disk", "--json", "--catalog", db]) == 0
    shown = json.loads(capsys.readouterr().out)
    assert shown["orientable_ideal"] is False
    assert any(w.startswith("not orientable by pushing") for w in shown["warnings"])
