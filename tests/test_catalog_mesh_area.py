"""``catalog list`` and ``show``: a mesh's area is its convex hull's, and said to be.

A mesh import keeps, as each pose's outline, the convex hull of the mesh seen from above (what
the fence feels), not its footprint: an L plate of 1112 mm2 listed 1756.0 mm2 and 0 holes.
The catalog cannot give the footprint, so it labels the figure: ``+`` and a footnote in
``list``, the words in ``show``, ``area_of`` and ``holes`` null in ``--json``.
"""

from __future__ import annotations

import json
from pathlib import Path

import fixtures_cad as fx
from shared import cli_ok

L_PLATE = [(0, 0), (60, 0), (60, 10), (10, 10), (10, 40), (0, 40)]


def _catalog(tmp_path: Path, capsys) -> Path:
    db = tmp_path / "c.db"
    mesh = fx.write_mesh(fx.prism(L_PLATE, 3.0), tmp_path / "lb.stl")
    cli_ok(capsys, ["catalog", "add", str(mesh), "--catalog", str(db)])
    square = tmp_path / "sq.json"
    square.write_text(json.dumps({"name": "sq", "vertices": [[0, 0], [10, 0], [10, 10], [0, 10]]}))
    cli_ok(capsys, ["catalog", "add", str(square), "--catalog", str(db)])
    return db


def test_list_marks_a_meshs_area_as_its_hulls(tmp_path: Path, capsys) -> None:
    db = _catalog(tmp_path, capsys)
    out = cli_ok(capsys, ["catalog", "list", "--catalog", str(db)]).out
    rows = {
        line.split()[0]: line.split() for line in out.splitlines() if line[:3] in ("lb ", "sq ")
    }
    assert rows["lb"][3:5] == ["1650.0+", "-"]  # its hull; its footprint is 900 mm2
    assert rows["sq"][3:5] == ["100.0", "0"]
    text = " ".join(out.split())
    assert "+ mm2 of a mesh: its convex hull seen from above" in text
    assert "its holes are not known" in text
    listed = {
        p["name"]: p
        for p in json.loads(cli_ok(capsys, ["catalog", "list", "--json", "--catalog", str(db)]).out)
    }
    assert listed["lb"]["area_of"] == "convex hull" and listed["lb"]["holes"] is None
    assert listed["sq"]["area_of"] == "outline" and listed["sq"]["holes"] == 0


def _words(text: str) -> str:
    """The words of a rich table, its rules and wrapping left out."""
    return " ".join(text.replace("│", " ").split())


def test_show_says_a_meshs_area_is_its_hulls(tmp_path: Path, capsys) -> None:
    db = _catalog(tmp_path, capsys)
    out = _words(cli_ok(capsys, ["catalog", "show", "lb", "--catalog", str(db)]).out)
    assert "mm2 of its convex hull seen from above (a mesh:" in out
    assert "0 holes" not in out
    shown = json.loads(
        cli_ok(capsys, ["catalog", "show", "lb", "--json", "--catalog", str(db)]).out
    )
    assert shown["area_of"] == "convex hull" and shown["holes"] is None
    plain = _words(cli_ok(capsys, ["catalog", "show", "sq", "--catalog", str(db)]).out)
    assert "100.000 mm2, 0 holes" in plain
