"""``feederkit demo``, the main job: the pipeline (:func:`feederkit.demo.run_demo`) on a few
sample parts, fast, and the whole bundled catalog through the command line (slow)."""

from __future__ import annotations

import contextlib
import io
import json
import shutil
from pathlib import Path

import pytest

from feederkit.cli.app import main
from feederkit.demo import DemoResult, run_demo
from feederkit.errors import InputError
from feederkit.plans.readplan import read_plan
from feederkit.plans.verify import check_plan

ROOT = Path(__file__).resolve().parents[1]
FEW = ("isosceles-right-triangle", "octagon", "quadrilateral", "rectangle-2x1")


@pytest.fixture(scope="module")
def few(tmp_path_factory: pytest.TempPathFactory) -> DemoResult:
    """The demo pipeline on four sample parts (the paper's mix and the look-alike's)."""
    folder = tmp_path_factory.mktemp("parts")
    for name in FEW:
        shutil.copy(ROOT / "catalog" / f"{name}.json", folder)
    return run_demo(folder, tmp_path_factory.mktemp("out"), reports=False)


def test_pipeline_plans_every_part_both_ways(few: DemoResult) -> None:
    assert [p.name for p in few.plans] == sorted(FEW)
    for p in few.plans:
        assert p.sensed["stats"]["length"] <= p.sensorless["stats"]["length"]
        assert p.landing == "up" and p.to_dict()["landing"] == "up"
        for f in p.files:
            check_plan(read_plan(f))
            # One landing planned, and the file says which (design.md, "Landings").
            data = json.loads(f.read_text())
            assert [x.get("landing") for x in data["parts"]] == ["up"]
    # The regular octagon's states share one diameter: no sensor is to blame for that.
    assert {p.name: p.warnings for p in few.plans}["octagon"] == ()


def test_pipeline_compiles_the_papers_changeover(few: DemoResult) -> None:
    by_name = {c.name: c for c in few.changeovers}
    fig27 = by_name["fig27-triangle-octagon"]
    assert fig27.compiled.plan["stats"]["length"] == 2
    assert fig27.compiled.witnesses == () and not fig27.lookalike


def test_pipeline_shows_a_lookalike_pair_no_plan_can_tell_apart(few: DemoResult) -> None:
    pair = {c.name: c for c in few.changeovers}["lookalike-pair"]
    assert pair.lookalike
    # Over every landing: the look-alike is one on either side, the rectangle is told apart.
    sides = [("quadrilateral/up", "quadrilateral-twin/up")]
    sides.append(("quadrilateral/down", "quadrilateral-twin/down"))
    assert [(w.part_a, w.part_b) for w in pair.compiled.witnesses] == sides
    assert pair.compiled.lumped == sides
    assert all("Lemma 8" in w.reason for w in pair.compiled.witnesses)
    summary = pair.to_dict()
    assert summary["unrecognizable_pairs"] and summary["lookalike"] is True
    assert len(summary["landings"]) == 6 and summary["rejected"] == []
    check_plan(read_plan(pair.plan_path))


def test_pipeline_plans_the_papers_shapes_face_up(few: DemoResult) -> None:
    shapes = {c.name: c for c in few.changeovers}["paper-shapes"]
    assert shapes.landings_planned == ("up",)
    assert {r["landing"] for r in shapes.landings} == {"up"}
    assert shapes.compiled.witnesses == () and shapes.rejected_share == 0.0


@pytest.fixture(scope="module")
def feeder(tmp_path_factory: pytest.TempPathFactory) -> DemoResult:
    """The demo pipeline on two feeder parts: the chiral L bracket and the symmetric T clip."""
    folder = tmp_path_factory.mktemp("feeder")
    for name in ("l-bracket", "t-clip"):
        shutil.copy(ROOT / "catalog" / f"{name}.json", folder)
    return run_demo(folder, tmp_path_factory.mktemp("out"), reports=False)


def test_feeder_parts_are_planned_over_every_landing_face_down_rejected(
    feeder: DemoResult, capsys
) -> None:
    (c,) = feeder.changeovers
    assert c.name == "feeder-parts" and c.note is None
    assert [(r["part"], r["landing"], r["accept"]) for r in c.landings] == [
        ("l-bracket", "up", True),
        ("l-bracket", "down", False),
        ("t-clip", "up", True),
    ]
    assert c.compiled.rejected == {"l-bracket/down"}
    assert c.rejected_share == pytest.approx(0.25)
    summary = c.to_dict()
    assert summary["rejected"] == ["l-bracket/down"] and summary["unrecognizable_pairs"] == []
    plan = read_plan(c.plan_path)
    for leaf in plan.leaves():
        assert leaf.reject == all(e.landing == "down" for e in leaf.results)
    assert main(["run", str(c.plan_path), "--all"]) == 0
    assert "reject" in capsys.readouterr().out


