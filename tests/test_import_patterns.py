"""Real-drawing patterns that must never give the wrong part without a word (docs/import.md).

Each fixture is made here and checks what the importer must do: a cut sheet is the outer
plate, not a piece from its window; a drawing frame is skipped; a gap a CAD user left is
closed (and named); a header that gets the units wrong is pointed out; a solid with cavities
is one part; paper-space geometry is named as such.
"""

from __future__ import annotations

import math
from pathlib import Path

import fixtures_cad as fx
import numpy as np
import pytest
import shapely
import trimesh

from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts
from feederkit.importers.mesh import load_mesh, solid


def parts(path: Path, **options):
    return import_parts(path, ImportOptions(**options))[1]


def area(ip) -> float:
    return float(ip.part.outline.polygon().area)


# ---- frames and cut sheets ------------------------------------------------------------------


@pytest.mark.parametrize("frame", ["title", "double", None])
def test_cut_sheet_imports_the_plate_and_lists_the_pieces(tmp_path, frame):
    path = fx.write_cut_sheet(tmp_path / "sheet.dxf", frame=frame)
    (ip,) = parts(path)
    assert area(ip) == pytest.approx(fx.CUT_PLATE_AREA, rel=2e-4)
    assert len(ip.part.outline.holes) == 5  # the window and four mounting holes
    assert any("holes hold 2 other part(s)" in w for w in ip.warnings)
    assert sum("left out: sheet-" in w for w in ip.warnings) == 2
    assert any("skipped 1 drawing frame" in w for w in ip.warnings) == (frame is not None)
    every = parts(path, all_parts=True)
    got = sorted(round(area(p), 1) for p in every)
    want = sorted(round(a, 1) for a in (fx.CUT_PLATE_AREA, *fx.CUT_PIECE_AREAS))
    assert got == pytest.approx(want, rel=2e-4)


def test_frame_with_title_block_around_a_part_with_a_hole_is_skipped(tmp_path):
    (ip,) = parts(fx.write_framed(tmp_path / "framed.dxf"))
    assert area(ip) == pytest.approx(fx.FRAME_PART_AREA, rel=2e-4)
    assert any("skipped 1 drawing frame" in w for w in ip.warnings)


# ---- gaps ------------------------------------------------------------------------------------


def test_spline_outline_with_a_small_gap_is_closed_and_named(tmp_path):
    (closed,) = parts(fx.write_gap_spline(tmp_path / "closed.dxf", 0.0))
    (gapped,) = parts(fx.write_gap_spline(tmp_path / "gap.dxf", 0.1))  # 0.1 % of 100 mm
    oval = math.pi * 50 * 30
    assert area(closed) == pytest.approx(oval - fx.GAP_HOLE_AREA, rel=5e-3)
    assert area(gapped) == pytest.approx(area(closed), rel=1e-3)
    assert len(gapped.part.outline.holes) == 1
    notes = [w for w in gapped.warnings if "closed 1 gap" in w]
    assert len(notes) == 1 and "0.1 mm" in notes[0]
    assert not any("gap" in w for w in closed.warnings)


def test_open_outline_too_wide_to_close_is_said_to_surround_the_part(tmp_path):
    (ip,) = parts(fx.write_gap_spline(tmp_path / "wide.dxf", 5.0))  # 5 % of the size: not healed
    assert area(ip) == pytest.approx(fx.GAP_HOLE_AREA, rel=1e-3)  # only the hole is closed
    assert any("open outline" in w and "surrounds the imported part" in w for w in ip.warnings)


# ---- size and units ------------------------------------------------------------------------


def test_metre_header_on_an_inch_drawing_is_pointed_out(tmp_path):
    path = fx.write_wrong_header(tmp_path / "plate.dxf")
    (ip,) = parts(path)
    size = [w for w in ip.warnings if "across" in w]
    assert len(size) == 1
    # 8 x 5 m read in metres: 9434 mm across its diagonal (its size is its diameter)
    assert "9434 mm" in size[0] and "239.6 mm in in" in size[0] and "--units" in size[0]
    assert any("contradicts" in w and "$MEASUREMENT 0" in w for w in ip.warnings)
    (right,) = parts(path, units="in")
    assert area(right) == pytest.approx(fx.WRONG_HEADER_AREA_IN2 * 25.4**2, rel=2e-4)
    assert not any("across" in w or "contradicts" in w for w in right.warnings)


def test_plausible_header_gives_no_unit_warning(tmp_path):
    (ip,) = parts(fx.write_wrong_header(tmp_path / "inch.dxf", insunits=1, measurement=0))
    assert not any("across" in w or "contradicts" in w for w in ip.warnings)


def test_mesh_modelled_in_metres_is_imported_with_a_warning(tmp_path):
    box = trimesh.creation.box((0.04, 0.03, 0.02))  # a 40 mm housing modelled in metres
    (ip,) = parts(fx.write_mesh(box, tmp_path / "housing.stl"))
    # Its size is its resting outline's diameter (0.04 x 0.03: 0.05 mm), as the plan's.
    assert any("0.05 mm across" in w and "50 mm in m" in w for w in ip.warnings)
    assert ip.hull_tolerance == pytest.approx(0.002 * 0.05)  # of its 0.05 mm diameter
    (right,) = parts(fx.write_mesh(box, tmp_path / "housing.stl"), units="m")
    assert sorted(fx_extents(right.part.hull)) == pytest.approx([30.0, 40.0], rel=1e-6)
    assert not any("across" in w for w in right.warnings)


