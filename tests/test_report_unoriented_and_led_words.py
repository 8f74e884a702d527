"""The HTML report's words where they were wrong (a new user's review of a changeover read by
an LED array):

- poses of one part that a result lists together are called "symmetric or nearly so" only
  when they look alike (outline and holes compared, ``mechanics.symmetry.unlike_pairs``);
  poses that do not look alike, a slotted link end for end, are named as such: the part is
  not oriented between them (a leaf of its own kind, a banner, a list);
- an operation node that no start reaches on the nominal push says so, as its leaves do,
  instead of "0 possible states";
- the sensor design of a plan read by an LED array says it in the array's terms too: the
  tolerance the array reads as and the coarsest pitch that keeps the mix recognizable.
"""

from __future__ import annotations

import json
import math
import os
import random
import re
from pathlib import Path

import pytest
from test_report import long_sides_plan, op, parse, part_entry, plan_file, result

from feederkit.outline import make_outline
from feederkit.plans import plan_from_dict
from feederkit.reports import render_report
from feederkit.reports.design_html import design_section, led_pitch, led_tolerance
from feederkit.reports.report import plan_section
from feederkit.sensors import LedSensor, ToleranceSensor

# --- poses that look alike, and poses that do not ---------------------------------------------

PLATE = [(0, 0), (40, 0), (40, 20), (0, 20)]
"""A 40 x 20 plate; its COM is put at the centre, so its hull is 180-degree symmetric."""


def circle(cx, cy, r, n=32):
    return [
        (cx + r * math.cos(2 * math.pi * k / n), cy + r * math.sin(2 * math.pi * k / n))
        for k in range(n)
    ]


def plate_plan():
    """The plate, sensorless: rotating 45 degrees sends every state onto a long side, s0 or
    s2, which no push or reading tells apart (the hull is symmetric under 180 degrees)."""
    return long_sides_plan("plate", PLATE, (20, 10))


def outline_with_hole(x):
    """The plate's outline with an R4 hole at (x, 10), COM at the centre as planned."""
    return make_outline("plate", PLATE, [circle(x, 10, 4)], com=(20, 10))


def test_poses_whose_holes_differ_are_not_called_symmetric():
    # the docs' example: an R4 hole 12 mm off centre, the plate lying on either long side
    doc = parse(render_report(plate_plan(), outlines={"plate": outline_with_hole(32)}))
    text = "".join(doc.text)
    assert "symmetric or nearly so; each is a correct answer" not in text
    leaves = doc.with_class("result")
    assert len(leaves) == 1 and "unoriented" in leaves[0]["class"].split()
    assert not doc.with_class("symmetric")
    assert "not oriented: plate, one of 2 poses that no plan tells apart and that do not look" in (
        text
    )
    ids = {a.get("id") for _, a in doc.tags}
    assert {"unoriented", "unoriented-poses"} <= ids and "alike-poses" not in ids
    assert "plate states 0 and 2 (poses 0 and 180 degrees)" in text
    assert "the part is not oriented between them" in text


def test_poses_that_look_alike_stay_a_correct_answer():
    doc = parse(render_report(plate_plan(), outlines={"plate": outline_with_hole(20)}))
    text = "".join(doc.text)
    assert "Poses no plan tells apart that look alike (symmetric or nearly so; each is a" in text
    assert "plate: states s0, s2 at leaf 2" in text
    assert [n["class"].split()[-1] for n in doc.with_class("result")] == ["symmetric"]
    ids = {a.get("id") for _, a in doc.tags}
    assert "unoriented" not in ids and "unoriented-poses" not in ids


def test_without_an_outline_the_report_says_it_compared_hulls_only():
    # a plan file records the hull only: whether holes tell the poses apart is not known
    doc = parse(render_report(plate_plan()))
    text = "".join(doc.text)
    ids = {a.get("id") for _, a in doc.tags}
    assert "alike-hulls" in ids and "alike-poses" not in ids and "unoriented" not in ids
    assert "Poses no plan tells apart whose contact hulls look alike" in text
    assert "The plan file records only the hull" in text


GOLDEN = Path(__file__).resolve().parent / "golden"


def test_the_heptagons_unlike_poses_are_named_from_the_hull_alone():
    # Fig. 17: three unlike poses its push function permutes; the hull alone shows it
    plan = json.loads((GOLDEN / "heptagon-fig17.sensorless.json").read_text(encoding="utf-8"))
    doc = parse(render_report(plan))
    assert [n["class"].split()[-1] for n in doc.with_class("result")] == ["unoriented"]
    assert "the part is not oriented between them" in "".join(doc.text)
    octagon = json.loads((GOLDEN / "octagon.sensorless.json").read_text(encoding="utf-8"))
    kinds = {n["class"].split()[-1] for n in parse(render_report(octagon)).with_class("result")}
    assert kinds == {"symmetric"}  # a regular octagon's poses look alike


