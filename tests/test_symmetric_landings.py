"""Landings of curved CAD parts: a mirror-symmetric outline is one landing, however its arcs'
chords were simplified (``--hull-tolerance``); an asymmetric one, however slightly, is two."""

from __future__ import annotations

import math

import fixtures_cad as fx
import pytest

from feederkit.cli.app import main
from feederkit.importers import ImportOptions, import_parts
from feederkit.landing import landings_of_outline, mirror_part
from feederkit.landing.model import congruent


def imported(path, **options):
    _, parts = import_parts(path, ImportOptions(**options))
    (ip,) = parts
    return ip


def slot(msp, length: float = 60.0, width: float = 20.0, skew: float = 0.0) -> None:
    """A length x width slot of LINEs and ARCs; ``skew`` raises a point of its upper side, a
    third of the way along, so that no mirror axis is left."""
    r = width / 2
    msp.add_line((r, 0), (length - r, 0))
    if skew:
        bump = (length / 3, width + skew)
        msp.add_line((length - r, width), bump)
        msp.add_line(bump, (r, width))
    else:
        msp.add_line((length - r, width), (r, width))
    msp.add_arc((length - r, r), r, -90, 90)
    msp.add_arc((r, r), r, 90, 270)


def d_shape(msp, skew: float = 0.0) -> None:
    """A 40 x 20 D: a straight back, flat sides 30 long and a half-disc (bulge 1); ``skew``
    moves the upper corner of the back outwards."""
    msp.add_lwpolyline(
        [(0, 0, 0), (30, 0, 1.0), (30, 20, 0), (-skew, 20, 0)], format="xyb", close=True
    )


def exactly_mirror_symmetric(outline) -> bool:
    ys = [y for _, y in outline.vertices]
    mid = (max(ys) + min(ys)) / 2
    pts = {(round(x, 9), round(y, 9)) for x, y in outline.vertices}
    return pts == {(x, round(2 * mid - y, 9)) for x, y in pts}


@pytest.mark.parametrize("build", [slot, d_shape])
def test_symmetric_curved_cad_part_has_one_landing(tmp_path, build):
    ip = imported(fx.write_entities(tmp_path / "part.dxf", build))
    assert 0.0 < ip.hull_tolerance <= 0.05  # simplified (below 0.05 where chords would hold it)
    assert exactly_mirror_symmetric(ip.part.outline)
    # The simplified hull and its mirror need not be congruent (the chords of an arc merge
    # in one order): the landings are decided on the outline's exact hull.
    (only,) = landings_of_outline(ip.part, side_probability=0.3)
    assert only.name == "up" and only.probability == 1.0 and only.merged == ("down",)


def test_symmetric_slot_plans_with_one_landing(tmp_path, capsys):
    path = fx.write_entities(tmp_path / "slot.dxf", slot)
    assert main(["plan", str(path), "--tolerance", "0.2"]) == 0
    out = capsys.readouterr().out
    assert "(down)" not in out and "cannot tell" not in out


@pytest.mark.parametrize(("build", "skew"), [(slot, 0.1), (d_shape, 0.1)])
def test_asymmetry_above_the_hull_tolerance_keeps_two_landings(tmp_path, build, skew):
    ip = imported(fx.write_entities(tmp_path / "part.dxf", lambda msp: build(msp, skew=skew)))
    assert skew > ip.hull_tolerance
    assert [x.name for x in landings_of_outline(ip.part)] == ["up", "down"]


def test_chiral_curved_part_keeps_two_landings(tmp_path):
    # a 40 x 20 plate with one rounded corner (r = 8): no mirror axis
    bulge = math.tan(math.radians(90) / 4)

    def build(msp):
        msp.add_lwpolyline(
            [(0, 0, 0), (32, 0, bulge), (40, 8, 0), (40, 20, 0), (0, 20, 0)],
            format="xyb",
            close=True,
        )

    ip = imported(fx.write_entities(tmp_path / "chiral.dxf", build))
    up, down = landings_of_outline(ip.part)
    assert not congruent(up.part, down.part)
    assert not congruent(ip.part, mirror_part(ip.part))
