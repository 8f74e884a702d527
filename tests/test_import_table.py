"""The ``catalog import`` summary keeps part and file names whole at 80 columns
(docs/catalog.md): headers wrap between words; when even that leaves no room for the names,
the summary is plain columns, one line a part."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

NAMES = ("chamfer-plate-cb", "flat-washer", "l-bracket-r3", "mini-bracket", "slotted-link")
"""The part names an 80-column table once broke in the middle (``chamfer-plate-c`` / ``b``)."""


def _import_at_80_columns(folder: Path, db: Path) -> subprocess.CompletedProcess[str]:
    """``feederkit catalog import FOLDER`` in a process of its own, 80 columns wide."""
    code = "import sys; from feederkit.cli.app import main; sys.exit(main(sys.argv[1:]))"
    env = {**os.environ, "COLUMNS": "80"}
    args = ["catalog", "import", str(folder), "--catalog", str(db)]
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, env=env, check=False
    )


def _plates(folder: Path, names: tuple[str, ...]) -> None:
    """An outline file per name (``NAME.json``): plates of different sizes, so that none is
    a duplicate of another."""
    folder.mkdir()
    for k, name in enumerate(names):
        w, h = 20 + 3 * k, 11 + k
        outline = {"name": name, "vertices": [[0, 0], [w, 0], [w, h], [0.4 * w, h + 4], [0, h]]}
        (folder / f"{name}.json").write_text(json.dumps(outline))


def _row_of(lines: list[str], name: str) -> str:
    (row,) = [line for line in lines if line.split() and line.split()[0] == name]
    return row


def test_names_are_whole_in_the_import_table_at_80_columns(tmp_path: Path) -> None:
    folder = tmp_path / "parts"
    _plates(folder, NAMES)
    db = tmp_path / "c.db"
    for status in ("added", "unchanged"):  # "unchanged" is the widest status
        done = _import_at_80_columns(folder, db)
        assert done.returncode == 0, done.stderr
        lines = done.stdout.splitlines()
        assert max(len(line) for line in lines) <= 80, done.stdout
        assert "catalog import" in lines[0]  # the table, not the plain columns
        for name in NAMES:
            row = _row_of(lines, name)
            assert f"{name}.json" in row.split() and status in row.split(), done.stdout
        assert "orientable" in done.stdout and "(ideal)" in done.stdout


def test_names_too_long_for_a_table_give_plain_columns(tmp_path: Path) -> None:
    long = (
        "left-hand-mounting-bracket-for-the-led-array-rev-b",
        "right-hand-mounting-bracket-for-the-led-array-rev-b",
    )
    folder = tmp_path / "parts"
    _plates(folder, long)
    done = _import_at_80_columns(folder, tmp_path / "c.db")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].split() == [
        "part",
        "rev",
        "status",
        "orientable",
        "(ideal)",
        "warnings",
        "file",
    ]
    for name in long:
        assert _row_of(lines, name).split()[-1] == f"{name}.json"
    assert "…" not in done.stdout
