"""Folder import (catalog import DIR): which files are sources, every bad file named, --skip-bad."""

from __future__ import annotations

from pathlib import Path

import fixtures_cad as fx
import pytest

from feederkit.catalog import import_directory
from feederkit.catalog.bulk import is_outline_file, source_files
from feederkit.errors import InputError

SQUARE = '{"name": "%s", "vertices": [[0, 0], [10, 0], [10, 10], [0, 10]]}'


def folder(tmp_path: Path) -> Path:
    d = tmp_path / "parts"
    (d / "sub").mkdir(parents=True)
    (d / "a.json").write_text(SQUARE % "a")
    fx.write_plate(d / "sub" / "plate.dxf")
    (d / "settings.json").write_text('{"theme": "dark"}')  # JSON, but not an outline
    (d / "package.json").write_text("[1, 2, 3]")
    (d / "readme.txt").write_text("parts")
    return d


def test_only_sources_are_read_and_json_by_content(tmp_path):
    d = folder(tmp_path)
    found, ignored = source_files(d)
    assert sorted(p.name for p in found) == ["a.json", "plate.dxf"]
    assert sorted(p.name for p in ignored) == ["package.json", "readme.txt", "settings.json"]
    (d / "broken.json").write_text('{"vertices": [[0, 0], [1')  # meant as an outline: reported
    assert is_outline_file(d / "broken.json")


def test_every_bad_file_is_named_with_its_path_and_nothing_imported(tmp_path):
    d = folder(tmp_path)
    (d / "sub" / "broken.dxf").write_text("0\nSECTION\n2\nENTITIES\n0\nLINE\n")
    (d / "empty.stl").write_bytes(b"")
    db = tmp_path / "c.db"
    with pytest.raises(InputError) as info:
        import_directory(db, d)
    message = str(info.value)
    assert "2 of 4 files" in message and "--skip-bad" in message
    assert str(d / "sub" / "broken.dxf") in message and str(d / "empty.stl") in message
    assert "\n" not in message
    result = import_directory(db, d, skip_bad=True)
    assert sorted(o.name for o in result.outcomes) == ["a", "plate"]
    assert len(result.bad) == 2 and all(str(d) in b for b in result.bad)
