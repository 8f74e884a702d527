"""No strong plan, short chords: a coarser ``--hull-tolerance`` is offered only when it can work.

A finely drawn arc's short hull edges are each a possible resting edge once the shape
tolerance tilts them (docs/uncertainty.md). The hint used to offer "a drawing imported with a
coarser --hull-tolerance" for every part, but import lowers any hull tolerance at which the
simplified hull rests in two states where the outline rests in one (a near-round part, most
meshes of arcs: ``mechanics.modelerror.keeping_tolerance``), so following it changed
nothing. Now the hint names a coarser tolerance only when import keeps one that lengthens
those edges (``plans.advice.coarser_kept_hull``), and otherwise says what can help.
"""

from __future__ import annotations

import math
from pathlib import Path

import fixtures_cad as fx
import pytest
from shapely import Polygon
from shared import cli_ok

from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.advice import coarser_kept_hull, short_chords_words


def _ellipse_points() -> list[tuple[float, float]]:
    """A 60 x 54 mm ellipse drawn as 128 chords: simplified at any tolerance it rests in
    more states than its outline does."""
    return [(30 * math.cos(k * math.pi / 64), 27 * math.sin(k * math.pi / 64)) for k in range(128)]


def test_a_near_round_part_is_not_offered_a_coarser_hull_tolerance() -> None:
    pf = push_function(make_part(make_outline("ellipse", _ellipse_points())))
    assert coarser_kept_hull(pf, 0.1) is None
    words = short_chords_words([pf], 0.1)
    assert "edges as short as 1.33 mm" in words and "tilt by 8.68 degrees" in words
    assert "a smaller --shape-tolerance" in words
    assert "fewer arc points (a coarser tessellation in a mesh's CAD export)" in words
    assert "a coarser --hull-tolerance cannot help: import lowers it" in words
    assert "imported with --hull-tolerance" not in words


def test_a_part_whose_coarser_hull_is_kept_is_offered_it() -> None:
    """The rounded rectangle of tests/test_wandering.py: at 0.23 mm its hull keeps its four
    resting states and has no edge the shape tolerance tilts by 5 degrees (it has a plan
    there)."""
    box = Polygon([(0, 0), (40, 0), (40, 25), (0, 25)])
    rounded = box.buffer(-2, quad_segs=16).buffer(2, quad_segs=16)
    pf = push_function(make_part(make_outline("rr", list(rounded.exterior.coords)[:-1])))
    # The probe is 0.5 % of the part's size (its diameter, 45.67 mm), 0.2284 mm, kept.
    assert coarser_kept_hull(pf, 0.03) == pytest.approx(0.005 * pf.part.size)
    words = short_chords_words([pf], 0.03)
    assert "or the part imported with --hull-tolerance 0.228 (its resting states kept" in words
    assert "cannot help" not in words


def test_plan_on_a_mesh_of_arcs_does_not_offer_a_coarser_hull_tolerance(
    tmp_path: Path, capsys
) -> None:
    """The reviewer's cam: a mesh whose hull tolerance import lowered."""
    mesh = fx.write_mesh(fx.prism(_ellipse_points(), 5.0), tmp_path / "ell.stl")
    args = ["plan", str(mesh), "--landings", "0", "--tolerance", "0.1", "--shape-tolerance"]
    err = cli_ok(capsys, [*args, "0.1", "-o", str(tmp_path / "p.json")], code=1).err
    text = " ".join(err.split())
    assert "hull tolerance 0.025 mm, not 0.05" in text  # import lowered it
    assert "ell/pose-0's contact hull has edges as short as" in text
    assert "a coarser --hull-tolerance cannot help" in text
    assert "imported with a coarser --hull-tolerance" not in text


def test_a_small_part_s_own_short_edge_is_not_guessed_an_arc() -> None:
    """A 3 x 2 mm plate with one 0.3 mm chamfer (a new user's review: "an arc drawn as many
    chords?" on a part with no arc): the hint names the short edge and a smaller shape
    tolerance, not fewer arc points; the ellipse's 128 chords still are guessed an arc."""
    plate = [(0.0, 0.0), (3.0, 0.0), (3.0, 1.7), (2.7, 2.0), (0.0, 2.0)]
    pf = push_function(make_part(make_outline("plate", plate)))
    words = short_chords_words([pf], 0.05)
    assert "edges as short as 0.424 mm, which" in words and "a smaller --shape-tolerance" in words
    assert "arc" not in words and "hull-tolerance" not in words
    assert "a smaller --shape-tolerance may have a plan" in words  # one remedy: no comma
    ellipse = push_function(make_part(make_outline("ellipse", _ellipse_points())))
    assert "(an arc drawn as many chords?)" in short_chords_words([ellipse], 0.1)