def test_feeder_changeover_is_printed_with_its_rejects(feeder: DemoResult) -> None:
    from rich.console import Console

    from feederkit.cli.demo import print_changeover

    out = Console(width=200, record=True, file=io.StringIO())
    print_changeover(out, feeder.changeovers[0])
    text = out.export_text()
    assert "l-bracket/down 25 % rejected" in text
    assert "1 rejected (25 % of the parts end in a reject result" in text


def test_an_accept_list_no_plan_can_keep_accepts_every_landing(tmp_path: Path, monkeypatch):
    import feederkit.demo
    from feederkit.catalog import add_outline, open_catalog
    from feederkit.demo import DemoMix, compile_demo_changeover
    from feederkit.errors import PlanningError
    from feederkit.sources import load_part

    real = feederkit.demo.compile_changeover

    def refuse_rejects(*args, accept=None, **kwargs):
        if accept is not None:
            raise PlanningError("l-bracket (up) is accepted and l-bracket (down) rejected")
        return real(*args, accept=accept, **kwargs)

    monkeypatch.setattr(feederkit.demo, "compile_changeover", refuse_rejects)
    catalog = tmp_path / "demo.db"
    open_catalog(catalog, create=True).close()
    for name in ("l-bracket", "t-clip"):
        add_outline(catalog, load_part(str(ROOT / "catalog" / f"{name}.json")).outline, name=name)
    mix = DemoMix("feeder-parts", ("l-bracket", "t-clip"), accept=("up",))
    c = compile_demo_changeover(catalog, mix, tmp_path, 1.0, report=False)
    assert c.note is not None and c.note.startswith("every landing accepted: l-bracket (up)")
    assert c.compiled.rejected == frozenset() and len(c.landings) == 3


def test_the_lookalike_report_is_given_the_pair(tmp_path: Path, monkeypatch) -> None:
    import feederkit.reports

    def fake_report(plan, *, unrecognizable, outlines, **_other):
        pairs = sorted((u["part_a"], u["part_b"]) for u in unrecognizable)
        return f"<p>{pairs} {sorted(outlines)}</p>"

    monkeypatch.setattr(feederkit.reports, "render_report", fake_report)
    for name in ("quadrilateral", "rectangle-2x1"):
        shutil.copy(ROOT / "catalog" / f"{name}.json", tmp_path)
    result = run_demo(tmp_path, tmp_path / "out")
    (pair,) = result.changeovers
    assert pair.name == "lookalike-pair" and pair.report_path is not None
    html = pair.report_path.read_text(encoding="utf-8")
    assert "('quadrilateral/up', 'quadrilateral-twin/up')" in html
    assert "('quadrilateral/down', 'quadrilateral-twin/down')" in html
    assert "rectangle-2x1/down" in html


def test_summary_is_json(few: DemoResult) -> None:
    data = json.loads(json.dumps(few.to_dict(), allow_nan=False))
    assert {p["name"] for p in data["parts"]} == set(FEW)
    assert all("warnings" in p for p in data["plans"])
    assert all("warnings" in c and "min_margin_deg" in c for c in data["changeovers"])


def test_demo_margins_show_their_digits() -> None:
    from feederkit.cli.demo import margin_text

    assert margin_text(0.04363826470942911) == "0.0436°"
    assert margin_text(45.00000000000001) == "45°"
    assert margin_text(None) == "-" and margin_text(float("inf")) == "-"


def test_demo_rejects_a_missing_folder_and_a_bad_percentage(tmp_path: Path, capsys) -> None:
    assert main(["demo", "--catalog-dir", str(tmp_path / "nope"), "-o", str(tmp_path)]) == 2
    rc = main(["demo", "--catalog-dir", str(tmp_path), "--tolerance-percent", "60"])
    assert rc == 2 and "--tolerance-percent" in capsys.readouterr().err
    with pytest.raises(InputError, match="sensor tolerance"):
        run_demo(tmp_path, tmp_path / "o", percent=0.0)


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    out = tmp_path_factory.mktemp("demo")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["demo", "--catalog-dir", str(ROOT / "catalog"), "-o", str(out), "--json"])
    assert code == 0
    return json.loads(buf.getvalue()), out


@pytest.mark.slow
def test_demo_plans_every_orientable_part_both_ways(demo_run: tuple[dict, Path]) -> None:
    summary, out = demo_run
    names = {p.stem for p in (ROOT / "catalog").glob("*.json")}
    planned = {p["name"] for p in summary["plans"]}
    assert planned == names - set(summary["not_orientable"])
    for p in summary["plans"]:
        assert p["sensor"]["length"] <= p["sensorless"]["length"]
        for f in p["files"]:
            check_plan(read_plan(f))


