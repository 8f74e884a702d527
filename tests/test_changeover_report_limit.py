"""The report's sensor design takes its budget from the command's ``--time-limit``
(docs/changeovers.md, docs/reports.md): ``changeover compile --time-limit S --report R``
answers within about S, and a design cut short there gets a section that says so and what it
decided; ``changeover report --time-limit S`` gives the design S seconds less the drawings."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import pytest
from shared import cli_ok

from feederkit.cli.app import main
from feederkit.design.limit import DesignClock
from feederkit.reports.design_html import design_section

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
MIX = "isosceles-right-triangle,octagon"
SLOW_S = 10.0
"""How long the stand-in design step runs when its clock does not stop it (the old fixed
budget of 60 s would let it run this long). The tests assert the command ends well before
it: a bound on the work, not on this machine's speed (a loaded machine stretches the 2 s
limit's command, never by 8 s)."""


ok = cli_ok  # feederkit ARGS exits CODE; the captured output


@pytest.fixture()
def db(tmp_path, capsys) -> Path:
    folder = tmp_path / "parts"
    folder.mkdir()
    for name in MIX.split(","):
        shutil.copy(CATALOG / f"{name}.json", folder)
    path = tmp_path / "parts.db"
    ok(capsys, ["catalog", "init", "--catalog", str(path)])
    ok(capsys, ["catalog", "import", str(folder), "--catalog", str(path)])
    return path


@pytest.fixture()
def slow_design(monkeypatch) -> list[float | None]:
    """The design's pair step made slow: it polls its clock (as every design loop does) for up
    to ``SLOW_S`` seconds. Returns the time limits the design's clocks were given."""
    import feederkit.design.sensor as sensor

    limits: list[float | None] = []

    def slow(*args, **kwargs):
        clock = next(a for a in (*args, *kwargs.values()) if isinstance(a, DesignClock))
        limits.append(clock.time_limit_s)
        clock.begin("deciding the pairs' critical tolerances", 3)
        clock.advance()
        end = time.monotonic() + SLOW_S
        while time.monotonic() < end:
            clock.check()
            time.sleep(0.01)
        raise AssertionError("the design's clock never stopped it")

    monkeypatch.setattr(sensor, "strong_mix_critical", slow)
    monkeypatch.setattr(sensor, "mix_critical_tolerance", slow)
    return limits


def test_compile_report_design_is_bounded_by_the_commands_time_limit(
    db, tmp_path, capsys, slow_design
):
    html = tmp_path / "mix.html"
    args = ["changeover", "compile", "mix", "--mix", MIX, "--tolerance", "0.01"]
    started = time.monotonic()
    cap = ok(capsys, [*args, "--time-limit", "2", "--report", str(html), "--catalog", str(db)])
    elapsed = time.monotonic() - started
    assert slow_design and slow_design[0] is not None and slow_design[0] <= 2.0
    assert elapsed < SLOW_S, elapsed  # the limit plus a small constant: the design stopped
    page = html.read_text()
    section = page[page.index('<section id="sensor-design">') :]
    section = section[: section.index("</section>")]
    assert 'id="design-cut-short"' in section
    assert "did not finish within the time limit" in section and "1 of 3 pairs" in section
    (line,) = [w for w in cap.err.splitlines() if "sensor design" in w]
    assert line.startswith("warning: ") and "cut short" in line and "--time-limit" in line


def test_changeover_report_takes_a_time_limit_for_its_design(db, tmp_path, capsys, slow_design):
    ok(
        capsys,
        ["changeover", "compile", "mix", "--mix", MIX, "--tolerance", "0.01", "--catalog", str(db)],
    )
    slow_design.clear()
    html = tmp_path / "mix.html"
    started = time.monotonic()
    args = ["changeover", "report", "mix", "-o", str(html), "--time-limit", "0.5"]
    cap = ok(capsys, [*args, "--catalog", str(db)])
    assert time.monotonic() - started < SLOW_S
    assert slow_design == [0.5]
    assert 'id="design-cut-short"' in html.read_text()
    assert "cut short by the command's --time-limit" in cap.err and "of 0.5 s" in cap.err
    bad = ["changeover", "report", "mix", "-o", str(html), "--time-limit", "0"]
    assert main([*bad, "--catalog", str(db)]) == 2


