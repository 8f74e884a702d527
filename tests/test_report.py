"""The HTML changeover report: content, escaping, self-containment, plan tracing, errors."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from html.parser import HTMLParser

import pytest
import typer
from shared import plan_part_entry
from typer.testing import CliRunner

from feederkit.cli.report import register
from feederkit.errors import InputError
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans import plan_json, read_plan
from feederkit.reports import render_report

NASTY = '<b>&"x'

# --- hand-built plans (design.md plan file, version 1) ----------------------------------------


def part_entry(name, vertices, com=None, holes=()):
    return plan_part_entry(make_part(make_outline(name, vertices, holes, com=com)), revision="A")


def result(*entries):
    out = []
    for entry, sid in entries:
        pose = next(s["pose_deg"] for s in entry["stable_states"] if s["id"] == sid)
        out.append({"part": entry["name"], "state": sid, "pose_deg": pose})
    return {"result": out}


def op(action, margin, *branches):
    return {
        "action_deg": action,
        "margin_deg": margin,
        "branches": [{"reading": r, "next": n} for r, n in branches],
    }


def plan_file(parts, sensor, root, stats):
    return {
        "format": "feederkit-plan",
        "version": 1,
        "conventions": "Conventions as in design.md.",
        "sensor": sensor,
        "parts": parts,
        "root": root,
        "stats": stats,
    }


RECT = [(0, 0), (2, 0), (2, 1), (0, 1)]
TRIANGLE = [(0, 0), (1, 0), (0, 1)]


def rectangle_plan(name="rect"):
    """The 2x1 rectangle, COM at its centre, sensorless: rotate 45 deg, length 2.

    States by edge: s0 (e0, normal 270), s1 (e1, 0), s2 (e2, 90), s3 (e3, 180); rotating by 45
    sends every one of them onto a long edge, s0 or s2, which no plan tells apart.
    """
    return long_sides_plan(name, RECT, (1, 0.5))


def long_sides_plan(name, hull, com):
    """A rectangle ``hull`` (edges from the bottom one, counter-clockwise) sensorless: rotate
    45 deg onto a long side, s0 or s2, which the result lists together; length 2."""
    rect = part_entry(name, hull, com=com)
    root = op(None, None, (None, op(45.0, 18.43, (None, result((rect, 0), (rect, 2))))))
    stats = {
        "length": 2,
        "expected_length": 2.0,
        "min_margin_deg": 18.43,
        "optimal": True,
        "lower_bound": 2,
    }
    return plan_file([rect], {"model": "none"}, root, stats)


def _share(entry, state):
    """The probability that the first alignment leaves the part in ``state``: its resting
    range's share of the circle."""
    lo, hi = entry["stable_states"][state]["resting_range_deg"]
    return ((hi - lo) % 360.0) / 360.0


def triangle_plan(name=NASTY, e=0.01):
    """The isosceles right triangle (legs 1), tolerance e: length 2.

    s0 (e0, normal 270, d 1), s1 (hypotenuse, 45, d 0.707), s2 (e2, 180, d 1). Reading 0.707
    names s1; otherwise rotating by 90 sends s0 to s2 (d 1) and s2 to s1 (d 0.707).
    """
    tri = part_entry(name, TRIANGLE)
    hyp = tri["stable_states"][1]["diameter"]

    def rd(d):
        return [d - e, d + e]

    root = op(
        None,
        None,
        (rd(hyp), result((tri, 1))),
        (rd(1.0), op(90.0, 18.43, (rd(1.0), result((tri, 2))), (rd(hyp), result((tri, 1))))),
    )
    stats = {
        "length": 2,
        "expected_length": 2.0 - _share(tri, 1),  # s1 is named at once; the others take two
        "min_margin_deg": 18.43,
        "optimal": True,
        "lower_bound": 2,
    }
    return plan_file([tri], {"model": "tolerance", "tolerance_mm": e}, root, stats)


def twin_plan():
    """Two parts with the same shape: the triangle plan, every leaf holding both parts."""
    a = part_entry("tri-a", TRIANGLE)
    b = part_entry("tri-b", TRIANGLE)
    hyp = a["stable_states"][1]["diameter"]
    e = 0.01

    def rd(d):
        return [d - e, d + e]

    root = op(
        None,
        None,
        (rd(hyp), result((a, 1), (b, 1))),
        (
            rd(1.0),
            op(
                90.0,
                18.43,
                (rd(1.0), result((a, 2), (b, 2))),
                (rd(hyp), result((a, 1), (b, 1))),
            ),
        ),
    )
    stats = {
        "length": 2,
        "expected_length": 2.0 - _share(a, 1),
        "min_margin_deg": 18.43,
        "optimal": True,
        "lower_bound": 2,
    }
    return plan_file([a, b], {"model": "tolerance", "tolerance_mm": e}, root, stats)


