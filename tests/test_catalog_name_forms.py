"""How the catalog commands read and print part names (docs/catalog.md): ``NAME@REV`` read as
``part analyze`` reads it, names equal under Unicode normalisation are one name, and
``catalog list`` pads its columns by display width."""

from __future__ import annotations

import json
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
