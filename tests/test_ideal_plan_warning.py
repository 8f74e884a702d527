"""A plan made on the ideal model says, wherever its file is used, that on a feeder that
vibrates it holds less than its margins say (its certificate): ``plan`` said it once on
stderr, and ``run`` and ``simulate`` of the file said nothing (a review simulated such a plan
with an exact robot, 60 of 60, and another plan 13 of 30, with no note either time)."""

from __future__ import annotations

from pathlib import Path

import pytest

from feederkit.cli.app import main
from feederkit.plans.readplan import plan_from_dict

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
WORDS = "the plan is the ideal model's: on a feeder that vibrates it holds"


def words(text: str) -> str:
    return " ".join(text.split())


@pytest.fixture(scope="module")
def ideal_plan(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("ideal") / "r0.plan.json"
    args = ["plan", str(CATALOG / "rectangle-2x1.json"), "--tolerance", "0.05"]
    # Written, and a result to act on: it holds no rotation error on a feeder that vibrates.
    assert main([*args, "--rotation-error", "0", "-o", str(out)]) == 1
    return out


def test_the_plan_file_knows_it_holds_less_than_its_margins(ideal_plan):
    import json

    plan = plan_from_dict(json.loads(ideal_plan.read_text()))
    warning = plan.ideal_model_warning()
    assert warning is not None and warning.startswith(WORDS)
    assert "no rotation error at all" in warning


def test_run_says_it(ideal_plan, capsys):
    assert main(["run", str(ideal_plan), "--all"]) == 0
    out = capsys.readouterr()
    assert WORDS in words(out.out + out.err)


def test_a_plan_with_a_declared_rotation_error_is_not_warned(tmp_path, capsys):
    out = tmp_path / "r1.plan.json"
    args = ["plan", str(CATALOG / "rectangle-2x1.json"), "--tolerance", "0.05", "-o", str(out)]
    assert main(args) == 0
    capsys.readouterr()
    assert main(["run", str(out), "--all"]) == 0
    shown = capsys.readouterr()
    assert WORDS not in words(shown.out + shown.err)


def test_simulate_says_it(ideal_plan, capsys):
    pytest.importorskip("mujoco")
    assert main(["simulate", str(ideal_plan), "--trials", "1"]) in (0, 1)
    assert WORDS in words(capsys.readouterr().err)


def test_the_report_says_it(ideal_plan, tmp_path):
    page = tmp_path / "r0.html"
    assert main(["report", str(ideal_plan), "-o", str(page)]) == 0
    html = page.read_text()
    assert 'id="ideal-model"' in html and WORDS.replace("'", "&#x27;") in words(html)


def test_changeover_export_says_it(tmp_path, capsys):
    import json

    db = str(tmp_path / "c.db")
    assert main(["catalog", "add", str(CATALOG / "rectangle-2x1.json"), "--catalog", db]) == 0
    args = ["changeover", "compile", "r0", "--mix", "rectangle-2x1", "--tolerance", "0.05"]
    assert main([*args, "--rotation-error", "0", "--catalog", db]) == 1  # stored, exit 1
    capsys.readouterr()
    out = tmp_path / "r0.json"
    assert main(["changeover", "export", "r0", "-o", str(out), "--json", "--catalog", db]) == 0
    shown = capsys.readouterr()
    assert WORDS in words(shown.err)
    data = json.loads(shown.out)
    assert data["up_to_date"] is True and data["plan_warnings"][0].startswith(WORDS)