def count_nodes(node):
    if "result" in node:
        return 1
    return 1 + sum(count_nodes(b["next"]) for b in node["branches"])


def count_final_poses(node):
    if "result" in node:
        return len(node["result"])
    return sum(count_final_poses(b["next"]) for b in node["branches"])


class Elements(HTMLParser):
    """Collects start tags (name, attrs) and text, to check the markup without a browser."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict[str, str]]] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, {k: v or "" for k, v in attrs}))

    def handle_data(self, data):
        self.text.append(data)

    def with_class(self, cls):
        return [a for _, a in self.tags if cls in a.get("class", "").split()]


def parse(html):
    p = Elements()
    p.feed(html)
    return p


# --- tests --------------------------------------------------------------------------------------


@pytest.mark.parametrize("make", [rectangle_plan, triangle_plan, twin_plan])
def test_one_tree_node_per_plan_node_and_one_leaf_per_final_pose(make):
    plan = make()
    doc = parse(render_report(plan))
    nodes = doc.with_class("tree-node")
    assert len(nodes) == count_nodes(plan["root"])
    assert [int(n["data-node-id"]) for n in nodes] == list(range(len(nodes)))
    assert len(doc.with_class("final-pose")) == count_final_poses(plan["root"])


class Nesting(HTMLParser):
    """Whether every ``ul`` and ``li`` opened is closed, in order."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.open: list[str] = []
        self.ok = True

    def handle_starttag(self, tag, attrs):
        if tag in ("ul", "li"):
            self.open.append(tag)

    def handle_endtag(self, tag):
        if tag in ("ul", "li"):
            self.ok = self.ok and bool(self.open) and self.open.pop() == tag


@pytest.mark.parametrize("limit", [1, 3, 5])
def test_a_tree_too_large_stops_and_says_what_it_left_out(monkeypatch, limit):
    import feederkit.reports.tree_html as tree_html

    plan = triangle_plan()
    whole = parse(render_report(plan))
    assert not whole.with_class("tree-stop")
    monkeypatch.setattr(tree_html, "TREE_FIGURES", limit)
    html = render_report(plan)
    doc = parse(html)
    (stop,) = doc.with_class("tree-stop")
    drawn = doc.with_class("tree-node")
    assert 0 < len(drawn) < count_nodes(plan["root"])
    # Every distinct node is drawn or counted as left out (this plan shares none).
    left = int(stop["data-operations"]) + int(stop["data-results"])
    assert len(drawn) + left == count_nodes(plan["root"])
    assert "the drawing stops after" in "".join(doc.text)
    nesting = Nesting()
    nesting.feed(html[html.index('<ul class="tree">') :])
    assert nesting.ok


def test_the_tree_shows_the_possible_states_at_each_node():
    doc = parse(render_report(triangle_plan()))
    by_id = {int(n["data-node-id"]): n for n in doc.with_class("tree-node")}
    assert by_id[0]["data-states"] == "3"  # any orientation: all stable states
    assert "op" in by_id[2]["class"] and by_id[2]["data-states"] == "2"  # s0 and s2 read alike
    states = [(f["data-part"], f["data-state"]) for f in doc.with_class("state")]
    assert states[:3] == [(NASTY, "0"), (NASTY, "1"), (NASTY, "2")]
    assert states[3:] == [(NASTY, "0"), (NASTY, "2")]
    edges = doc.with_class("edge")
    assert [e["data-action-deg"] for e in edges] == ["", "", "90", "90"]
    assert edges[0]["data-reading"].startswith("0.697")


def test_led_readings_route_states_by_beam_count():
    plan = triangle_plan()
    plan["sensor"] = {"model": "led", "pitch_mm": 0.1, "noise_mm": 0.0}
    # width 1 blocks the beams at 0.1 .. 0.9 (9 beams), width 0.707 those up to 0.7 (7 beams)
    plan["root"]["branches"][0]["reading"] = [0.7, 0.7]
    plan["root"]["branches"][1]["reading"] = [0.9, 0.9]
    inner = plan["root"]["branches"][1]["next"]["branches"]
    inner[0]["reading"], inner[1]["reading"] = [0.9, 0.9], [0.7, 0.7]
    doc = parse(render_report(plan))
    assert [n["data-states"] for n in doc.with_class("tree-node")] == ["3", "1", "2", "1", "1"]
    assert not doc.with_class("warn")


