"""``catalog export`` names what the outline file leaves behind: a revision's side
probability and its stored shape and COM tolerances, with the flags that store them again
(docs/catalog.md, ``export``). A round trip without them lands the part 0.5/0.5 and plans it
at tolerance 0."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import feederkit.catalog as cat
from feederkit.cli.app import main
from feederkit.outline import make_outline, save_outline_json

ELL = [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)]
"""An L plate, not mirror-symmetric: it lands up and down."""


@pytest.fixture
def ell(tmp_path: Path) -> Path:
    path = tmp_path / "ell.json"
    save_outline_json(make_outline("ell", ELL), path)
    return path


def cli(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[str, str]:
    """Run the command line in process; it must succeed. Its stdout and stderr."""
    code = main(list(args))
    out, err = capsys.readouterr()
    assert code == 0, err
    return out, err


def test_export_warns_of_side_probability_and_tolerances(tmp_path, ell, capsys):
    db = str(tmp_path / "a.db")
    cli(capsys, "catalog", "add", str(ell), "--side-probability", "0.8",
        "--shape-tolerance", "0.05", "--com-tolerance", "0.1", "--catalog", db)  # fmt: skip
    out_file = tmp_path / "out" / "ell.json"
    out_file.parent.mkdir()
    out, _ = cli(capsys, "catalog", "export", "ell", "-o", str(out_file), "--json", "--catalog", db)
    [warning] = json.loads(out)["warnings"]
    assert "side probability 0.8" in warning
    assert "shape tolerance 0.05 mm" in warning and "COM tolerance 0.1 mm" in warning
    assert "--side-probability 0.8 --shape-tolerance 0.05 --com-tolerance 0.1" in warning
    _, err = cli(capsys, "catalog", "export", "ell", "-o", str(out_file), "--catalog", db)
    assert err.startswith("warning: ") and "--side-probability 0.8" in err

    # The flags the warning gives make the round trip store what the catalog stored.
    flags = warning.split("give ", 1)[1].split(" when ", 1)[0].split()
    db2 = str(tmp_path / "b.db")
    cli(capsys, "catalog", "import", str(out_file.parent), *flags, "--catalog", db2)
    before, after = cat.get_revision(db, "ell"), cat.get_revision(db2, "ell")
    assert [(x.name, x.probability) for x in after.landings] == [
        (x.name, x.probability) for x in before.landings
    ]
    assert (after.shape_tolerance_mm, after.com_tolerance_mm) == (0.05, 0.1)


def test_export_names_only_what_is_stored(tmp_path, ell, capsys):
    db = str(tmp_path / "a.db")
    out_file = str(tmp_path / "x.json")
    cli(capsys, "catalog", "add", str(ell), "--com-tolerance", "0.25", "--catalog", db)
    out, _ = cli(capsys, "catalog", "export", "ell", "-o", out_file, "--json", "--catalog", db)
    [warning] = json.loads(out)["warnings"]
    assert "give --com-tolerance 0.25 when" in warning
    assert "side probability" not in warning and "shape tolerance" not in warning
    # Nothing but the defaults: nothing to say.
    save_outline_json(make_outline("plain", ELL), tmp_path / "plain.json")
    cli(capsys, "catalog", "add", str(tmp_path / "plain.json"), "--catalog", db)
    out, _ = cli(capsys, "catalog", "export", "plain", "-o", out_file, "--json", "--catalog", db)
    assert json.loads(out)["warnings"] == []
