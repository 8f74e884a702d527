"""Orientability judged on merged wells (docs/import.md, Not orientable by pushing): stable
states split by a barrier no deeper than the hull tolerance are one well."""

from __future__ import annotations

import fixtures_cad as fx
import pytest

from feederkit.cli.app import main
from feederkit.importers import ImportOptions, import_parts
from feederkit.mechanics import push_function


def imported(path, **options):
    _, parts = import_parts(path, ImportOptions(**options))
    (ip,) = parts
    return ip


def ellipse(a: float, b: float):
    return lambda msp: msp.add_ellipse((0, 0), major_axis=(a, 0), ratio=b / a)


def test_ellipse_is_orientable_across_its_minor_axis_vertex(tmp_path):
    # A 60 x 30 ellipse: the hull vertex at each end of the minor axis splits the deep well
    # into two stable edges about 0.005 mm below it; merged, the well is 15 mm deep.
    ip = imported(fx.write_entities(tmp_path / "ellipse.dxf", ellipse(30.0, 15.0)))
    tol = ip.hull_tolerance
    assert tol == pytest.approx(0.05)
    pf = push_function(ip.part)
    assert max(s.barrier_mm for s in pf.states) < tol  # every stable edge alone is shallow
    verdict = ip.orientability
    assert verdict.orientable, verdict.reason
    assert verdict.useful_states == 2  # the two ends of the minor axis
    assert verdict.deepest_well_mm == pytest.approx(15.0, abs=0.01)
    from feederkit.importers.orientable import wells

    found, _ = wells(pf, tol)
    assert [round(w.width_deg, 6) for w in found] == [180.0, 180.0]
    assert sorted(len(w.states) for w in found) == [2, 2]


def test_ellipse_plans(tmp_path, capsys):
    path = fx.write_entities(tmp_path / "ellipse.dxf", ellipse(30.0, 15.0))
    assert main(["plan", str(path)]) == 0
    assert "not orientable" not in capsys.readouterr().err


def test_ellipse_rounder_than_the_tolerance_is_disk_like(tmp_path):
    # axes 20 and 19.96: the merged well is 0.02 mm deep, below the 0.04 mm tolerance
    ip = imported(fx.write_entities(tmp_path / "round.dxf", ellipse(10.0, 9.98)))
    assert ip.hull_tolerance == pytest.approx(0.04, rel=1e-3)  # 0.2 % of its 20 mm
    assert not ip.orientability.orientable
    assert "disk-like" in ip.orientability.reason
    assert ip.orientability.deepest_well_mm <= ip.hull_tolerance


def test_exact_hull_keeps_every_state_a_well(tmp_path):
    # with no simplification nothing is merged: one well per stable state
    ip = imported(fx.write_gear(tmp_path / "gear.dxf", teeth=12), hull_tolerance=0.0)
    from feederkit.importers.orientable import wells

    pf = push_function(ip.part)
    found, deepest = wells(pf, 0.0)
    assert len(found) == pf.n
    assert deepest == pytest.approx(max(s.barrier_mm for s in pf.states), abs=1e-9)