def test_a_leaf_that_disagrees_with_the_trace_is_flagged():
    plan = triangle_plan()
    plan["root"]["branches"][0]["next"] = result((plan["parts"][0], 0))
    assert "warn" in render_report(plan)


def test_part_names_are_escaped_everywhere():
    html = render_report(
        triangle_plan(),
        unrecognizable=[
            {
                "part_a": NASTY,
                "part_b": "<i>y",
                "states_a": [0],
                "states_b": [1],
                "reason": "<script>same</script>",
            }
        ],
        simulation={"trials": 3, "successes": 2, "note": "<u>"},
    )
    assert NASTY not in html and "<i>y" not in html and "<script" not in html and "<u>" not in html
    assert "&lt;b&gt;&amp;&quot;x" in html
    doc = parse(html)
    assert not [t for t, _ in doc.tags if t in ("b", "i", "script", "u")]
    assert f"Plan report: {NASTY}" in "".join(doc.text)
    assert all(f["data-part"] == NASTY for f in doc.with_class("final-pose"))


@pytest.mark.parametrize("make", [rectangle_plan, triangle_plan, twin_plan])
def test_the_page_is_self_contained_and_prints_on_a4(make):
    html = render_report(make())
    assert html.startswith("<!DOCTYPE html>")
    for banned in ("<script", "<link", "@import", "url(", "<iframe", "<object"):
        assert banned not in html
    # the only URLs are the SVG namespace (an identifier, never fetched)
    assert set(re.findall(r"https?://[^\s\"'<>]+", html)) <= {"http://www.w3.org/2000/svg"}
    for src in re.findall(r'src="([^"]*)"', html):
        assert src.startswith("data:image/svg+xml;base64,")
    assert "default-src 'none'" in html  # the page itself forbids loading anything
    assert "@media print" in html and "size: A4" in html
    assert html.count("<svg") >= 1


def test_statistics_cycle_time_and_simulation():
    html = render_report(
        triangle_plan(), seconds_per_op=4.5, simulation={"trials": 20, "successes": 19}
    )
    text = "".join(parse(html).text)
    assert "2 push-align operations" in text
    expected = triangle_plan()["stats"]["expected_length"]
    assert f"{expected:.3f} operations" in text
    assert "\u00b118.43\u00b0" in text
    assert f"{4.5 * expected:.3g} s expected, 9 s worst case at 4.5 s per operation" in text
    assert "successes (oriented correctly): 19 of 20 (95%)" in text
    assert "yes: no shorter plan exists (lower bound 2)" in text
    assert "within \u00b10.01 mm" in text
    without = "".join(parse(render_report(triangle_plan())).text)
    assert "not known: give a cell profile with timing" in without


def timed_triangle_plan(profile: str) -> dict:
    """:func:`triangle_plan` with a cell profile's cycle time: 3 s (20 parts per minute)
    expected, 4 s (15) at worst."""
    plan = triangle_plan()
    plan["stats"]["cycle_time"] = {
        "profile": profile,
        "expected_s": 3.0,
        "worst_s": 4.0,
        "parts_per_minute": 20.0,
        "worst_parts_per_minute": 15.0,
    }
    return plan


def test_the_cell_profiles_cycle_time_is_shown_and_named():
    plan = timed_triangle_plan("cell-a.toml (overridden: --tolerance)")
    text = "".join(parse(render_report(plan)).text)
    assert "3 s per part, 20 parts per minute" in text
    assert "4 s per part, 15 parts per minute" in text
    assert "cell-a.toml (overridden: --tolerance)" in text
    del plan["stats"]["cycle_time"]["worst_s"]
    with pytest.raises(InputError, match="cycle_time needs expected_s, worst_s and profile"):
        render_report(plan)


