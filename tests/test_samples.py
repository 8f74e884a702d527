"""Real-world CAD files drawn by others (../shared/samples): each imports as its README says.

Skipped when the folder is absent.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from feederkit.importers import ImportOptions, import_parts
from feederkit.mechanics import push_function

SAMPLES = Path(__file__).resolve().parents[1].parent / "shared" / "samples"

pytestmark = pytest.mark.skipif(not SAMPLES.is_dir(), reason=f"{SAMPLES} is absent")

# file, units read, area mm2 (largest loop with its holes), holes: from the samples' README
DRAWINGS = [
    ("trimesh__apu-mount.DXF", "in", 16572.4, 11),
    ("trimesh__sliding-base.dxf", "in", 48950.3, 1),
    ("trimesh__1002_tray_bottom.DXF", "in", 109562.6, 23),
    ("trimesh__wrench.dxf", "in", 1075.7, 1),
    ("cadquery__gear.dxf", "mm", 540.8, 1),
    ("cadquery__vslot-2020_1.dxf", "mm", 162.6, 1),
]

# file, resting poses (README)
MESHES = [
    ("trimesh__featuretype.STL", 6),
    ("trimesh__angle_block.STL", 6),
    ("trimesh__idler_riser.STL", 9),
]


@pytest.mark.parametrize(("name", "units", "area", "holes"), DRAWINGS)
def test_drawings(name, units, area, holes):
    result, parts = import_parts(SAMPLES / name, ImportOptions())
    ip = parts[0]
    outline = ip.part.outline
    assert ip.source.source_units == units
    assert outline.polygon().area == pytest.approx(area, abs=0.15)
    assert len(outline.holes) == holes
    assert ip.orientability.orientable
    if name == "cadquery__gear.dxf":
        assert any("no units" in w for w in ip.warnings)
    if name == "trimesh__sliding-base.dxf":
        assert len(result.others) >= 1  # several parts in one drawing


def test_gear_sample_one_stable_edge_per_tooth_pair():
    _, (raw,) = import_parts(SAMPLES / "cadquery__gear.dxf", ImportOptions(hull_tolerance=0.0))
    _, (ip,) = import_parts(SAMPLES / "cadquery__gear.dxf", ImportOptions())
    assert len(raw.part.hull) > len(ip.part.hull)
    pf = push_function(ip.part)
    useful = ip.orientability.useful_states
    widths = sorted(s.resting_range_deg[1] - s.resting_range_deg[0] for s in pf.states)
    # 15 teeth: 15 gap edges of equal width, the other states are narrow tip lands
    assert useful == 15
    assert widths[-15:] == pytest.approx([widths[-1]] * 15, abs=1e-6)


@pytest.mark.parametrize(("name", "poses"), MESHES)
def test_meshes(name, poses):
    _, (ip,) = import_parts(SAMPLES / name, ImportOptions())
    assert ip.source.pose.count == poses
    assert ip.part.outline.polygon().area > 0


def test_plate_holes_two_likely_poses():
    _, (ip,) = import_parts(SAMPLES / "trimesh__plate_holes.STL", ImportOptions())
    probs = [
        import_parts(SAMPLES / "trimesh__plate_holes.STL", ImportOptions(pose=k))[1][
            0
        ].source.pose.probability
        for k in range(ip.source.pose.count)
    ]
    assert sum(probs[:2]) > 0.95 and probs[2] < 0.05
