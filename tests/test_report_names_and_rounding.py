"""The report and plots after review 66b (docs/reports.md): the sensor design's critical
tolerances rounded down as the terminal rounds them (F5), part names the plot's font cannot
draw (F7), and the changeover's name heading its report (F10)."""

from __future__ import annotations

import json
import os
import random
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
from shared import cli_ok
from test_report import rectangle_plan

from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.reports import part_figure, part_plot_bytes, render_report
from feederkit.reports.design_html import design_section
from feederkit.reports.partplot import drawable
from feederkit.sensors import LedSensor
from feederkit.words import shown_tolerance

ROOT = Path(__file__).resolve().parents[1]
CATALOG = ROOT / "catalog"
OCTAGON = [(1, 0), (2, 0), (3, 1), (3, 2), (2, 3), (1, 3), (0, 2), (0, 1)]
CJK = "日本語パーツ"
CJK_ESCAPED = "\\u65e5\\u672c\\u8a9e\\u30d1\\u30fc\\u30c4"

# --- F5: critical tolerances as the terminal shows them ------------------------------------------

CRITICAL = 0.4552137502
"""quadrilateral & rectangle-2x1's critical tolerance: 0.455213 works, 0.455214 does not."""

DESIGN = {
    "sensor_model": "tolerance",
    "critical_tolerance_mm": CRITICAL,
    "pairs": [{"a": "quad25/up", "b": "quad25/down", "critical_tolerance_mm": CRITICAL}],
    "lengths": [
        {"tolerance_mm": [0.0, 0.3 - 1e-12], "length": 3, "expected": 2.5},
        {"tolerance_mm": [0.3 - 1e-12, CRITICAL], "length": 5, "expected": 3.25},
    ],
    "model": "strong plans at the declared uncertainty",
    "answer": "this mix is recognizable with a tolerance up to 0.455213 mm",
}


def test_the_design_section_never_rounds_a_critical_tolerance_up():
    html = design_section(DESIGN)
    assert "0.455214" not in html  # num(x, 6) rounded it up: compiling there fails
    assert "0.3 &lt; tolerance &le; 0.455213 mm" in html  # the steps, both ends
    assert "0 &lt; tolerance &le; 0.3 mm" in html  # float noise is not shown as 0.299999
    assert "<td>quad25/up</td><td>quad25/down</td><td>0.455213 mm</td>" in html  # the pairs
    assert "critical 0.455213 mm" in html  # the plot's mark
    assert "0.4552 mm" not in html  # the axis's end, under the mark, said 0.4552: too coarse
    led = design_section(DESIGN, LedSensor(0.1, 0.02))
    assert "within the 0.455213 mm that keeps the mix recognizable" in led
    assert "0.455214" not in led


def test_shown_tolerances_never_round_up():
    # One rule (feederkit.words.shown_tolerance) for the terminal and the report.
    rng = random.Random(66)
    values = [CRITICAL, 0.3 - 1e-12, 0.3, 6.0274084767, 0.000123456789, 0.0, 12.5, 1e-7]
    values += [rng.uniform(0.0, 10.0) for _ in range(500)]
    values += [round(rng.uniform(0.0, 2.0), rng.randint(1, 8)) for _ in range(500)]
    for x in values:
        assert float(shown_tolerance(x)) <= float(f"{x:.9g}"), x


# --- F7: part names the plot's font cannot draw ---------------------------------------------------


def cjk_part():
    return make_part(make_outline(CJK, OCTAGON))


@pytest.mark.parametrize("fmt", ["png", "svg"])
def test_a_name_the_font_cannot_draw_warns_nothing(fmt):
    pf = push_function(cjk_part())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data = part_plot_bytes(pf, fmt)
    assert data
    assert [str(w.message) for w in caught] == []  # was "Glyph 26085 ... missing from font(s)"


def test_a_name_the_font_cannot_draw_is_shown_escaped_and_says_so():
    fig = part_figure(push_function(cjk_part()))
    title = fig.axes[0].get_title()
    first, note = title.split("\n")
    assert first == f"{CJK_ESCAPED}: 8 stable states"
    assert "\\uXXXX" in note and "cannot draw" in note
    assert drawable(title) == (title, False)  # every character has a glyph: no empty boxes
    # names the font draws are drawn as they are, on one line
    for name in ("bracket-a", "Linie 3 \u2013 M\u00fcller", "\u00c5ngstr\u00f6m \u00b5m"):
        assert drawable(name) == (name, False)
        title = part_figure(push_function(make_part(make_outline(name, OCTAGON)))).axes[0]
        assert title.get_title() == f"{name}: 8 stable states"
    assert drawable("a\U00020000b") == ("a\\U00020000b", True)  # CJK extension B: 8 digits


def test_part_plot_prints_no_python_warning(tmp_path):
    src = tmp_path / "jp.json"
    src.write_text(json.dumps({"name": CJK, "vertices": OCTAGON}), encoding="utf-8")
    out = tmp_path / "jp.png"
    done = subprocess.run(
        [sys.executable, "-m", "feederkit", "part", "plot", str(src), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT)},  # this tree's feederkit
    )
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""  # was 6 pairs of "UserWarning: Glyph ... missing" lines
    assert out.read_bytes().startswith(b"\x89PNG")


# --- F10: the changeover's name heads its report -------------------------------------------------


def heading_of(html: str) -> tuple[str, str]:
    title = html.split("<title>", 1)[1].split("</title>", 1)[0]
    h1 = html.split("<h1", 1)[1].split("</h1>", 1)[0]
    return title, h1


