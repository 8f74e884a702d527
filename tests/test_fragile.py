"""Fragile stable states: real in the kinematic model, decided by chance on a real belt."""

from __future__ import annotations

import math
from pathlib import Path

from feederkit.mechanics import push_function
from feederkit.mechanics.analysis import (
    FRAGILE_LINES,
    fragile_states,
    fragile_warning,
    fragile_warnings,
)
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sources import load_part

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def test_plain_shapes_have_no_fragile_state() -> None:
    for name in ("rectangle-2x1", "isosceles-right-triangle", "octagon", "quadrilateral"):
        pf = push_function(load_part(str(CATALOG / f"{name}.json")))
        assert fragile_states(pf) == ()
        assert fragile_warning(pf) is None


def test_nearly_collinear_edges_make_fragile_states() -> None:
    # A 40 x 10 bar whose bottom is two edges meeting at a 0.5-degree bend, COM above the bend:
    # the part rests on either half with a barrier of a few micrometres.
    bend = 20.0 * 0.00872665  # tan(0.5 deg) * 20 mm
    outline = make_outline("bent-bar", [(0, 0), (20, -bend), (40, 0), (40, 10), (0, 10)])
    pf = push_function(make_part(outline))
    fragile = fragile_states(pf)
    bottom = {s.id for s in pf.states if abs(s.normal_deg - 270.0) < 1.0}
    assert len(bottom) == 2
    assert bottom and bottom <= set(fragile)
    assert all(pf.states[i].barrier_mm < 0.04 for i in fragile)
    warning = fragile_warning(pf)
    assert warning is not None and "bent-bar" in warning and "simulate" in warning


def test_flattened_arc_facets_are_fragile_but_the_flat_is_not() -> None:
    # The washer's flat (normal 270) is its one robust state; the facets of its flattened arc
    # are stable in the model with sub-micrometre barriers, even where their ranges are wide.
    pf = push_function(load_part(str(CATALOG / "d-washer.json")))
    flat = next(s for s in pf.states if abs(s.normal_deg - 270.0) < 1e-6)
    assert set(fragile_states(pf)) == {s.id for s in pf.states} - {flat.id}


def test_plan_and_analyze_warn_about_fragile_states(capsys) -> None:  # noqa: ANN001
    from feederkit.cli.app import main

    bracket = str(CATALOG / "l-bracket.json")
    assert main(["plan", bracket, "--tolerance", "0.5", "--json"]) == 0
    err = capsys.readouterr().err
    assert "fragile states 1" in err and "simulate" in err
    assert main(["part", "analyze", bracket, "--json"]) == 0
    assert "fragile states 1" in capsys.readouterr().err
    rectangle = str(CATALOG / "rectangle-2x1.json")
    assert main(["plan", rectangle, "--tolerance", "0.01", "--json"]) == 0
    assert "fragile" not in capsys.readouterr().err


def _bent_bar(name: str, degrees: float) -> object:
    """A 40 x 10 bar whose bottom bends by ``degrees``: two fragile states (see above)."""
    bend = 20.0 * math.tan(math.radians(degrees))
    return push_function(
        make_part(make_outline(name, [(0, 0), (20, -bend), (40, 0), (40, 10), (0, 10)]))
    )


def test_a_large_mix_gets_one_line_for_its_fragile_parts() -> None:
    few = [_bent_bar(f"bar-{k}", 0.5 + 0.1 * k) for k in range(FRAGILE_LINES)]
    lines = fragile_warnings(few)
    assert lines == [fragile_warning(pf) for pf in few]
    many = [*few, _bent_bar("bar-x", 0.45)]
    octagon = push_function(load_part(str(CATALOG / "octagon.json")))
    (line,) = fragile_warnings([*many, octagon])
    assert line.startswith(f"{len(many)} parts have fragile states")
    for pf in many:
        found = fragile_states(pf)
        ids = ", ".join(map(str, found))
        # "bar (0)" read as no fragile state: the states are named as states.
        assert f"{pf.part.name} ({'state' if len(found) == 1 else 'states'} {ids})" in line
    assert "octagon" not in line and "simulate" in line