def test_the_sensor_design_table_and_plot():
    design = {
        "sensor_model": "tolerance",
        "critical_tolerance_mm": 0.5,
        "pairs": [
            {"a": "p", "b": "q", "critical_tolerance_mm": 0.5},
            {"a": "p", "b": "r", "critical_tolerance_mm": None},
        ],
        "lengths": [
            {"tolerance_mm": [0.0, 0.25], "length": 2, "expected": 1.5},
            {"tolerance_mm": [0.25, 0.5], "length": 3, "expected": 2.25},
        ],
        "model": "ideal model",
        "answer": "this mix is recognizable with a tolerance up to 0.5 mm",
    }
    doc = parse(render_report(triangle_plan(), design=design))
    text = "".join(doc.text)
    assert "this mix is recognizable with a tolerance up to 0.5 mm" in text
    assert "none: no sensor separates them" in text
    assert "0.25 < tolerance ≤ 0.5 mm" in text
    svgs = [a for t, a in doc.tags if t == "svg" and "design-plot" in a.get("class", "")]
    assert len(svgs) == 1
    with pytest.raises(InputError, match="design sensor"):
        render_report(triangle_plan(), design={"sensor_model": "magic"})


def test_a_design_step_with_no_strong_plan_is_named_and_left_out_of_the_plot():
    design = {
        "sensor_model": "tolerance",
        "critical_tolerance_mm": None,
        "pairs": [],
        "lengths": [
            {"tolerance_mm": [0.0, 0.25], "length": None, "expected": None},
            {"tolerance_mm": [0.25, 0.5], "length": 3, "expected": 2.25},
        ],
        "answer": "no tolerance makes this mix recognizable",
    }
    doc = parse(render_report(triangle_plan(), design=design))
    assert "no strong plan" in "".join(doc.text)
    lines = [a for t, a in doc.tags if t == "line" and a.get("stroke") == "#0072b2"]
    assert len(lines) == 1  # the step with a plan only
    design["lengths"] = design["lengths"][:1]
    doc = parse(render_report(triangle_plan(), design=design))
    assert not [a for t, a in doc.tags if t == "svg" and "design-plot" in a.get("class", "")]


def test_per_part_section_has_a_state_table_and_an_embedded_plot():
    doc = parse(render_report(rectangle_plan()))
    assert len(doc.with_class("stable-state")) == 4
    imgs = [a for t, a in doc.tags if t == "img"]
    assert len(imgs) == 1 and imgs[0]["src"].startswith("data:image/svg+xml;base64,")
    assert "Conventions as in design.md." in "".join(doc.text)


def test_only_the_first_members_get_a_part_plot(monkeypatch):
    import feederkit.reports.parts_html as parts_html

    monkeypatch.setattr(parts_html, "PART_PLOTS", 1)
    doc = parse(render_report(twin_plan()))
    sections = doc.with_class("part")
    assert len(sections) == 2 and len(doc.with_class("plot")) == 1
    assert len(doc.with_class("plot-skipped")) == 1 and len(doc.with_class("states")) == 2
    assert "feederkit part plot" in "".join(doc.text)


def test_a_skipped_part_plot_names_the_members_catalog_revision():
    from dataclasses import replace

    from feederkit.plans.readplan import plan_from_dict
    from feederkit.reports.parts_html import _no_plot

    plan = plan_from_dict(twin_plan())
    member = replace(plan.parts[0], revision=3, landing="pose-2")
    assert "feederkit part plot " + member.name + "@3 -o " in _no_plot(member)
    assert "--pose 2" in _no_plot(member)
    assert "mirror image" in _no_plot(replace(member, landing="down"))
    assert "SOURCE" in _no_plot(replace(member, revision=None))


def test_symmetric_leaves_and_twins_are_reported():
    text = "".join(parse(render_report(rectangle_plan())).text)
    assert "Poses no plan tells apart" in text and "rect: states s0, s2" in text
    doc = parse(render_report(twin_plan()))
    pairs = doc.with_class("pair")
    assert len(pairs) == 1 and pairs[0]["data-source"] == "plan"  # one row, three witnesses
    assert len(doc.with_class("confused")) == 3
    text = "".join(doc.text)
    assert "tri-a s1 ~ tri-b s1; tri-a s2 ~ tri-b s2" in text  # each pairing once
    assert "tri-b s2; tri-a s1" not in text
    assert "leaf 3: first alignment, reads 0.99\u20131.01 mm \u2192 rotate 90\u00b0 ccw" in text