def test_a_changeovers_report_is_headed_by_its_name():
    plan = rectangle_plan()
    title, h1 = heading_of(render_report(plan, changeover="Linie 3 \u2013 <M\u00fcller>"))
    assert "Linie 3 \u2013 &lt;M\u00fcller&gt;" in title
    assert 'data-changeover="Linie 3 \u2013 &lt;M\u00fcller&gt;"' in h1
    assert "Changeover \u2018Linie 3 \u2013 &lt;M\u00fcller&gt;\u2019 report: rect" in h1
    # a plan file has no name: its page is headed as before
    title, h1 = heading_of(render_report(plan))
    assert title == "feederkit report: rect"
    assert h1 == ">Plan report: rect"


@pytest.fixture()
def db(tmp_path, capsys) -> Path:
    folder = tmp_path / "parts"
    folder.mkdir()
    for name in ("isosceles-right-triangle", "octagon"):
        shutil.copy(CATALOG / f"{name}.json", folder)
    path = tmp_path / "parts.db"
    cli_ok(capsys, ["catalog", "init", "--catalog", str(path)])
    cli_ok(capsys, ["catalog", "import", str(folder), "--catalog", str(path)])
    return path


def test_compile_and_report_name_the_changeover(db, tmp_path, capsys, monkeypatch):
    import feederkit.reports

    given: list[object] = []

    def fake_report(plan, *, changeover=None, **_kw):
        given.append(changeover)
        return "<p></p>"

    monkeypatch.setattr(feederkit.reports, "render_report", fake_report)
    html = str(tmp_path / "r.html")
    mix = ["--mix", "isosceles-right-triangle,octagon", "--tolerance", "0.01"]
    cli_ok(
        capsys,
        ["changeover", "compile", "line 1", *mix, "--report", html, "--catalog", str(db)],
    )
    cli_ok(capsys, ["changeover", "report", "line 1", "-o", html, "--catalog", str(db)])
    assert given == ["line 1", "line 1"]


def test_the_design_plot_labels_the_critical_tolerance_rounded_down(tmp_path):
    # design sensor --plot said "critical tolerance 0.4909 mm" for 0.490866 mm, at which the
    # triangle and the octagon cannot be told apart (the terminal said 0.490866).
    from pathlib import Path

    import matplotlib

    from feederkit.design.plot import plot_design
    from feederkit.design.sensor import design_tolerance
    from feederkit.mechanics.push import push_function
    from feederkit.outline import load_outline_json
    from feederkit.part import make_part

    catalog = Path(__file__).resolve().parents[1] / "catalog"
    pfs = [
        push_function(make_part(load_outline_json(catalog / f"{n}.json")))
        for n in ("equilateral-triangle", "octagon")
    ]
    design = design_tolerance(pfs)
    shown = shown_tolerance(design.critical_tolerance)
    with matplotlib.rc_context({"svg.fonttype": "none"}):  # the labels as text
        svg = plot_design(design, tmp_path / "d.svg").read_text()
    assert f"critical tolerance {shown} mm" in svg
    assert float(shown) <= design.critical_tolerance


def test_one_parts_plan_over_its_landings_is_a_plan_report(tmp_path, capsys):
    # Both landings of one part were headed "Changeover report: quadrilateral".
    from feederkit.cli.app import main

    html = tmp_path / "q.html"
    args = ["plan", str(CATALOG / "quadrilateral.json"), "--tolerance", "0.2"]
    assert main([*args, "-o", str(tmp_path / "q.json"), "--report", str(html)]) in (0, 1)
    capsys.readouterr()
    assert heading_of(html.read_text())[1] == ">Plan report: quadrilateral"


def test_poses_that_all_look_alike_name_no_unlike_pair():
    # A triangle's three poses, all alike, ended in an empty "not alike: ".
    from feederkit.reports.sections import _unlike_words
    from feederkit.reports.twins import TwinLeaf

    alike = TwinLeaf(1, 0, (0, 1, 2), (), False, ())
    assert _unlike_words(alike) == ""
    apart = TwinLeaf(1, 0, (0, 1, 2), ((0, 2),), False, ())
    assert _unlike_words(apart) == ", not alike: s0 and s2"


def test_a_small_member_of_a_mix_of_sizes_is_drawn_magnified(tmp_path, capsys):
    # Every pose of a 1 mm part beside a 100 mm one was drawn sub-pixel: a fence bar only.
    from feederkit.cli.app import main

    big = tmp_path / "plate.json"
    big.write_text(
        json.dumps({"name": "plate", "vertices": [[0, 0], [100, 0], [100, 40], [0, 60]]})
    )
    small = tmp_path / "chip.json"
    small.write_text(json.dumps({"name": "chip", "vertices": [[0, 0], [1, 0], [0.2, 0.7]]}))
    html = tmp_path / "r.html"
    args = ["plan", str(big), str(small), "--tolerance", "0.2", "--landings", "up"]
    assert main([*args, "-o", str(tmp_path / "p.json"), "--report", str(html)]) in (0, 1)
    capsys.readouterr()
    text = html.read_text()
    poses = [f for f in text.split("<figure")[1:] if '<svg class="pose"' in f.split(">", 1)[1]]
    chip = [f for f in poses if 'data-part="chip"' in f.split(">", 1)[0]]
    plate = [f for f in poses if 'data-part="plate"' in f.split(">", 1)[0]]

    def caption(figure: str) -> str:
        return figure.split("<figcaption>", 1)[1].split("</figcaption>", 1)[0]

    assert chip and all("\u00d7" in caption(f) for f in chip)
    assert plate and not any("\u00d7" in caption(f) for f in plate)
