"""``simulate --part`` against catalog parts (docs/simulation.md, "The match check"): the hull
tolerance stored with the catalog revision a plan was made from is the one allowed, so the
exact drawing and the exact revision a plan was made from are accepted; a warning says how
much of the distance is the import's simplification of the hull; without a catalog revision
the refusal says to give --hull-tolerance with the value the part was imported with."""

from __future__ import annotations

import json
import math
from pathlib import Path

import fixtures_cad as fx
import pytest
from shared import cli_ok, one_line_error

from feederkit.errors import InputError
from feederkit.plans.readplan import as_plan
from feederkit.sim.real import plan_drawing, real_parts

needs_mujoco = pytest.mark.skipif(
    not __import__("feederkit.sim", fromlist=["mujoco_available"]).mujoco_available(),
    reason="MuJoCo is not installed here: pip install 'feederkit[sim]' to run these",
)

COARSE = 0.3
"""The hull tolerance the bracket is added with: its R2 and R3 fillets' chords then lie
0.29 mm inside the drawn arcs (the only hull tolerance with a strong plan for it)."""


def _bulge(deg: float) -> float:
    return math.tan(math.radians(deg) / 4.0)


def _l_bracket(msp) -> None:
    """A 40 x 30 L, legs 10 mm thick, R2 outer corners, an R3 inner fillet, two holes."""
    r, ri = 2.0, 3.0
    pts = [
        (r, 0, 0),
        (40 - r, 0, _bulge(90)),
        (40, r, 0),
        (40, 10 - r, _bulge(90)),
        (40 - r, 10, 0),
        (10 + ri, 10, _bulge(-90)),
        (10, 10 + ri, 0),
        (10, 30 - r, _bulge(90)),
        (10 - r, 30, 0),
        (r, 30, _bulge(90)),
        (0, 30 - r, 0),
        (0, r, _bulge(90)),
    ]
    msp.add_lwpolyline([(x, y, 0, 0, b) for x, y, b in pts], format="xyseb", close=True)
    msp.add_circle((30, 5), 2.5)
    msp.add_circle((5, 22), 2.5)


@pytest.fixture(scope="module")
def bracket(tmp_path_factory) -> dict[str, Path]:
    """The drawing, a catalog it was added to at hull tolerance 0.3 mm, another catalog it
    was added to with the defaults, and a plan over both landings made from the first."""
    from feederkit.cli.app import main

    here = tmp_path_factory.mktemp("bracket")
    dxf = fx.write_entities(here / "l-bracket-r3.dxf", _l_bracket)
    coarse, default = here / "coarse.db", here / "default.db"
    assert (
        main(
            ["catalog", "add", str(dxf), "--hull-tolerance", str(COARSE), "--catalog", str(coarse)]
        )
        == 0
    )
    assert main(["catalog", "add", str(dxf), "--catalog", str(default)]) == 0
    plan = here / "plan.json"
    args = ["plan", "l-bracket-r3", "--tolerance", "0.5", "--shape-tolerance", "0.05"]
    assert main([*args, "-o", str(plan), "--catalog", str(coarse)]) == 0
    return {"dxf": dxf, "coarse": coarse, "default": default, "plan": plan}