def test_unrecognizable_pairs_from_the_mix_analysis():
    given = [
        {
            "part_a": "a",
            "part_b": "b",
            "states_a": [0, 1],
            "states_b": [2],
            "reason": "same push-diameter function",
        }
    ]
    doc = parse(render_report(triangle_plan(), unrecognizable=given))
    assert [p["data-source"] for p in doc.with_class("pair")] == ["mix"]
    text = "".join(doc.text)
    assert "same push-diameter function" in text
    assert "a: s0, s1; b: s2" in text  # unequal lists are shown side by side
    paired = [{"part_a": "a", "part_b": "b", "states_a": [0, 1], "states_b": [2, 0], "reason": "r"}]
    assert "a s0 ~ b s2, a s1 ~ b s0" in "".join(
        parse(render_report(triangle_plan(), unrecognizable=paired)).text
    )


def test_outlines_draw_holes():
    plan = rectangle_plan()
    outline = make_outline(
        "rect", RECT, [[(0.2, 0.2), (0.6, 0.2), (0.6, 0.6), (0.2, 0.6)]], com=(1, 0.5)
    )
    with_holes = render_report(plan, outlines={"rect": outline})
    paths = re.findall(r'<path d="([^"]*)" fill="#', with_holes)
    assert paths and all(d.count("M ") == 2 for d in paths)
    plain = re.findall(r'<path d="([^"]*)" fill="#', render_report(plan))
    assert all(d.count("M ") == 1 for d in plain)


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda p: p.update(format="other"), "not a feederkit plan"),
        (lambda p: p.update(version=3), "unsupported plan version"),
        (lambda p: p.pop("root"), "no 'root'"),
        (lambda p: p["root"]["branches"][0]["next"]["result"][0].update(part="ghost"), "ghost"),
        (lambda p: p["root"]["branches"][0]["next"]["result"][0].update(state=9), "state 9"),
        (lambda p: p["root"]["branches"][0].update(reading=[2, 1]), "lo > hi"),
        (lambda p: p["parts"][0].update(hull=[[0, 0]]), "fewer than three"),
        (lambda p: p.update(sensor={"model": "sonar"}), "unknown sensor model"),
    ],
)
def test_malformed_plans_are_bad_input(mutate, message):
    plan = triangle_plan()
    mutate(plan)
    with pytest.raises(InputError, match=message):
        render_report(plan)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_seconds_per_op_must_be_positive(bad):
    with pytest.raises(InputError, match="seconds per operation"):
        render_report(triangle_plan(), seconds_per_op=bad)


def test_read_plan_errors(tmp_path):
    with pytest.raises(InputError, match="no such plan file"):
        read_plan(tmp_path / "none.json")
    broken = tmp_path / "broken.json"
    broken.write_text("{not json")
    with pytest.raises(InputError, match="not valid JSON"):
        read_plan(broken)
    other = tmp_path / "outline.json"
    other.write_text(json.dumps({"name": "x", "vertices": [[0, 0], [1, 0], [0, 1]]}))
    with pytest.raises(InputError, match="not a feederkit plan"):
        read_plan(other)


def test_a_plan_that_fails_verification_gets_a_red_banner():
    good = parse(render_report(triangle_plan()))
    assert not good.with_class("banner")
    plan = triangle_plan()
    plan["root"]["branches"][1]["next"]["action_deg"] = 0.0  # now the rotation does nothing
    doc = parse(render_report(plan))
    (banner,) = [a for a in doc.with_class("banner") if a.get("id") == "verification"]
    assert banner["data-ok"] == "false"
    assert "FAILED verification" in "".join(doc.text)


def test_a_small_margin_is_warned_about():
    plan = triangle_plan()
    plan["root"]["branches"][1]["next"]["margin_deg"] = 0.04
    plan["stats"]["min_margin_deg"] = 0.04
    doc = parse(render_report(plan))
    assert [a["id"] for a in doc.with_class("caution")] == ["low-margin"]
    text = "".join(doc.text)
    assert "below \u00b11\u00b0" in text and "\u00b10.04\u00b0" in text  # never "0.0"
    assert not parse(render_report(triangle_plan())).with_class("caution")


def test_the_simulation_row_is_in_words():
    sim = {
        "trials": 10,
        "successes": 8,
        "failures": [{}, {}],
        "unsettled": [],
        "settled_pushes": 19,
        "push_agreements": 18,
        "success_rate": 0.8,
        "min_margin_deg": 18.43,
    }
    text = "".join(parse(render_report(triangle_plan(), simulation=sim)).text)
    assert "successes (oriented correctly): 8 of 10 (80%)" in text
    assert "failures 2, never settled 0" in text
    assert "18 of 19 settled pushes ended where the push function says" in text
    assert "success_rate" not in text and "min_margin_deg" not in text


