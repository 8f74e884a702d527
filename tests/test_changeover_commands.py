"""``changeover compile|remove|export|report|show|list`` (docs/changeovers.md): stored and written
together, exported byte for byte, reported with the pairs no plan can tell apart, and a
warning when a part has a newer revision than the one the changeover is made for."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from shared import one_line_error

from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
PARTS = ("isosceles-right-triangle", "octagon", "quadrilateral", "rectangle-2x1")
FIG27 = ["changeover", "compile", "fig27", "--mix", "isosceles-right-triangle,octagon"]


def ok(capsys, args: list[str], code: int = 0):
    rc = main(args)
    captured = capsys.readouterr()
    assert rc == code, captured.err
    return captured


@pytest.fixture()
def db(tmp_path, capsys) -> Path:
    """A catalog with four sample parts and a push-diameter look-alike of the quadrilateral."""
    folder = tmp_path / "parts"
    folder.mkdir()
    for name in PARTS:
        shutil.copy(CATALOG / f"{name}.json", folder)
    path = tmp_path / "parts.db"
    ok(capsys, ["catalog", "init", "--catalog", str(path)])
    ok(capsys, ["catalog", "import", str(folder), "--catalog", str(path)])
    twin = tmp_path / "quad-twin.json"
    src = str(folder / "quadrilateral.json")
    ok(
        capsys,
        ["lookalike", src, "--keep", "push-diameter", "--name", "quad-twin", "-o", str(twin)],
    )
    ok(capsys, ["catalog", "add", str(twin), "--catalog", str(path)])
    return path


def test_export_writes_the_stored_plan_byte_for_byte(db, tmp_path, capsys):
    compiled = tmp_path / "compiled.json"
    ok(capsys, [*FIG27, "--tolerance", "0.01", "-o", str(compiled), "--catalog", str(db)])
    exported = tmp_path / "exported.json"
    cap = ok(capsys, ["changeover", "export", "fig27", "-o", str(exported), "--catalog", str(db)])
    assert exported.read_bytes() == compiled.read_bytes()
    assert str(exported) in cap.out
    cap = ok(
        capsys,
        ["changeover", "export", "fig27", "-o", str(exported), "--json", "--catalog", str(db)],
    )
    assert json.loads(cap.out)["up_to_date"] is True
    assert exported.read_bytes() == compiled.read_bytes()
    ok(capsys, ["run", str(exported), "--all"])
    err = one_line_error(
        capsys, ["changeover", "export", "nope", "-o", str(exported), "--catalog", str(db)]
    )
    assert "nope" in err


@pytest.mark.slow
def test_report_names_the_pair_no_plan_can_tell_apart(db, tmp_path, capsys):
    # The ideal model: the report's wiring is under test, not strong planning of look-alikes.
    args = ["changeover", "compile", "twins", "--mix", "quadrilateral,quad-twin"]
    ok(capsys, [*args, "--tolerance", "0.01", "--rotation-error", "0", "--catalog", str(db)], 1)
    html = tmp_path / "twins.html"
    ok(capsys, ["changeover", "report", "twins", "-o", str(html), "--catalog", str(db)])
    text = html.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>")
    assert "quad-twin" in text and "Lemma 8" in text


def test_report_is_given_the_stored_parts_and_the_pair(db, tmp_path, capsys, monkeypatch):
    import feederkit.reports

    def fake_report(plan, *, unrecognizable, outlines, design=None, cautions=(), **_kw):
        assert design is not None and design["sensor_model"] == "tolerance"
        pairs = sorted(sorted((u["part_a"], u["part_b"])) for u in unrecognizable)
        return f"<p>{pairs} {sorted(outlines)}</p>"

    monkeypatch.setattr(feederkit.reports, "render_report", fake_report)
    # The ideal model: the report's wiring is under test, not strong planning of look-alikes.
    args = ["changeover", "compile", "twins", "--mix", "quadrilateral,quad-twin"]
    ok(capsys, [*args, "--tolerance", "0.01", "--rotation-error", "0", "--catalog", str(db)], 1)
    html = tmp_path / "twins.html"
    ok(capsys, ["changeover", "report", "twins", "-o", str(html), "--catalog", str(db)])
    # Every landing is planned: the look-alikes are a pair on either side (PART/LANDING).
    pairs = "[['quad-twin/down', 'quadrilateral/down'], ['quad-twin/up', 'quadrilateral/up']]"
    outlines = "['quad-twin/down', 'quad-twin/up', 'quadrilateral/down', 'quadrilateral/up']"
    assert html.read_text() == f"<p>{pairs} {outlines}</p>"
    # Face up only (--landings up), the pair and the outlines of the parts as drawn.
    ok(
        capsys,
        [
            *args,
            "--landings",
            "up",
            "--tolerance",
            "0.01",
            "--rotation-error",
            "0",
            "--replace",
            "--catalog",
            str(db),
        ],
        1,
    )
    ok(capsys, ["changeover", "report", "twins", "-o", str(html), "--catalog", str(db)])
    assert html.read_text() == "<p>[['quad-twin/up', 'quadrilateral/up']] " + (
        "['quad-twin/up', 'quadrilateral/up']</p>"
    )
    one_line_error(capsys, ["changeover", "report", "nope", "-o", str(html), "--catalog", str(db)])


def test_a_design_past_its_limit_is_cut_short_in_the_report(db, tmp_path, capsys, monkeypatch):
    import feederkit.design.sensor
    import feederkit.reports

    got: list = []

    def fake_report(plan, *, unrecognizable, outlines, design=None, cautions=(), **_kw):
        got.append(design)
        return "<p>report</p>"

    ok(capsys, [*FIG27, "--tolerance", "0.01", "--catalog", str(db)])
    monkeypatch.setattr(feederkit.reports, "render_report", fake_report)
    monkeypatch.setattr(feederkit.design.sensor, "REPORT_DESIGN_LIMIT_S", 1e-9)
    html = tmp_path / "fig27.html"
    cap = ok(capsys, ["changeover", "report", "fig27", "-o", str(html), "--catalog", str(db)])
    assert html.read_text() == "<p>report</p>"
    assert got[0]["complete"] is False and "time limit of 1e-09 s" in got[0]["stopped"]
    (line,) = [w for w in cap.err.splitlines() if "sensor design" in w]
    assert line.startswith("warning: ") and "1e-09 s" in line and "--time-limit" in line
    monkeypatch.setattr(feederkit.design.sensor, "REPORT_DESIGN_LIMIT_S", 60.0)
    ok(capsys, ["changeover", "report", "fig27", "-o", str(html), "--catalog", str(db)])
    assert got[1] is not None and got[1]["sensor_model"] == "tolerance"
    assert got[1]["complete"] is True


def test_remove_deletes_one_changeover_and_keeps_the_parts(db, capsys):
    ok(capsys, [*FIG27, "--tolerance", "0.01", "--catalog", str(db)])
    cap = ok(capsys, ["changeover", "remove", "fig27", "--catalog", str(db)])
    assert "removed" in cap.out
    assert json.loads(ok(capsys, ["changeover", "list", "--json", "--catalog", str(db)]).out) == []
    one_line_error(capsys, ["changeover", "show", "fig27", "--catalog", str(db)])
    one_line_error(capsys, ["changeover", "remove", "fig27", "--catalog", str(db)])
    assert "octagon" in ok(capsys, ["catalog", "list", "--catalog", str(db)]).out


def test_a_newer_part_revision_is_warned_about(db, tmp_path, capsys):
    ok(capsys, [*FIG27, "--tolerance", "0.01", "--catalog", str(db)])
    changed = tmp_path / "octagon.json"
    data = json.loads((CATALOG / "octagon.json").read_text())
    data["vertices"][0] = [data["vertices"][0][0] * 1.1, data["vertices"][0][1]]
    changed.write_text(json.dumps(data))
    ok(capsys, ["catalog", "add", str(changed), "--revise", "--catalog", str(db)])
    cap = ok(capsys, ["changeover", "show", "fig27", "--json", "--catalog", str(db)])
    shown = json.loads(cap.out)
    assert "revision 1" in cap.err and "latest is 2" in cap.err
    assert len(shown["warnings"]) == 1 and "octagon" in shown["warnings"][0]
    listed = json.loads(ok(capsys, ["changeover", "list", "--json", "--catalog", str(db)]).out)
    assert listed[0]["warnings"] == shown["warnings"]
    out = tmp_path / "e.json"
    # A stale export is a result to act on (exit 1), the file still written.
    cap = ok(capsys, ["changeover", "export", "fig27", "-o", str(out), "--catalog", str(db)], 1)
    assert "latest is 2" in cap.err and out.is_file()
    cap = ok(
        capsys,
        ["changeover", "export", "fig27", "-o", str(out), "--json", "--catalog", str(db)],
        1,
    )
    exported = json.loads(cap.out)  # stdout is the JSON alone, the warning on stderr
    assert exported["up_to_date"] is False and exported["warnings"] == shown["warnings"]
    assert (
        exported["output"] == str(out) and {"name": "octagon", "revision": 1} in (exported["parts"])
    )
    # So is a stale report: the page says it first, the file still written.
    page = tmp_path / "r.html"
    cap = ok(capsys, ["changeover", "report", "fig27", "-o", str(page), "--catalog", str(db)], 1)
    assert "out of date" in cap.err and page.is_file()
    html = page.read_text(encoding="utf-8")
    assert 'id="caution-0"' in html and "latest is 2" in html
    # Compiling against the old revision on purpose says so, too.
    pinned = ["changeover", "compile", "old", "--mix", "octagon@1,rectangle-2x1"]
    cap = ok(capsys, [*pinned, "--tolerance", "0.01", "--json", "--catalog", str(db)])
    assert any("latest is 2" in w for w in json.loads(cap.out)["warnings"])


def test_a_revision_that_puts_the_same_file_back_keeps_the_changeover_up_to_date(
    db, tmp_path, capsys
):
    # octagon@3 is the file of octagon@1 again: the changeover made for @1 was called out of
    # date (export exit 1), and a script recompiling on exit 1 compiled for nothing.
    ok(capsys, [*FIG27, "--tolerance", "0.01", "--catalog", str(db)])
    original = tmp_path / "parts" / "octagon.json"
    kept = original.read_bytes()
    data = json.loads(kept)
    data["vertices"][0] = [data["vertices"][0][0] * 1.1, data["vertices"][0][1]]
    original.write_text(json.dumps(data))
    ok(capsys, ["catalog", "add", str(original), "--revise", "--catalog", str(db)])
    shown = json.loads(
        ok(capsys, ["changeover", "show", "fig27", "--json", "--catalog", str(db)]).out
    )
    assert any("latest is 2" in w for w in shown["warnings"])  # another file: out of date
    original.write_bytes(kept)
    ok(capsys, ["catalog", "add", str(original), "--revise", "--catalog", str(db)])
    out = tmp_path / "e.json"
    cap = ok(
        capsys, ["changeover", "export", "fig27", "-o", str(out), "--json", "--catalog", str(db)]
    )
    exported = json.loads(cap.out)
    assert exported["up_to_date"] is True and exported["warnings"] == []


def test_compile_stores_nothing_when_its_files_cannot_be_written(db, tmp_path, capsys, monkeypatch):
    import feederkit.cli.common

    monkeypatch.setattr(feederkit.cli.common, "report_html", lambda *a: "<!DOCTYPE html>")
    plan = tmp_path / "fig27.json"
    bad_report = tmp_path / "no" / "such" / "r.html"
    args = [*FIG27, "--tolerance", "0.01", "-o", str(plan), "--report", str(bad_report)]
    err = one_line_error(capsys, [*args, "--catalog", str(db)])
    assert "r.html" in err
    assert not plan.exists()
    assert json.loads(ok(capsys, ["changeover", "list", "--json", "--catalog", str(db)]).out) == []
    assert list(tmp_path.glob(".fig27.json.*")) == []  # no temporary left behind


def test_an_existing_name_says_replace(db, capsys):
    ok(capsys, [*FIG27, "--tolerance", "0.01", "--catalog", str(db)])
    err = one_line_error(capsys, [*FIG27, "--tolerance", "0.01", "--catalog", str(db)])
    assert "--replace" in err


def test_compile_json_has_warnings_and_a_file_member_is_refused(db, tmp_path, capsys):
    cap = ok(capsys, [*FIG27, "--tolerance", "0.01", "--json", "--catalog", str(db)])
    assert json.loads(cap.out)["warnings"] == []
    src = str(CATALOG / "octagon.json")
    args = ["changeover", "compile", "f", "--mix", f"{src},rectangle-2x1", "--catalog", str(db)]
    assert "catalog part" in one_line_error(capsys, args)


def test_no_output_may_be_the_catalog_itself(db, tmp_path, capsys):
    before = db.read_bytes()
    for args in (
        [*FIG27, "--tolerance", "0.01", "-o", str(db)],
        ["plan", "octagon", "--tolerance", "0.01", "-o", str(db)],
        ["plan", "octagon", "--tolerance", "0.01", "--report", f"{db}-wal.html", "-o", f"{db}-wal"],
    ):
        err = one_line_error(capsys, [*args, "--catalog", str(db)])
        assert "SQLite database" in err and "a feederkit catalog?" in err
    ok(capsys, [*FIG27, "--tolerance", "0.01", "--catalog", str(db)])
    err = one_line_error(
        capsys, ["changeover", "export", "fig27", "-o", str(db), "--catalog", str(db)]
    )
    assert "over an SQLite database" in err
    listed = json.loads(ok(capsys, ["catalog", "list", "--json", "--catalog", str(db)]).out)
    assert len(listed) == len(PARTS) + 1 and db.read_bytes() != b""
    assert before[:16] == db.read_bytes()[:16] == b"SQLite format 3\x00"


def test_a_list_option_given_twice_is_refused(db, capsys):
    args = ["changeover", "compile", "x", "--mix", "octagon", "--mix=rectangle-2x1"]
    err = one_line_error(capsys, [*args, "--tolerance", "0.01", "--catalog", str(db)])
    assert "--mix given twice" in err and "comma-separated" in err
    err = one_line_error(capsys, ["design", "sensor", "--mix", "a", "--mix", "b"])
    assert "--mix given twice" in err
    assert json.loads(ok(capsys, ["changeover", "list", "--json", "--catalog", str(db)]).out) == []


def test_every_input_is_checked_before_an_existing_name_is_refused(db, capsys):
    ok(capsys, [*FIG27, "--tolerance", "0.01", "--catalog", str(db)])
    for extra, said in (
        (["--shape-tolerance", "50"], "shape tolerance 50 mm"),
        (["--landings", "down"], "has no landing down"),
    ):
        err = one_line_error(capsys, [*FIG27, "--tolerance", "0.01", *extra, "--catalog", str(db)])
        assert said in err and "already exists" not in err


def test_show_names_the_declared_uncertainty(db, capsys):
    ok(capsys, [*FIG27, "--tolerance", "0.01", "--rotation-error", "0.5", "--catalog", str(db)])
    out = ok(capsys, ["changeover", "show", "fig27", "--catalog", str(db)]).out
    assert "uncertainty: rotation error ±0.5°, shape tolerance 0 mm" in out
    data = json.loads(
        ok(capsys, ["changeover", "show", "fig27", "--json", "--catalog", str(db)]).out
    )
    assert data["uncertainty"]["rotation_error_deg"] == pytest.approx(0.5)
    assert data["uncertainty_declared"] is True


def test_run_warns_of_a_stored_tolerance_the_plan_does_not_declare(db, tmp_path, capsys):
    ok(capsys, [*FIG27, "--tolerance", "0.01", "--catalog", str(db)])
    plan = tmp_path / "fig27.json"
    ok(capsys, ["changeover", "export", "fig27", "-o", str(plan), "--catalog", str(db)])
    run = ["run", str(plan), "octagon", "--all", "--json", "--catalog", str(db)]
    assert json.loads(ok(capsys, run).out)["warnings"] == []
    src = str(CATALOG / "octagon.json")
    add = ["catalog", "add", src, "--revise", "--shape-tolerance", "0.005"]
    ok(capsys, [*add, "--catalog", str(db)])
    warnings = json.loads(ok(capsys, run).out)["warnings"]
    assert any("octagon r2 stores a shape tolerance of 0.005 mm" in w for w in warnings)
    pinned = ["run", str(plan), "octagon@1", "--all", "--json", "--catalog", str(db)]
    assert json.loads(ok(capsys, pinned).out)["warnings"] == []
