"""catalog import: every bad file named, nothing imported unless --skip-bad (docs/import.md)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def _folder(tmp_path: Path) -> Path:
    d = tmp_path / "drawings"
    d.mkdir()
    shutil.copy(CATALOG / "octagon.json", d / "octagon.json")
    (d / "bad.dxf").write_text("garbage\n")
    return d


def test_a_bad_file_imports_nothing_and_is_named(tmp_path, capsys) -> None:
    d = _folder(tmp_path)
    db = tmp_path / "c.db"
    assert main(["catalog", "import", str(d), "--catalog", str(db)]) == 2
    err = capsys.readouterr().err
    assert "bad.dxf" in err and "--skip-bad" in err and len(err.strip().splitlines()) == 1


def test_skip_bad_imports_the_rest_and_lists_the_skipped(tmp_path, capsys) -> None:
    d = _folder(tmp_path)
    db = tmp_path / "c.db"
    args = ["catalog", "import", str(d), "--catalog", str(db), "--skip-bad", "--json"]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    assert [p["name"] for p in out["parts"]] == ["octagon"]
    assert len(out["skipped"]) == 1 and "bad.dxf" in out["skipped"][0]


def test_an_import_budget_is_an_option(tmp_path, capsys) -> None:
    d = _folder(tmp_path)
    (d / "bad.dxf").unlink()
    db = tmp_path / "c.db"
    assert main(["catalog", "import", str(d), "--catalog", str(db), "--max-loops", "1"]) == 0


def test_catalog_list_fits_80_columns(tmp_path, capsys) -> None:
    db = tmp_path / "c.db"
    assert main(["catalog", "import", str(CATALOG), "--catalog", str(db)]) == 0
    capsys.readouterr()
    assert main(["catalog", "list", "--catalog", str(db)]) == 0
    out = capsys.readouterr().out
    assert "isosceles-right-triangle" in out
    assert max(len(line) for line in out.splitlines()) <= 80
