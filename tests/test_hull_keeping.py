"""A simplified contact hull rests where the outline does (``mechanics.modelerror``).

Import simplifies a CAD part's hull (``--hull-tolerance``); a chord across a gentle arc is a
stable edge the arc does not have, and a plan made on it tells the robot a pose the part is
not in. The import lowers the tolerance until the simplified hull's resting states (section
3's stable states, those a breath of vibration carries across merged) are the outline's own.
"""

from __future__ import annotations

import math
from pathlib import Path

import fixtures_cad as fx
import pytest

from feederkit.cli.app import main
from feederkit.importers.model import ImportOptions
from feederkit.importers.reader import import_parts
from feederkit.mechanics.modelerror import (
    KEEP_STEPS,
    _resting,
    keeping_tolerance,
    kept_part,
    splits,
)
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sources import load_part

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def _ellipse(a: float = 30.0, b: float = 27.0, n: int = 128):
    pts = [(a * math.cos(2 * math.pi * k / n), b * math.sin(2 * math.pi * k / n)) for k in range(n)]
    return make_part(make_outline("ellipse", pts))


def _rests(part) -> list[float]:
    """The resting normals (deg) of the part's physical states."""
    return sorted(
        round((s.rest_deg[0] + s.rest_deg[1]) / 2.0 % 360.0, 1) for s in _resting(part).states
    )


def test_chords_across_an_ellipse_make_resting_states_it_does_not_have():
    exact = _ellipse()
    chorded = make_part(exact.outline, exact.com, hull_tolerance=0.05)
    # The ends of the minor axis; at the ends of the major axis the radius function has its
    # maxima, where the chords' shallow states are the facets of a hill the part rolls off.
    assert _resting(exact).n == 2
    assert _resting(chorded).n == 16
    assert splits(_resting(chorded), _resting(exact))
    assert not splits(_resting(exact), _resting(exact))
    kept = keeping_tolerance(exact, 0.05)
    assert kept.lowered and (kept.model, kept.outline) == (16, 2)
    assert kept.tolerance == pytest.approx(0.025)
    part, same = kept_part(exact, 0.05)
    assert same == kept and len(part.hull) <= len(exact.hull)
    assert not splits(_resting(part), _resting(exact))


def test_a_tolerance_that_splits_at_every_halving_gives_the_exact_hull():
    exact = _ellipse(30.0, 29.5, 512)
    kept = keeping_tolerance(exact, 0.05 * 2**7)  # 6.4 mm: still above 0.05 after 4 halvings
    assert (kept.tolerance, kept.model, kept.outline) == (0.0, 7, 2)
    assert KEEP_STEPS == 4
    assert kept_part(exact, kept.asked)[0].hull == exact.hull


@pytest.mark.parametrize("name", ["l-bracket", "t-clip", "chamfered-plate", "d-washer"])
def test_the_catalog_parts_keep_what_they_rest_on(name):
    exact = load_part(str(CATALOG / f"{name}.json"))
    part, kept = kept_part(exact, 0.05)
    assert _rests(part) == _rests(exact)
    if name != "d-washer":  # polygons: nothing to lower
        assert kept is None or not kept.lowered


def _washer_with_flat(msp) -> None:
    """An R15 washer with a flat at y = 12 and an R6 hole: it rests on the flat (27 mm) or on
    its arc's lowest point (the COM is 0.87 mm below the centre), also 27 mm."""
    x = math.sqrt(15.0**2 - 12.0**2)
    a0, a1 = math.degrees(math.atan2(12.0, -x)), math.degrees(math.atan2(12.0, x)) + 360.0
    bulge = math.tan(math.radians(a1 - a0) / 4.0)
    msp.add_lwpolyline([(x, 12.0, 0, 0, 0), (-x, 12.0, 0, 0, bulge)], format="xyseb", close=True)
    msp.add_circle((0.0, 0.0), 6.0)


def test_the_import_lowers_the_tolerance_of_a_washer_with_a_flat(tmp_path):
    path = fx.write_entities(tmp_path / "washer.dxf", _washer_with_flat)
    (ip,) = import_parts(path, ImportOptions())[1]
    assert ip.hull_tolerance < 0.05
    (note,) = [w for w in ip.warnings if w.startswith("hull tolerance")]
    assert "not 0.05" in note and "rests in two states where the outline rests in one" in note
    assert "simplified 33, outline 2" in note
    states = _resting(ip.part).states
    assert len(states) == 2  # the flat and the arc's lowest point, nothing between
    arc = next(s for s in states if s.rest_deg[0] < 270.0 < s.rest_deg[1])
    assert arc.diameter[0] == pytest.approx(27.0, abs=1e-6)  # the arc's own width is read
    # At the asked tolerance the chords hold the washer in 33 states.
    chorded = make_part(ip.part.outline, ip.part.com, hull_tolerance=0.05)
    assert _resting(chorded).n > 2


def test_an_ellipse_drawing_gets_a_plan_at_the_default_tolerance(tmp_path, capsys):
    """At 0.05 mm the 60 x 54 mm ellipse had no strong plan at 1 degree of rotation error
    (its chords' states, 0.33 degrees wide, cannot be aimed at); on the kept hull it has one
    (100 of 100 in ``feederkit simulate``, docs/import.md)."""

    def ellipse(msp) -> None:
        msp.add_ellipse((0.0, 0.0), major_axis=(30.0, 0.0), ratio=0.9)

    path = fx.write_entities(tmp_path / "ellipse.dxf", ellipse)
    assert main(["plan", str(path), "--sensorless", "--json"]) == 0
    out = capsys.readouterr()
    assert "hull tolerance 0.025 mm, not 0.05" in out.err