def fx_extents(ring) -> tuple[float, float]:
    xs, ys = [p[0] for p in ring], [p[1] for p in ring]
    return max(xs) - min(xs), max(ys) - min(ys)


def test_hull_tolerance_scales_with_a_small_part(tmp_path):
    def build(msp):
        msp.add_lwpolyline(
            [(0.5, 0, 0), (2.5, 0, fx.BULGE_90), (3, 0.5, 0), (3, 1.5, fx.BULGE_90),
             (2.5, 2, 0), (0.5, 2, fx.BULGE_90), (0, 1.5, 0), (0, 0.5, fx.BULGE_90)],
            format="xyb",
            close=True,
        )  # fmt: skip

    (ip,) = parts(fx.write_entities(tmp_path / "small.dxf", build))
    # 0.2 % of its 3.23 mm diameter, below the 0.05 cap
    assert ip.hull_tolerance == pytest.approx(0.002 * ip.part.size, rel=1e-6)
    assert ip.hull_tolerance == pytest.approx(0.00647, rel=1e-3)
    assert fx_extents(ip.part.hull) == pytest.approx((3.0, 2.0), abs=1e-6)
    (big,) = parts(fx.write_plate(tmp_path / "plate.dxf"))
    assert big.hull_tolerance == pytest.approx(0.05)


# ---- meshes: cavities and open surfaces ------------------------------------------------------


@pytest.mark.parametrize("inverted", [True, False])
def test_solid_with_a_cavity_is_one_part_with_its_com(tmp_path, inverted):
    """An inner shell facing inward is a cavity; one facing outward is an inner body (an
    insert), taken as the solid's own material with a warning, not subtracted."""
    mesh = fx.hollow_box(20.0, 6.0, (4.0, 0.0, 0.0))
    if not inverted:
        mesh = trimesh.util.concatenate([trimesh.creation.box((20.0,) * 3), _box_at(6.0, 4.0)])
    path = fx.write_mesh(mesh, tmp_path / "hollow.stl")
    m, _, _ = load_mesh(path, None)
    s = solid(m, False, str(path))
    want_x = -(6.0**3 * 4.0) / (20.0**3 - 6.0**3)  # the cavity's volume moved to the other side
    if inverted:
        assert s.com == pytest.approx((want_x, 0.0, 0.0), abs=1e-9)
        assert any("1 internal void" in w for w in s.warnings)
    else:
        assert s.com == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
        assert any("an inner body" in w and "--com" in w for w in s.warnings)
        assert not any("void" in w for w in s.warnings)
    (ip,) = parts(path)
    assert ip.source.pose.count == 6
    assert sorted(fx_extents(ip.part.hull)) == pytest.approx([20.0, 20.0], rel=1e-6)


def _box_at(side: float, x: float) -> trimesh.Trimesh:
    b = trimesh.creation.box((side,) * 3)
    b.apply_translation((x, 0.0, 0.0))
    return b


def test_bodies_side_by_side_are_refused(tmp_path):
    mesh = trimesh.util.concatenate([trimesh.creation.box((5, 5, 5)), _box_at(5.0, 20.0)])
    with pytest.raises(InputError, match="2 separate bodies"):
        parts(fx.write_mesh(mesh, tmp_path / "two.stl"))


def test_open_surface_in_pieces_is_not_a_closed_solid(tmp_path):
    box = trimesh.creation.box((10, 20, 30))
    sheet = trimesh.Trimesh(box.vertices, box.faces[3:], process=False)
    other = sheet.copy()
    other.apply_translation((50, 0, 0))
    path = fx.write_mesh(trimesh.util.concatenate([sheet, other]), tmp_path / "open.stl")
    with pytest.raises(InputError, match=r"not a closed solid \(an open surface .* in 2 pieces\)"):
        parts(path)


# ---- paper space ---------------------------------------------------------------------------


def test_paper_space_drawing_is_named_and_readable(tmp_path):
    path = fx.write_paper_space(tmp_path / "paper.dxf")
    with pytest.raises(InputError, match=r"in paper space \(layout 'Layout1'\): use --space paper"):
        parts(path)
    (ip,) = parts(path, space="paper")
    assert area(ip) == pytest.approx(800 - math.pi * 25, rel=2e-4)


def test_unknown_space_is_refused():
    with pytest.raises(InputError, match="--space must be model or paper"):
        ImportOptions(space="layout")


def test_pose_order_does_not_depend_on_the_face_order(tmp_path):
    box = trimesh.creation.box((10, 20, 30))
    order = np.random.default_rng(3).permutation(len(box.faces))
    shuffled = trimesh.Trimesh(box.vertices, box.faces[order], process=False)
    a = fx.write_mesh(box, tmp_path / "a.stl")
    b = fx.write_mesh(shuffled, tmp_path / "b.stl")
    for k in range(6):
        pa, pb = parts(a, pose=k)[0], parts(b, pose=k)[0]
        assert np.allclose(pa.source.pose.transform, pb.source.pose.transform, atol=1e-9)
        assert shapely.Polygon(pa.part.hull).equals_exact(shapely.Polygon(pb.part.hull), 1e-6)
