"""``--all-parts`` keeps every separate part of a drawing, or says it cannot (sources.py)."""

from __future__ import annotations

import json

import fixtures_cad as fx
import pytest

from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.importers import ImportOptions
from feederkit.loading import load_parts
from feederkit.sources import load_part_with_warnings, load_parts_with_warnings


def test_every_part_of_a_drawing_is_loaded(tmp_path):
    two = str(fx.write_two_parts(tmp_path / "two.dxf"))
    every = load_parts_with_warnings(two, options=ImportOptions(all_parts=True))
    assert [x.part.name for x in every] == ["two", "two-2"]
    assert [x.part.name for x in load_parts_with_warnings(two)] == ["two"]
    assert load_parts([two], options=ImportOptions(all_parts=True)).names == ["two", "two-2"]


def test_a_single_outline_command_refuses_several_parts(tmp_path):
    two = str(fx.write_two_parts(tmp_path / "two.dxf"))
    with pytest.raises(InputError, match="holds 2 separate parts"):
        load_part_with_warnings(two, options=ImportOptions(all_parts=True))
    assert load_part_with_warnings(two).part.name == "two"


def test_part_analyze_lists_every_part_with_all_parts(tmp_path, capsys):
    two = str(fx.write_two_parts(tmp_path / "two.dxf"))
    assert main(["part", "analyze", two, "--all-parts", "--json"]) == 0
    assert [p["name"] for p in json.loads(capsys.readouterr().out)] == ["two", "two-2"]
    assert main(["lookalike", two, "--all-parts", "--keep", "push"]) == 2
    err = capsys.readouterr().err
    assert "holds 2 separate parts" in err and len(err.strip().splitlines()) == 1


def test_plan_takes_the_import_options(tmp_path, capsys):
    two = str(fx.write_two_parts(tmp_path / "two.dxf"))
    out = tmp_path / "p.json"
    code = main(["plan", two, "--all-parts", "--tolerance", "0.5", "-o", str(out), "--json"])
    assert code in (0, 1), capsys.readouterr().err
    assert {p["name"] for p in json.loads(out.read_text())["parts"]} == {"two", "two-2"}
    assert main(["plan", two, "--units", "furlongs"]) == 2
    assert "unknown unit" in capsys.readouterr().err