# --- an operation node no start reaches on the nominal push -----------------------------------


def unreached_plan(rotation_error_deg):
    """The 2 x 1 rectangle read within 0.1 mm: a branch between its two diameters (1, 2)
    that no state reads on the nominal push leads to an operation node."""
    rect = part_entry("rect", [(0, 0), (2, 0), (2, 1), (0, 1)], com=(1, 0.5))
    narrow, wide = result((rect, 0), (rect, 2)), result((rect, 1), (rect, 3))
    inner = op(90.0, 10.0, ([0.85, 1.15], narrow), ([1.85, 2.15], wide))
    root = op(None, None, ([0.85, 1.15], narrow), ([1.3, 1.7], inner), ([1.85, 2.15], wide))
    stats = {
        "length": 2,
        "expected_length": 1.0,
        "min_margin_deg": 10.0,
        "optimal": False,
        "lower_bound": 1,
    }
    data = plan_file([rect], {"model": "tolerance", "tolerance_mm": 0.1}, root, stats)
    data["version"] = 2
    data["uncertainty"] = {
        "rotation_error_deg": rotation_error_deg,
        "shape_tolerance_mm": 0.0,
        "com_tolerance_mm": 0.0,
    }
    return plan_from_dict(data)


def node_heads(html):
    return {
        int(m.group(1)): re.sub(r"<[^>]+>", "", m.group(2))
        for m in re.finditer(r'data-node-id="(\d+)".*?<div class="node-head">(.*?)</div>', html)
    }


def test_an_operation_node_no_start_reaches_says_so_not_zero_states():
    heads = node_heads(plan_section(unreached_plan(1.0)))
    assert "0 possible states" not in " ".join(heads.values())
    assert "on the nominal push (no rotation error) no start reaches it" in heads[2]
    assert "1 possible state" not in heads[2]


def test_on_the_ideal_model_an_unreached_operation_node_is_flagged():
    html = plan_section(unreached_plan(0.0))
    assert "following the plan, no state reaches it" in node_heads(html)[2]
    assert '<span class="warn">node 2' in html


# --- the sensor design in an LED array's terms -------------------------------------------------

DESIGN = {
    "sensor_model": "tolerance",
    "critical_tolerance_mm": 1.3501,
    "pairs": [{"a": "link/up", "b": "bracket/up", "critical_tolerance_mm": 1.3501}],
    "lengths": [
        {"tolerance_mm": [0.0, 0.5], "length": 2, "expected": 1.5},
        {"tolerance_mm": [0.5, 1.3501], "length": 3, "expected": 1.8142},
    ],
    "model": "strong plans at the declared uncertainty",
    "answer": "this mix is recognizable with a tolerance up to 1.3501 mm",
}


def test_an_led_array_reads_as_half_its_pitch_plus_its_noise():
    # every count the array can give a diameter leaves it within that of (count + 1/2) pitch
    rng = random.Random(7)
    for _ in range(2000):
        sensor = LedSensor(rng.uniform(0.01, 2.0), rng.uniform(0.0, 0.3))
        d = rng.uniform(0.0, 60.0)
        lo, hi = sensor.counts(d)
        worst = max(abs((c + 0.5) * sensor.pitch - d) for c in range(lo, hi + 1))
        assert worst <= led_tolerance(sensor) + 1e-9
    assert led_pitch(led_tolerance(LedSensor(0.3, 0.02)), 0.02) == pytest.approx(0.3)
    assert led_pitch(0.02, 0.02) is None


def test_the_sensor_design_of_an_led_plan_names_the_coarsest_pitch():
    html = design_section(DESIGN, LedSensor(0.1, 0.02))
    text = "".join(parse(html).text)
    assert "this mix is recognizable with a tolerance up to 1.3501 mm" in text  # kept
    assert "pitch 0.1 mm, noise 0.02 mm" in text and "this one reads as 0.07 mm" in text
    assert "within the 1.3501 mm that keeps the mix recognizable" in text
    assert "every pitch below 2.66 mm keeps it recognizable" in text  # (1.3501 - 0.02) / 0.5
    assert "feederkit design sensor --pitches" in text
    assert "LED pitch reading as finely (noise 0.02 mm)" in text
    assert "below 0.96 mm (this plan's array: 0.1 mm)" in text  # the first step's pitches
    assert "0.96 to 2.66 mm" in text


