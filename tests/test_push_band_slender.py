"""A slender part (radius of gyration under 0.27 of its size) checked at 20 mm gets the wide
push band at its ordinary hilltops.

The catalog's isosceles right triangle (1.4 mm, simulated at 20 mm): the physics carried pushes
over its hilltops from up to 3.4 degrees (its 45-degree corners) and 4.0 (its right angle), and
its sensorless plan made with the fixed 2-degree band failed 3 of 400 trials, each a drop
3.2-3.4 degrees before a 45-degree corner's hilltop carried over it (docs/uncertainty.md, "Push
bands").
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from shared import run_cli

from feederkit.mechanics.uncertain import (
    PUSH_BAND_DEG,
    SLENDER_BAND_DEG,
    SLENDER_GYRATION_REL,
    gyration_rel,
    ordinary_push_band_deg,
    uncertain_mechanics,
)
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sources import load_part
from feederkit.uncertainty import Uncertainty

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def _reaches(part) -> list[float]:
    mech = uncertain_mechanics(part, Uncertainty(1.0, 0.0, 0.0))
    return [r for b in mech.bands for r in (b.divergent_deg - b.lo_deg, b.hi_deg - b.divergent_deg)]


def test_the_triangles_hilltops_get_the_slender_band():
    tri = load_part(str(CATALOG / "isosceles-right-triangle.json"))
    assert gyration_rel(tri) == pytest.approx(1.0 / 3.0 / math.sqrt(2.0), rel=1e-9)  # 0.236
    reaches = _reaches(tri)
    assert len(reaches) == 6
    # Beyond the 4.0 degrees the physics carried pushes from, at every hilltop, both flanks.
    assert all(r == pytest.approx(SLENDER_BAND_DEG, abs=1e-9) and r > 4.0 + 1.0 for r in reaches)


@pytest.mark.parametrize("name", ["rectangle-2x1", "quadrilateral", "equilateral-triangle"])
def test_compact_parts_keep_the_fixed_band(name):
    part = load_part(str(CATALOG / f"{name}.json"))
    assert gyration_rel(part) > SLENDER_GYRATION_REL + 0.01  # carried from 2.2 degrees at most
    assert all(r == pytest.approx(PUSH_BAND_DEG, abs=1e-9) for r in _reaches(part))


def test_the_slender_band_falls_to_the_fixed_one_by_30_mm():
    def tri(size_mm: float):
        leg = size_mm / math.sqrt(2.0)
        return make_part(make_outline("t", [(0, 0), (leg, 0), (0, leg)]))

    assert ordinary_push_band_deg(tri(1.4)) == pytest.approx(SLENDER_BAND_DEG)
    assert ordinary_push_band_deg(tri(20.0)) == pytest.approx(SLENDER_BAND_DEG)
    assert ordinary_push_band_deg(tri(25.0)) == pytest.approx((SLENDER_BAND_DEG + 2.0) / 2.0)
    assert ordinary_push_band_deg(tri(30.0)) == pytest.approx(PUSH_BAND_DEG)
    assert ordinary_push_band_deg(tri(60.0)) == pytest.approx(PUSH_BAND_DEG)


@pytest.mark.slow
def test_the_triangles_sensorless_plan_holds_in_the_physics_check(tmp_path, capsys):
    pytest.importorskip("mujoco")
    out = tmp_path / "tri.json"
    src = str(CATALOG / "isosceles-right-triangle.json")
    rc, _, _ = run_cli(capsys, "plan", src, "--sensorless", "-o", str(out))
    assert rc == 0
    assert json.loads(out.read_text(encoding="utf-8"))["stats"]["length"] == 4
    rc, stdout, _ = run_cli(
        capsys, "simulate", str(out), "--trials", "400", "--seed", "1", "--json"
    )
    got = json.loads(stdout)
    assert got["wrong_accepts"] == 0 and got["successes"] == 400
