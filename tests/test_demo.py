"""``feederkit demo``, the main job, on the bundled catalog: every file it writes is right."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from feederkit.cli.app import main
from feederkit.plans.fileformat import read_plan
from feederkit.plans.verify import check_plan

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    out = tmp_path_factory.mktemp("demo")
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["demo", "--catalog-dir", str(ROOT / "catalog"), "-o", str(out), "--json"])
    assert code == 0
    return json.loads(buf.getvalue()), out


def test_demo_plans_every_orientable_part_both_ways(demo_run: tuple[dict, Path]) -> None:
    summary, out = demo_run
    names = {p.stem for p in (ROOT / "catalog").glob("*.json")}
    planned = {p["name"] for p in summary["plans"]}
    assert planned == names - set(summary["not_orientable"])
    for p in summary["plans"]:
        assert p["sensor"]["length"] <= p["sensorless"]["length"]
        for f in p["files"]:
            check_plan(read_plan(f))


def test_demo_compiles_the_papers_changeover(demo_run: tuple[dict, Path]) -> None:
    summary, out = demo_run
    by_name = {c["name"]: c for c in summary["changeovers"]}
    fig27 = by_name["fig27-triangle-octagon"]
    assert fig27["parts"] == ["isosceles-right-triangle", "octagon"]
    assert fig27["length"] == 2
    assert fig27["unrecognizable_pairs"] == []
    assert len(by_name) >= 2
    for c in summary["changeovers"]:
        plan = read_plan(c["plan"])
        check_plan(plan)
        assert {p["name"] for p in plan["parts"]} == set(c["parts"])
        html = Path(c["report"]).read_text(encoding="utf-8")
        assert "<svg" in html and c["parts"][0] in html


def test_demo_rejects_a_missing_folder(tmp_path: Path) -> None:
    assert main(["demo", "--catalog-dir", str(tmp_path / "nope"), "-o", str(tmp_path)]) == 2