def test_a_partial_design_shows_what_it_decided_and_no_table():
    design = {
        "sensor_model": "tolerance",
        "parts": ["a", "b"],
        "critical_tolerance_mm": 0.2,
        "pairs": [{"a": "a", "b": "b", "critical_tolerance_mm": 0.2}],
        "lengths": [],
        "complete": False,
        "stopped": "the sensor design did not finish within the time limit of 1 s",
        "model": "",
        "answer": "recognizable up to 0.2 mm; the length table is left out",
    }
    html = design_section(design)
    assert 'id="design-cut-short"' in html and "0.2 mm" in html
    assert "design-steps" not in html and "design-plot" not in html
    whole = {**design, "stopped": None, "complete": True}
    whole["lengths"] = [{"tolerance_mm": [0.0, 0.2], "length": 2, "expected": 1.5}]
    html = design_section(whole)
    assert "design-cut-short" not in html and "design-steps" in html


def test_the_design_budget_is_what_the_time_limit_leaves(monkeypatch):
    import feederkit.design.sensor as sensor
    from feederkit.cli.changeover import REPORT_DESIGN_MIN_S, report_design_budget

    now = time.monotonic()
    assert 6.0 < report_design_budget(10.0, now - 3.0) <= 7.0  # 10 s less the 3 s used
    assert report_design_budget(5.0, now - 30.0) == REPORT_DESIGN_MIN_S  # plan overshot
    assert report_design_budget(600.0, now) == sensor.REPORT_DESIGN_LIMIT_S  # capped
    assert report_design_budget(None, now) == sensor.REPORT_DESIGN_LIMIT_S
    # The report's drawings come out of it too (a new user's review: 20 landings took 6-7 s
    # past a 2 s limit), in tenths of a second (the warning names it).
    budget = report_design_budget(10.0, now - 3.0, parts=10)
    assert 3.0 < budget <= 3.5 and budget == round(budget, 1)
    monkeypatch.setattr(sensor, "REPORT_DESIGN_LIMIT_S", 0.25)
    assert report_design_budget(5.0, now - 30.0) == 0.25
    assert 298.0 < report_design_budget(300.0, now, parts=2, cap=300.0) <= 299.3  # its own cap


def test_changeover_report_gives_its_design_a_long_time_limit_less_the_drawings(
    db, tmp_path, capsys, monkeypatch
):
    # `changeover report --time-limit 300` is the report's own limit: its design gets it less
    # the drawings, not the 60 s a compile's report is capped at.
    import feederkit.cli.changeover as changeover_cli

    ok(
        capsys,
        ["changeover", "compile", "mix", "--mix", MIX, "--tolerance", "0.01", "--catalog", str(db)],
    )
    budgets = []

    def report(plan, parts, witnesses, budget, **_kw):
        budgets.append(budget)
        return "<html></html>"

    monkeypatch.setattr(changeover_cli, "changeover_report", report)
    html = str(tmp_path / "mix.html")
    for limit in ("300", None):
        flag = [] if limit is None else ["--time-limit", limit]
        ok(capsys, ["changeover", "report", "mix", "-o", html, *flag, "--catalog", str(db)])
    parts = len(MIX.split(","))
    assert 290.0 < budgets[0] <= 300.0 - changeover_cli.REPORT_DRAW_S_PER_PART * parts
    assert 50.0 < budgets[1] <= 60.0 - changeover_cli.REPORT_DRAW_S_PER_PART * parts