@pytest.mark.slow
def test_demo_compiles_the_papers_changeover_and_the_lookalike(
    demo_run: tuple[dict, Path],
) -> None:
    summary, out = demo_run
    by_name = {c["name"]: c for c in summary["changeovers"]}
    fig27 = by_name["fig27-triangle-octagon"]
    assert fig27["parts"] == ["isosceles-right-triangle", "octagon"]
    assert fig27["length"] == 2
    assert fig27["unrecognizable_pairs"] == []
    assert by_name["lookalike-pair"]["unrecognizable_pairs"]
    feeder = by_name["feeder-parts"]
    assert feeder["rejected"] == ["chamfered-plate/down", "l-bracket/down"]
    assert feeder["rejected_share"] == pytest.approx(0.25)
    assert feeder["unrecognizable_pairs"] == [] and feeder["note"] is None
    assert by_name["paper-shapes"]["unrecognizable_pairs"] == []
    assert len(by_name) >= 4
    for c in summary["changeovers"]:
        check_plan(read_plan(c["plan"]))
        plan = json.loads(Path(c["plan"]).read_text(encoding="utf-8"))
        assert {p["name"] for p in plan["parts"]} == set(c["parts"])
        html = Path(c["report"]).read_text(encoding="utf-8")
        assert "<svg" in html and c["parts"][0] in html


def test_the_plans_tables_fit_80_columns(few: DemoResult) -> None:
    """The demo's plan tables are read in an 80-column terminal: no cell cut to '...'."""
    from rich.console import Console

    from feederkit.cli.demo import plans_tables

    out = Console(width=80, record=True, file=io.StringIO())
    for table in plans_tables(few.plans):
        out.print(table)
    text = out.export_text()
    assert "\u2026" not in text and max(len(line) for line in text.splitlines()) <= 80


def test_a_changeover_shows_its_cycle_time_with_a_profile(tmp_path: Path) -> None:
    from feederkit.catalog import add_outline, open_catalog
    from feederkit.cell import parse_cell, resolve_settings
    from feederkit.demo import DemoMix, compile_demo_changeover
    from feederkit.sources import load_part

    catalog = tmp_path / "demo.db"
    open_catalog(catalog, create=True).close()
    for name in ("isosceles-right-triangle", "octagon"):
        add_outline(catalog, load_part(str(ROOT / "catalog" / f"{name}.json")).outline, name=name)
    profile = parse_cell(
        {
            "robot": {"pick_place_s": 1.0, "rotation_speed_deg_s": 90.0},
            "belt": {"speed_m_s": 0.1, "drop_to_fence_mm": 100.0},
        },
        "cell.toml",
    )
    c = compile_demo_changeover(
        catalog,
        DemoMix("fig27", ("isosceles-right-triangle", "octagon")),
        tmp_path,
        1.0,
        report=False,
        cell=resolve_settings(profile),
    )
    cycle = c.to_dict()["cycle_time"]
    assert cycle["profile"] == "cell.toml"
    # At least the drift of every operation, at most a half turn more per later one.
    stats = c.compiled.plan["stats"]
    assert stats["expected_length"] <= cycle["expected_s"]
    assert cycle["worst_s"] <= 1.0 + (stats["length"] - 1) * 4.0 + 1e-9
    assert json.loads((tmp_path / "fig27.json").read_text())["stats"]["cycle_time"] == cycle


def test_a_design_past_the_reports_limit_leaves_the_demo_report_without_it(
    tmp_path: Path, monkeypatch
) -> None:
    import feederkit.design.sensor
    import feederkit.reports
    from feederkit.catalog import add_outline, open_catalog
    from feederkit.demo import DemoMix, compile_demo_changeover
    from feederkit.sources import load_part

    got: list = []

    verified: list = []

    def fake_report(plan, *, unrecognizable, outlines, design=None, verification=None):
        got.append(design)
        verified.append(verification)
        return "<p>report</p>"

    monkeypatch.setattr(feederkit.reports, "render_report", fake_report)
    catalog = tmp_path / "demo.db"
    open_catalog(catalog, create=True).close()
    for name in ("isosceles-right-triangle", "octagon"):
        add_outline(catalog, load_part(str(ROOT / "catalog" / f"{name}.json")).outline, name=name)
    mix = DemoMix("fig27", ("isosceles-right-triangle", "octagon"))
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    monkeypatch.setattr(feederkit.design.sensor, "REPORT_DESIGN_LIMIT_S", 1e-9)
    c = compile_demo_changeover(catalog, mix, tmp_path / "a", 1.0)
    assert got == [None] and c.report_path is not None and c.report_path.is_file()
    assert c.note is not None and "leaves out the sensor design" in c.note and "1e-09 s" in c.note
    monkeypatch.setattr(feederkit.design.sensor, "REPORT_DESIGN_LIMIT_S", 60.0)
    c = compile_demo_changeover(catalog, mix, tmp_path / "b", 1.0)
    assert got[1] is not None and got[1]["sensor_model"] == "tolerance" and c.note is None
    # The report shows the compile's own verification of the plan, not one made again.
    assert all(v is not None and v.ok for v in verified) and len(verified) == 2