def test_a_pair_named_by_the_plan_and_the_mix_is_one_row():
    given = [
        {"part_a": "tri-b", "part_b": "tri-a", "states_a": [1], "states_b": [1], "reason": "twins"}
    ]
    doc = parse(render_report(twin_plan(), unrecognizable=given))
    assert len(doc.with_class("pair")) == 1
    text = "".join(doc.text)
    assert "twins" in text and text.count("tri-a s1 ~ tri-b s1") == 1


def test_a_plan_325_operations_deep_is_reported():
    from test_plan_model import deep_plan

    doc = parse(render_report(deep_plan(325)))
    assert len(doc.with_class("tree-node")) == 326


def test_the_part_plot_is_the_plans_part():
    """The plot is drawn from the plan's hull and COM: its stable edges are the table's."""
    import base64

    from test_plan_model import golden

    doc = parse(render_report(golden("d-washer.tolerance.json")))
    (img,) = [a for t, a in doc.tags if t == "img"]
    svg = base64.b64decode(img["src"].split(",", 1)[1]).decode()
    edges = sorted(re.findall(r'id="stable-edge-(\d+)"', svg), key=int)
    table = [a["data-state"] for a in doc.with_class("stable-state")]
    assert edges == table
    assert "unstable" not in svg


def test_report_command_refuses_a_pdf(tmp_path):
    plan = tmp_path / "plan.json"
    plan.write_text(json.dumps(triangle_plan()))
    res = CliRunner().invoke(cli_app(), ["report", str(plan), "-o", str(tmp_path / "r.pdf")])
    assert isinstance(res.exception, InputError) and "HTML" in str(res.exception)
    assert not (tmp_path / "r.pdf").exists()


def test_report_command_refuses_a_file_over_the_size_limit(tmp_path):
    plan = tmp_path / "plan.json"
    plan.write_text(plan_json(triangle_plan()))
    out = tmp_path / "r.html"
    res = CliRunner().invoke(
        cli_app(), ["report", str(plan), "-o", str(out), "--max-plan-mb", "0.001"]
    )
    assert isinstance(res.exception, InputError) and "--max-plan-mb" in str(res.exception)
    assert not out.exists()


def cli_app():
    app = typer.Typer()

    @app.callback()
    def main():
        """feederkit (test harness)."""

    register(app)
    return app


def test_report_command_writes_the_page(tmp_path):
    plan = tmp_path / "plan.json"
    plan.write_text(json.dumps(triangle_plan()))
    out = tmp_path / "report.html"
    res = CliRunner().invoke(
        cli_app(), ["report", str(plan), "-o", str(out), "--seconds-per-op", "3"]
    )
    assert res.exit_code == 0, res.output
    assert str(out) in res.output
    assert out.read_text().startswith("<!DOCTYPE html>")
    assert "6 s worst case" in out.read_text()


def test_report_command_bad_input(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("[1, 2]")
    res = CliRunner().invoke(cli_app(), ["report", str(bad), "-o", str(tmp_path / "r.html")])
    assert isinstance(res.exception, InputError) and res.exception.exit_code == 2
    assert not (tmp_path / "r.html").exists()


def test_report_command_through_the_feederkit_entry_point(tmp_path):
    plan = tmp_path / "plan.json"
    plan.write_text("not json")
    code = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from feederkit.cli.app import main; "
            f"sys.exit(main(['report', {str(plan)!r}, '-o', {str(tmp_path / 'r.html')!r}]))",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert code.returncode == 2
    assert "not valid JSON" in code.stderr and "Traceback" not in code.stderr


def test_the_report_is_deterministic():
    assert render_report(twin_plan()) == render_report(twin_plan())


def test_a_changeover_report_reads_its_plan_once_and_keeps_the_files_cycle_time():
    # changeover_report reads the plan once (the design's members and the page share it):
    # the page still shows the file's stats.cycle_time.
    from feederkit.cli.changeover import changeover_report
    from feederkit.plans.readplan import as_plan

    plan = timed_triangle_plan("cell-b.toml")
    for view in (None, as_plan(plan)):
        text = "".join(parse(changeover_report(plan, [], [], 1.0, view=view)).text)
        assert "3 s per part, 20 parts per minute" in text and "cell-b.toml" in text
