"""Part plots (figs. 3-6): valid PNG and SVG files that show what they should."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from PIL import Image

from feederkit.cli.part_plot import plot_command
from feederkit.errors import InputError
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.reports import part_plot_bytes, plot_format, write_part_plot

SVG_NS = "{http://www.w3.org/2000/svg}"

SHAPES = {
    # name: (vertices, holes, com)
    "rectangle": (
        [(0, 0), (2, 0), (2, 1), (0, 1)],
        [[(0.2, 0.2), (0.6, 0.2), (0.6, 0.6)]],
        (1, 0.5),
    ),
    "triangle": ([(0, 0), (1, 0), (0, 1)], [], None),
    # a quadrilateral with an unstable edge: fewer stable states than edges
    "kite": ([(0, 0), (4, 0), (4.5, 0.6), (0.3, 3)], [], None),
    "octagon": ([(1, 0), (2, 0), (3, 1), (3, 2), (2, 3), (1, 3), (0, 2), (0, 1)], [], (1.2, 1.4)),
}


def make(name):
    vertices, holes, com = SHAPES[name]
    return make_part(make_outline(name, vertices, holes, com=com))


def svg_ids(svg_bytes):
    root = ET.fromstring(svg_bytes)
    assert root.tag == f"{SVG_NS}svg"
    return [el.get("id") for el in root.iter() if el.get("id")]


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_svg_has_one_marker_per_stable_orientation(name):
    part = make(name)
    pf = push_function(part)
    ids = svg_ids(part_plot_bytes(pf, "svg"))
    expected = sorted(f"stable-orientation-{s.id}" for s in pf.states)
    assert sorted(i for i in ids if i.startswith("stable-orientation-")) == expected
    assert sorted(i for i in ids if i.startswith("stable-edge-")) == sorted(
        f"stable-edge-{s.id}" for s in pf.states
    )
    assert sorted(i for i in ids if i.startswith("radius-minimum-")) == sorted(
        f"radius-minimum-{s.id}" for s in pf.states
    )


def test_a_part_with_an_unstable_edge_marks_only_its_stable_ones():
    pf = push_function(make("kite"))
    assert "unstable" in pf.edge_kinds
    ids = svg_ids(part_plot_bytes(pf, "svg"))
    assert len([i for i in ids if i.startswith("stable-orientation-")]) == pf.n < len(pf.edge_kinds)


def test_svg_shows_the_states_numbers_and_titles_as_paths():
    svg = part_plot_bytes(push_function(make("rectangle")), "svg").decode()
    assert "<script" not in svg and "<image" not in svg
    # fonts are drawn as paths; the texts appear as comments matplotlib writes beside them
    for label in (
        "s0 e0",
        "s1 e1",
        "s2 e2",
        "s3 e3",
        "radius function",
        "push function",
        "push-diameter function",
    ):
        assert label in svg


@pytest.mark.parametrize("suffix", ["png", "svg"])
def test_write_part_plot_files_are_valid(tmp_path, suffix):
    out = tmp_path / f"rect.{suffix}"
    write_part_plot(make("rectangle"), out)
    data = out.read_bytes()
    if suffix == "png":
        assert data.startswith(b"\x89PNG\r\n\x1a\n")
        with Image.open(out) as im:
            im.verify()
        with Image.open(out) as im:
            rgb = im.convert("RGB")
            assert rgb.width > 600 and rgb.height > 900
            colours = rgb.getcolors(maxcolors=1 << 20)
            assert colours is not None and len(colours) > 50  # drawn, not blank
            # the stable edges' colours are there (state 0 blue, state 1 red)
            present = {c for _, c in colours}
            assert (31, 119, 180) in present and (214, 39, 40) in present
    else:
        svg_ids(data)
    assert oct(out.stat().st_mode & 0o777) == "0o644"


def test_plot_names_with_markup_and_dollars_are_drawn_literally(tmp_path):
    part = make_part(make_outline('<b>&"x $a$', [(0, 0), (1, 0), (0, 1)]))
    out = tmp_path / "p.svg"
    write_part_plot(part, out)
    svg_ids(out.read_bytes())  # still well-formed XML


def test_plot_format_by_suffix(tmp_path):
    assert plot_format(tmp_path / "a.PNG") == "png"
    assert plot_format("b.svg") == "svg"
    with pytest.raises(InputError, match=r"\.png or \.svg"):
        plot_format("c.pdf")


def test_plot_command(tmp_path):
    src = tmp_path / "bracket.json"
    src.write_text(
        json.dumps(
            {
                "name": "bracket",
                "vertices": [[0, 0], [3, 0], [3, 1], [0, 2]],
                "holes": [[[1, 0.5], [2, 0.5], [2, 0.8]]],
            }
        )
    )
    out = tmp_path / "bracket.svg"
    plot_command(str(src), out)
    assert re.search(rb'id="stable-orientation-0"', out.read_bytes())
    with pytest.raises(InputError, match=r"\.png or \.svg"):
        plot_command(str(src), tmp_path / "bracket.jpg")
    with pytest.raises(InputError):
        plot_command(str(tmp_path / "missing.json"), out)
    plot_command(str(src), tmp_path / "with-com.png", com=(1.5, 0.8))
    assert (tmp_path / "with-com.png").read_bytes().startswith(b"\x89PNG")


def test_matplotlib_is_not_imported_with_feederkit():
    code = (
        "import sys, feederkit, feederkit.reports, feederkit.cli.report, feederkit.cli.part_plot;"
        "import feederkit.cli.app;"
        "sys.exit(1 if 'matplotlib' in sys.modules else 0)"
    )
    assert subprocess.run([sys.executable, "-c", code], timeout=120).returncode == 0


def test_plot_command_as_a_typer_command(tmp_path):
    import typer
    from typer.testing import CliRunner

    app = typer.Typer()

    @app.callback()
    def main():
        """feederkit part (test harness)."""

    app.command("plot")(plot_command)
    src = tmp_path / "t.json"
    src.write_text(json.dumps({"name": "t", "vertices": [[0, 0], [1, 0], [0, 1]]}))
    out = tmp_path / "t.svg"
    res = CliRunner().invoke(app, ["plot", str(src), "-o", str(out), "--com", "0.3", "0.3"])
    assert res.exit_code == 0, res.output
    assert str(out) in res.output and out.read_bytes().startswith(b"<?xml")
    res = CliRunner().invoke(app, ["plot", str(src)])
    assert res.exit_code == 2  # -o is required


@settings(max_examples=4, deadline=None)
@given(
    st.lists(
        st.tuples(st.floats(0, 359.9), st.floats(5.0, 40.0)),
        min_size=3,
        max_size=9,
        unique_by=lambda p: round(p[0]),
    )
)
def test_random_parts_have_one_marker_per_stable_orientation(polar):
    import math

    pts = [(r * math.cos(math.radians(a)), r * math.sin(math.radians(a))) for a, r in sorted(polar)]
    try:
        part = make_part(make_outline("random", pts))
    except InputError:
        assume(False)
    pf = push_function(part)
    ids = svg_ids(part_plot_bytes(pf, "svg"))
    assert len([i for i in ids if i.startswith("stable-orientation-")]) == pf.n


def test_a_part_with_arcs_labels_only_its_stable_edges_and_marks_fragile_ones():
    """The d-washer's flattened arc has many short edges: only stable ones get a label."""
    from pathlib import Path

    from feederkit.mechanics.analysis import fragile_states
    from feederkit.sources import load_part

    washer = Path(__file__).resolve().parents[1] / "catalog" / "d-washer.json"
    pf = push_function(load_part(str(washer)))
    assert len(pf.edge_kinds) > pf.n  # edges that are no stable state
    svg = part_plot_bytes(pf, "svg").decode()
    assert "unstable" not in svg and "metastable" not in svg
    fragile = fragile_states(pf)
    assert fragile  # the arc's states have barriers below 10 micrometres
    for s in pf.states:
        label = f"s{s.id} e{s.edge}" + (" fragile" if s.id in fragile else "")
        assert f"<!-- {label} -->" in svg
