"""``feederkit report --simulate N``: the page shows the MuJoCo success rate (issue 7, item 3)."""

from __future__ import annotations

from pathlib import Path

import pytest

from feederkit.cli.app import main
from feederkit.sim import mujoco_available

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


@pytest.fixture()
def plan_file(tmp_path: Path) -> Path:
    out = tmp_path / "triangle.plan.json"
    source = str(CATALOG / "isosceles-right-triangle.json")
    assert main(["plan", source, "--tolerance", "0.01", "-o", str(out)]) == 0
    return out


@pytest.mark.skipif(not mujoco_available(), reason="mujoco cannot be imported (feederkit[sim])")
def test_report_shows_the_simulated_success_rate(plan_file: Path, tmp_path: Path) -> None:
    html = tmp_path / "report.html"
    assert main(["report", str(plan_file), "-o", str(html), "--simulate", "4", "--seed", "3"]) == 0
    text = html.read_text(encoding="utf-8")
    assert "of 4 trials oriented correctly" in text


def test_report_refuses_a_non_positive_trial_count(plan_file: Path, tmp_path: Path) -> None:
    html = tmp_path / "report.html"
    assert main(["report", str(plan_file), "-o", str(html), "--simulate", "0"]) == 2
    assert not html.exists()
