"""How the catalog commands read and print part names (docs/catalog.md): ``NAME@REV`` read as
``part analyze`` reads it, names equal under Unicode normalisation are one name, and
``catalog list`` pads its columns by display width."""

from __future__ import annotations

import json
import sqlite3
import unicodedata
from pathlib import Path

import pytest
from shared import one_line_error

import feederkit.catalog as cat
from feederkit.cli.app import main
from feederkit.errors import InputError

QUAD = [[0, 0], [3, 0], [2.4, 2], [0.5, 1.6]]
"""A small quadrilateral (mm), as in the review's reproduction."""


def quad_file(path: Path, name: str | None = None, x: float = 2.4) -> Path:
    """An outline file of the quadrilateral (its third vertex at ``x``), ``name`` in it if given."""
    vertices = [QUAD[0], QUAD[1], [x, 2], QUAD[3]]
    data: dict = {"units": "mm", "vertices": vertices}
    if name is not None:
        data["name"] = name
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def cli(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    """Run the command line in process; it must succeed. Its stdout."""
    code = main(list(args))
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


@pytest.fixture
def db(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> str:
    """A catalog holding ``quadrilateral``."""
    path = str(tmp_path / "c.db")
    source = quad_file(tmp_path / "quadrilateral.json")
    cli(capsys, "catalog", "add", str(source), "--catalog", path)
    return path


# NAME@REV with a revision that is no number: the words of part analyze, not "no part named".

BAD_REVISION = "part 'quadrilateral' has no revision '{}' (NAME@REV takes a revision number)"


@pytest.mark.parametrize("rev", ["abc", "-1", ""])
@pytest.mark.parametrize(
    "command",
    [["show"], ["remove"], ["export", "-o", "q.json"]],
    ids=["show", "remove", "export"],
)
def test_catalog_commands_read_name_at_rev_as_part_analyze(db, capsys, tmp_path, command, rev):
    args = ["catalog", command[0], f"quadrilateral@{rev}", *command[1:], "--catalog", db]
    err = one_line_error(capsys, args)
    assert BAD_REVISION.format(rev) in err
    assert "no part named" not in err and "did you mean" not in err
    analyze = one_line_error(capsys, ["part", "analyze", f"quadrilateral@{rev}", "--catalog", db])
    assert BAD_REVISION.format(rev) in analyze  # the same words, from the same parser
    assert cat.get_revision(db, "quadrilateral").revision == 1  # nothing removed


def test_split_revision_is_the_one_reading():
    from feederkit.catalog.model import split_revision

    assert split_revision("clip@2") == ("clip", 2)
    assert split_revision("clip") == ("clip", None)
    assert split_revision("a@b@2") == ("a@b@2", None)  # no valid name before '@': unknown name
    with pytest.raises(InputError, match="numbered from 1"):
        split_revision("clip@0")
    with pytest.raises(InputError, match=r"part 'clip' has no revision 'x2'"):
        split_revision("clip@x2")


# Names equal under Unicode normalisation (NFC, typed on Linux; NFD, a macOS file name) are
# one name: stored in NFC, found in either form, old NFD rows too.

LOOK = "Ünïcode part"
NFC = unicodedata.normalize("NFC", LOOK)
NFD = unicodedata.normalize("NFD", LOOK)


def names(capsys: pytest.CaptureFixture[str], db: str) -> list[str]:
    """The part names ``catalog list --json`` gives."""
    return [
        p["name"] for p in json.loads(cli(capsys, "catalog", "list", "--json", "--catalog", db))
    ]


def test_nfd_and_nfc_names_are_one_name(tmp_path, capsys):
    assert NFC != NFD
    (tmp_path / "nfc").mkdir()
    (tmp_path / "nfd").mkdir()
    quad_file(tmp_path / "nfc" / f"{NFC}.json")
    quad_file(tmp_path / "nfd" / f"{NFD}.json", x=2.5)  # another file, the same-looking name
    db = str(tmp_path / "c.db")
    cli(capsys, "catalog", "import", str(tmp_path / "nfc"), "--catalog", db)
    err = one_line_error(capsys, ["catalog", "import", str(tmp_path / "nfd"), "--catalog", db])
    assert "duplicate name" in err and "--revise" in err
    assert names(capsys, db) == [NFC]
    cli(capsys, "catalog", "import", str(tmp_path / "nfd"), "--revise", "--catalog", db)
    assert names(capsys, db) == [NFC]
    assert cat.get_revision(db, NFD).revision == 2
    # --name in NFD is stored in NFC, and refused as a duplicate of the part.
    other = quad_file(tmp_path / "other.json", x=2.6)
    err = one_line_error(capsys, ["catalog", "add", str(other), "--name", NFD, "--catalog", db])
    assert "duplicate name" in err
    cli(capsys, "catalog", "add", str(other), "--name", f"{NFD} 2", "--catalog", db)
    assert names(capsys, db) == [NFC, f"{NFC} 2"]


def test_a_part_is_found_however_its_name_was_typed(tmp_path, capsys):
    db = str(tmp_path / "c.db")
    source = quad_file(tmp_path / "q.json")
    cli(capsys, "catalog", "add", str(source), "--name", NFC, "--catalog", db)
    other = quad_file(tmp_path / "r.json", x=2.7)
    cli(capsys, "catalog", "add", str(other), "--name", "r", "--catalog", db)
    shown = json.loads(cli(capsys, "catalog", "show", NFD, "--json", "--catalog", db))
    assert shown["name"] == NFC and shown["revisions"][0]["revision"] == 1
    cli(capsys, "catalog", "show", f"{NFD}@1", "--catalog", db)
    cli(capsys, "catalog", "export", NFD, "-o", str(tmp_path / "out.json"), "--catalog", db)
    analyzed = json.loads(cli(capsys, "part", "analyze", NFD, "--json", "--catalog", db))
    assert analyzed[0]["name"] == NFC
    # --mix finds it; the changeover stores the part, which show then lists as its user.
    compile_mix = ["changeover", "compile", "mx", "--mix", f"{NFD},r", "--tolerance", "0.2"]
    code = main([*compile_mix, "--catalog", db])
    capsys.readouterr()
    assert code in (0, 1)
    assert cat.get_changeover(db, "mx").info.parts == ((NFC, 1), ("r", 1))
    shown = json.loads(cli(capsys, "catalog", "show", NFD, "--json", "--catalog", db))
    assert shown["changeovers"] == ["mx"]
    cli(capsys, "catalog", "remove", NFD, "--force", "--catalog", db)
    assert names(capsys, db) == ["r"]


def test_names_stored_in_nfd_by_older_versions_are_still_found(tmp_path, capsys):
    db = str(tmp_path / "c.db")
    source = quad_file(tmp_path / "q.json")
    cli(capsys, "catalog", "add", str(source), "--name", NFC, "--catalog", db)
    with sqlite3.connect(db) as conn:  # as an older feederkit stored a macOS file's name
        conn.execute("UPDATE parts SET name = ?", (NFD,))
    assert cat.get_revision(db, NFC).name == NFD
    assert json.loads(cli(capsys, "catalog", "show", NFC, "--json", "--catalog", db))["name"] == NFD
    # The same file again is that part (unchanged), another file under the name a duplicate.
    again = ["catalog", "add", str(source), "--name", NFC, "--json", "--catalog", db]
    out = json.loads(cli(capsys, *again))
    assert out[0]["status"] == "unchanged"
    other = quad_file(tmp_path / "other.json", x=2.6)
    err = one_line_error(capsys, ["catalog", "add", str(other), "--name", NFC, "--catalog", db])
    assert "duplicate name" in err
    # Both forms stored by an older version: each is found by its own form.
    cli(capsys, "catalog", "add", str(other), "--name", "tmp", "--catalog", db)
    with sqlite3.connect(db) as conn:
        conn.execute("UPDATE parts SET name = ? WHERE name = 'tmp'", (NFC,))
    assert cat.get_revision(db, NFC).source_path == str(other.resolve())
    assert cat.get_revision(db, NFD).source_path == str(source.resolve())


# catalog list pads by terminal columns: wide characters take 2, combining marks 0.

WIDE = ("日本語パーツ", "ａｂ")
"""CJK and full-width Latin names: two columns a character."""


def test_display_width():
    from feederkit.cli.catalog import display_width

    assert [display_width(n) for n in (*WIDE, NFC, NFD, "t-clip")] == [12, 4, 12, 12, 6]


def columns(text: str) -> int:
    """The test's own count of terminal columns (wide 2, combining 0, else 1)."""
    return sum(
        0 if unicodedata.combining(ch) else 2 if unicodedata.east_asian_width(ch) in "WF" else 1
        for ch in text
    )


def test_list_columns_line_up_with_wide_and_combining_names(tmp_path, capsys):
    db = str(tmp_path / "c.db")
    source = quad_file(tmp_path / "q.json")
    for name in (*WIDE, "nfd", "t-clip"):
        cli(capsys, "catalog", "add", str(source), "--name", name, "--catalog", db)
    with sqlite3.connect(db) as conn:  # an NFD name, as older versions stored it
        conn.execute("UPDATE parts SET name = ? WHERE name = 'nfd'", (NFD,))
    lines = cli(capsys, "catalog", "list", "--catalog", db).splitlines()
    rows = [line for line in lines if " outline " in line]
    assert len(rows) == 4
    assert any(NFD in row for row in rows) and all(any(n in r for r in rows) for n in WIDE)
    starts = {columns(row[: row.index(" outline ")]) for row in rows}
    assert starts == {columns(lines[0][: lines[0].index(" kind")])}, rows  # one column
    assert {columns(row) for row in rows} == {len(lines[1])}  # as wide as the rule