def test_an_led_array_coarser_than_the_design_says_so():
    text = "".join(parse(design_section(DESIGN, LedSensor(3.0, 0.02))).text)
    assert "this one reads as 1.52 mm, not within the 1.3501 mm" in text
    text = "".join(parse(design_section(DESIGN, LedSensor(0.1, 1.4))).text)
    assert "at a noise of 1.4 mm no pitch reads that finely" in text


def test_a_tolerance_plan_keeps_its_design_words():
    for sensor in (None, ToleranceSensor(0.2)):
        html = design_section(DESIGN, sensor)
        assert 'id="led-terms"' not in html and "LED pitch" not in html


# --- the review's changeover, end to end ---------------------------------------------------------


def bulge(deg):
    return math.tan(math.radians(deg) / 4)


def draw_parts(folder):
    """The review's slotted link (a stadium with a slot at one end and a hole at the other)
    and mini-bracket (a notch with an R1 fillet, a hole), drawn as the review drew them."""
    ezdxf = pytest.importorskip("ezdxf")
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    m = doc.modelspace()
    b = bulge(180)
    m.add_lwpolyline([(0, -6, 0), (38, -6, b), (38, 6, 0), (0, 6, b)], format="xyb", close=True)
    slot = [(8, -2.5, 0), (24, -2.5, b), (24, 2.5, 0), (8, 2.5, b)]
    m.add_lwpolyline(slot, format="xyb", close=True)
    m.add_circle((38, 0), 3)
    doc.saveas(folder / "slotted-link.dxf")
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    m = doc.modelspace()
    notch = [(0, 0, 0), (15, 0, 0), (15, 4, 0), (10, 4, 0), (10, 8, bulge(90)), (9, 9, 0)]
    m.add_lwpolyline([*notch, (0, 9, 0)], format="xyb", close=True)
    m.add_circle((4, 4.5), 1.5)
    doc.saveas(folder / "mini-bracket.dxf")


@pytest.fixture(scope="module")
def changeover_page(tmp_path_factory):
    """``changeover compile`` of the slotted link and the mini-bracket face up, LED array
    0.1 mm, at the review's tolerances, with ``--report``: the exit code and the page."""
    from feederkit.cli.app import main

    folder = tmp_path_factory.mktemp("review")
    parts = folder / "parts"
    parts.mkdir()
    draw_parts(parts)
    db, page = folder / "fk.db", folder / "report.html"
    here = os.getcwd()
    os.chdir(folder)  # no cell profile here: the built-in defaults
    try:
        assert main(["catalog", "import", str(parts), "--catalog", str(db)]) == 0
        code = main(
            [
                "changeover",
                "compile",
                "w49c",
                "--mix",
                "slotted-link,mini-bracket",
                "--landings",
                "up",
                "--led-pitch",
                "0.1",
                "--noise",
                "0.02",
                "--rotation-error",
                "0.5",
                "--shape-tolerance",
                "0.05",
                "--com-tolerance",
                "0.1",
                "--catalog",
                str(db),
                "-o",
                str(folder / "plan.json"),
                "--report",
                str(page),
            ]
        )
    finally:
        os.chdir(here)
    return code, page.read_text(encoding="utf-8")


def test_the_slotted_link_end_for_end_is_not_oriented_in_the_report(changeover_page):
    code, html = changeover_page
    assert code == 1  # compile names the unlike poses and exits 1, the plan written
    doc = parse(html)
    text = "".join(doc.text)
    assert "symmetric or nearly so; each is a correct answer" not in text
    unoriented = doc.with_class("unoriented")
    assert unoriented and not doc.with_class("symmetric")
    assert "slotted-link (up) states 0 and 1 (poses 0 and 180 degrees)" in text


def test_no_node_of_the_changeover_reads_zero_possible_states(changeover_page):
    _, html = changeover_page
    assert "0 possible states" not in html
    heads = node_heads(html)
    empty = [k for k, h in heads.items() if "no start reaches it" in h and "operation" in h]
    ops = re.findall(r'class="tree-node op" data-node-id="(\d+)"[^>]*data-states="0"', html)
    assert {int(k) for k in ops} <= set(empty)


def test_the_changeover_design_is_said_in_the_led_arrays_terms(changeover_page):
    _, html = changeover_page
    text = "".join(parse(html).text)
    assert "In this plan's LED array's terms (pitch 0.1 mm, noise 0.02 mm)" in text
    assert "this one reads as 0.07 mm" in text
    assert re.search(r"every pitch below \d+(\.\d+)? mm keeps it recognizable", text)