@pytest.fixture()
def no_default_catalog(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """No ``$FEEDERKIT_CATALOG`` and no ``./feederkit.db``: only --catalog names one."""
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    monkeypatch.chdir(tmp_path)


def _plan(bracket: dict[str, Path]):
    return as_plan(json.loads(bracket["plan"].read_text(encoding="utf-8")))


def test_the_drawing_a_plan_was_made_from_is_accepted_with_the_stored_hull_tolerance(
    bracket, no_default_catalog
) -> None:
    plan = _plan(bracket)
    assert [p.label for p in plan.parts] == ["l-bracket-r3 (up)", "l-bracket-r3 (down)"]
    reals = real_parts(plan, [str(bracket["dxf"])], catalog=str(bracket["coarse"]))
    assert len(reals) == 2  # up as drawn, down mirrored: each against its stored landing
    where = f"l-bracket-r3@1 in {bracket['coarse']}"
    for real in reals:
        assert real.hull.mm == COARSE and real.hull.words() == f"stored with {where}"
        assert real.allowed_mm == pytest.approx(0.05 + COARSE + 0.01, abs=1e-3)
        assert 0.28 < real.hull_distance_mm < 0.3  # the fillets' chords
        assert 0.28 < real.simplified_mm < 0.3  # ... which the import made
        assert real.drawing_distance_mm < 0.02  # the part is its drawing
        line = real.tolerance_warning()
        assert line is not None and "\n" not in line
        assert "beyond the plan's declared shape tolerance of 0.05 mm" in line
        assert f"the plan's hull simplifies the drawing of {where} by 0.2" in line
        assert "(hull tolerance 0.3 mm, stored with it)" in line
        assert f"{bracket['dxf']}'s hull lies 0.0" in line and "mm from that drawing" in line
        geometry = real.to_dict()
        assert geometry["hull_tolerance_mm"] == COARSE
        assert geometry["simplified_mm"] == pytest.approx(real.simplified_mm, abs=1e-6)
        assert geometry["drawing_distance_mm"] == pytest.approx(real.drawing_distance_mm, abs=1e-6)


def test_the_catalog_revision_itself_is_accepted(bracket, no_default_catalog) -> None:
    plan = _plan(bracket)
    for source in ("l-bracket-r3", "l-bracket-r3@1"):
        (up, down) = real_parts(plan, [source], catalog=str(bracket["coarse"]))
        assert up.hull.mm == down.hull.mm == COARSE
        assert up.drawing_distance_mm == pytest.approx(0.0, abs=1e-9)


def test_the_catalog_in_use_is_the_environments(
    bracket, no_default_catalog, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("FEEDERKIT_CATALOG", str(bracket["coarse"]))
    (up, _) = real_parts(_plan(bracket), [str(bracket["dxf"])])
    assert up.hull.mm == COARSE


def test_without_the_revision_the_refusal_names_hull_tolerance(bracket, no_default_catalog) -> None:
    """No catalog, or one that holds another import of the part (the default hull tolerance):
    nothing is known of the plan's import, so the default is allowed and the line says to
    give --hull-tolerance with the value the part was imported with."""
    plan = _plan(bracket)
    assert plan_drawing(plan, 0, str(bracket["default"])) is None  # another import
    for catalog in (None, str(bracket["default"])):
        with pytest.raises(InputError) as exc:
            real_parts(plan, [str(bracket["dxf"])], catalog=catalog)
        line = str(exc.value)
        assert "\n" not in line and "not the part the plan was made for" in line
        assert "(the default a CAD import takes for the part's size: the plan does not" in line
        assert "give --hull-tolerance MM with the value it was imported with" in line


def test_a_given_hull_tolerance_says_how_much_of_the_allowance_it_is(
    bracket, no_default_catalog
) -> None:
    (up, _) = real_parts(_plan(bracket), [str(bracket["dxf"])], hull_tolerance=COARSE)
    assert up.hull.words() == "given with --hull-tolerance" and up.simplified_mm is None
    line = up.tolerance_warning()
    assert (
        "0.3 mm of it is the hull tolerance of the plan's import (given with --hull-tolerance)"
        in line
    )
    assert "not a tolerance the plan declares" in line
    assert "the part may lie up to 0.35 mm from its drawing unnoticed" in line


@needs_mujoco
def test_simulate_accepts_the_drawing_and_refuses_in_one_line_without_it(
    bracket, no_default_catalog, capsys
) -> None:
    plan, dxf = str(bracket["plan"]), str(bracket["dxf"])
    args = ["simulate", plan, "--trials", "1", "--part", f"l-bracket-r3={dxf}", "--json"]
    out = cli_ok(capsys, [*args, "--catalog", str(bracket["coarse"])])
    summary = json.loads(out.out)
    assert [g["hull_tolerance_mm"] for g in summary["geometry"]] == [COARSE, COARSE]
    assert "simplifies the drawing of l-bracket-r3@1" in summary["warnings"][0]
    err = one_line_error(capsys, args)
    assert "give --hull-tolerance MM with the value it was imported with" in err
