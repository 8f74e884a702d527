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
    assert "successes (oriented correctly): 4 of 4 (100.0 %; 95 % Wilson interval" in text
    assert "seed 3" in text and "sampled: rotation error ±1 deg per rotation" in text


def test_report_refuses_a_non_positive_trial_count(plan_file: Path, tmp_path: Path) -> None:
    html = tmp_path / "report.html"
    assert main(["report", str(plan_file), "-o", str(html), "--simulate", "0"]) == 2
    assert not html.exists()


def _trial(i: int, outcome: str, cause: str | None = None, rejected: bool = False):
    from feederkit.sim.summary import TrialResult

    return TrialResult(
        i, "bracket", 0.0, outcome, 2, "why", 0, (), cause=cause, predicted=False, rejected=rejected
    )


def test_the_simulation_row_uses_the_simulators_summary() -> None:
    """The report says what ``simulate`` says: failures by cause (never all "a wrong pose"),
    the sampled uncertainty, the seed, the Wilson interval, the rightly rejected apart."""
    from simsummaries import sim_summary

    from feederkit.reports.sections import simulation_text
    from feederkit.uncertainty import Uncertainty

    failures = (
        _trial(5, "failure", "reading in no branch"),
        _trial(6, "failure", "reading in no branch"),
        _trial(7, "failure", "wrong result"),
    )
    summary = sim_summary(
        {"bracket (up)": (18, 20), "bracket (down)": (19, 20)},
        seed=7,
        sampled=Uncertainty(1.0, 0.0, 0.0),
        min_margin_deg=3.0,
        failures=failures,
        pushes=80,
        rejects=19,
    )
    text = simulation_text(summary.to_dict())
    assert "wrong pose" not in text
    assert "reading in no branch: 2" in text and "wrong result: 1" in text
    assert "95 % Wilson interval" in text and summary.success_words() in text
    assert "18 oriented correctly and 19 rightly rejected" in text
    assert "sampled: rotation error ±1 deg per rotation" in text and "seed 7" in text
    beyond = {**summary.to_dict(), "warnings": ["bracket (up): x.json's hull lies 0.25 mm"]}
    assert simulation_text(beyond).endswith("; warning: bracket (up): x.json's hull lies 0.25 mm")