def test_a_design_the_mix_cannot_have_leaves_the_compile_and_its_report(
    db, tmp_path, capsys, monkeypatch
):
    """A design step that refuses the mix (InputError: a step finer than the diameters are
    known) ended ``compile --report`` with exit 2 after the plan was made; now the report
    is written, its section says why there is no design, and one warning says so."""
    import feederkit.design.sensor as sensor
    from feederkit.errors import InputError

    def refuse(*args, **kwargs):
        raise InputError("the sensor's resolution is finer than the parts' diameters are known")

    monkeypatch.setattr(sensor, "strong_mix_critical", refuse)
    monkeypatch.setattr(sensor, "mix_critical_tolerance", refuse)
    html = tmp_path / "mix.html"
    args = ["changeover", "compile", "mix", "--mix", MIX, "--tolerance", "0.01"]
    cap = ok(capsys, [*args, "--report", str(html), "--catalog", str(db)])
    page = html.read_text()
    section = page[page.index('<section id="sensor-design">') :]
    assert "not made: the sensor" in section[: section.index("</section>")]
    assert 'id="design-cut-short"' not in page
    (line,) = [w for w in cap.err.splitlines() if "sensor design" in w]
    assert line.startswith("warning: ") and "could not be made" in line


def test_compile_report_takes_the_compiles_verification_and_no_plot_past_the_limit(
    db, tmp_path, capsys, monkeypatch
):
    # The plan was verified by the compile itself: the report does not verify it again (a
    # 20-part mix's plan over both landings: 14 s), and draws no part plot once the
    # command's limit has passed (0.2-0.6 s each, 40 of them).
    import feederkit.reports.report as report_module

    def again(*_a, **_k):
        raise AssertionError("the report verified the plan again")

    monkeypatch.setattr(report_module, "verify_declared", again)
    html = tmp_path / "mix.html"
    args = ["changeover", "compile", "mix", "--mix", MIX, "--tolerance", "0.01"]
    ok(capsys, [*args, "--report", str(html), "--catalog", str(db)])
    page = html.read_text()
    assert page.count('class="plot"') == 2 and "plot-skipped" not in page
    # Past the limit: each member's section names the command that draws its plot.
    import feederkit.cli.changeover as changeover_cli

    monkeypatch.setattr(changeover_cli, "limit_instant", lambda *_a: time.monotonic() - 1.0)
    later = tmp_path / "late.html"
    ok(capsys, [*args, "--report", str(later), "--catalog", str(db), "--replace"])
    page = later.read_text()
    assert 'class="plot"' not in page and page.count("plot-skipped") == 2
    assert "time limit left no time for this member" in page


def test_plan_report_takes_the_plans_verification(tmp_path, capsys, monkeypatch):
    import feederkit.reports.report as report_module

    def again(*_a, **_k):
        raise AssertionError("the report verified the plan again")

    monkeypatch.setattr(report_module, "verify_declared", again)
    html = tmp_path / "plan.html"
    parts = [str(CATALOG / f"{name}.json") for name in MIX.split(",")]
    out = str(tmp_path / "plan.json")
    ok(capsys, ["plan", *parts, "--tolerance", "0.01", "-o", out, "--report", str(html)])
    assert 'class="plot"' in html.read_text()


@pytest.mark.parametrize("command", ["plan", "compile"])
def test_the_plan_file_is_read_back_once(db, tmp_path, capsys, monkeypatch, command):
    # Reading a plan file's object into a Plan (checked) costs seconds on a large plan
    # (2 s for a 16 MB one): the plan file, the report, the drawing and the pairs no result
    # tells apart all take the one reading.
    import feederkit.plans.readplan as readplan
    import feederkit.plans.writeplan as writeplan

    reads: list[str] = []
    real = readplan.plan_from_dict

    def counting(data, source="plan"):
        reads.append(source)
        return real(data, source)

    monkeypatch.setattr(readplan, "plan_from_dict", counting)
    monkeypatch.setattr(writeplan, "plan_from_dict", counting)
    if command == "plan":
        args = ["plan", *(str(CATALOG / f"{n}.json") for n in MIX.split(","))]
    else:
        args = ["changeover", "compile", "mix", "--mix", MIX, "--catalog", str(db)]
    html, out = tmp_path / "r.html", tmp_path / "p.json"
    ok(capsys, [*args, "--tolerance", "0.01", "-o", str(out), "--report", str(html)])
    assert reads == ["the plan to write"] and html.exists() and out.exists()
