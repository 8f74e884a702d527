"""Landings as values (docs/landings.md): sides of flat parts, mesh poses, plans over them."""

from __future__ import annotations

import math

import pytest
import trimesh

from feederkit.errors import InputError
from feederkit.landing import (
    congruence_rotations,
    congruent,
    landings_of_outline,
    mirror_part,
    select_landings,
)
from feederkit.landing.mesh import landings_of_mesh
from feederkit.landing.plan import plan_landings
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL

TOL = 1e-9


def ell():
    """An L with unequal legs (40 and 25) and an off-centre hole: a chiral part."""
    return make_part(
        make_outline(
            "ell",
            [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)],
            [[(30, 3), (34, 3), (34, 7), (30, 7)]],
        )
    )


def plate(name, vertices, holes=()):
    return make_part(make_outline(name, vertices, holes))


def solid_angle_share(x: float, y: float, d: float) -> float:
    """The share of 4 pi seen from the centre through a 2x by 2y face at distance d."""
    return 4.0 * math.atan(x * y / (d * math.sqrt(x * x + y * y + d * d))) / (4.0 * math.pi)


def test_down_is_the_mirror_image_about_the_y_axis():
    part = ell()
    up, down = landings_of_outline(part)
    assert (up.name, down.name) == ("up", "down")
    assert up.probability == pytest.approx(0.5) and down.probability == pytest.approx(0.5)
    assert down.part.name == "ell/down" and up.part.name == "ell/up"
    assert down.part.com[0] == pytest.approx(-part.com[0], abs=TOL)
    assert down.part.com[1] == pytest.approx(part.com[1], abs=TOL)
    mirrored = {(-x, y) for x, y in part.outline.vertices}
    assert set(down.part.outline.vertices) == mirrored
    assert set(down.part.outline.holes[0]) == {(-x, y) for x, y in part.outline.holes[0]}
    poly = down.part.outline.polygon()
    assert poly.area == pytest.approx(part.outline.polygon().area, rel=1e-12)
    assert poly.exterior.is_ccw == part.outline.polygon().exterior.is_ccw
    # The mirrored hull is counter-clockwise, numbered from its lowest-then-leftmost vertex.
    hull = down.part.hull
    assert hull[0] == min(hull, key=lambda p: (p[1], p[0]))
    area2 = sum(hull[i - 1][0] * hull[i][1] - hull[i][0] * hull[i - 1][1] for i in range(len(hull)))
    assert area2 > 0
    twice = mirror_part(down.part)
    assert set(twice.hull) == set(part.hull) and twice.com == pytest.approx(part.com)


def test_chiral_part_has_two_landings_a_sensor_tells_apart():
    landings = landings_of_outline(ell(), side_probability=0.7)
    assert [x.name for x in landings] == ["up", "down"]
    assert [x.probability for x in landings] == pytest.approx([0.7, 0.3])
    assert not congruent(landings[0].part, landings[1].part)
    planned = plan_landings(landings, ToleranceSensor(0.5))
    assert planned.indistinguishable == ()
    leaves = planned.leaves()
    seen = set()
    for leaf in leaves:
        assert {r.landing for r in leaf} in ({"up"}, {"down"})
        assert all(r.part == "ell" for r in leaf)
        seen |= {r.landing for r in leaf}
    assert seen == {"up", "down"}
    parts = [(e["name"], e["landing"]) for e in planned.made.plan["parts"]]
    assert parts == [("ell", "up"), ("ell", "down")]


def test_without_a_sensor_the_sides_are_reported_indistinguishable():
    planned = plan_landings(landings_of_outline(ell()), NoSensor(), uncertainty=IDEAL)
    (pair,) = planned.indistinguishable
    assert {pair.a.name, pair.b.name} == {"up", "down"}
    assert pair.witness.kind == "sensorless"


@pytest.mark.parametrize(
    "vertices",
    [
        [(0, 0), (30, 0), (30, 10), (0, 10)],  # rectangle
        [(0, 0), (30, 0), (15, 40)],  # isosceles triangle
        [(0, 0), (30, 0), (30, 30), (0, 30)],  # square
        [(0, 0), (40, 0), (40, 10), (0, 10), (-10, 5)],  # symmetric about y = 5 only
    ],
)
def test_mirror_symmetric_part_has_one_landing(vertices):
    part = plate("sym", vertices)
    (only,) = landings_of_outline(part, side_probability=0.3)
    assert only.name == "up" and only.probability == 1.0 and only.merged == ("down",)
    with pytest.raises(InputError, match="same shape as up"):
        select_landings((only,), ["down"])


def test_scalene_triangle_has_two_landings():
    part = plate("tri", [(0, 0), (30, 0), (10, 40)])
    assert [x.name for x in landings_of_outline(part)] == ["up", "down"]


def test_holes_decide_congruence_where_the_push_function_cannot():
    # Hull and COM are symmetric (the same push-diameter function on both sides), but the
    # holes lie on opposite diagonals: two landings, which no plan can tell apart.
    square = [(0, 0), (40, 0), (40, 20), (0, 20)]
    holes = [[(8, 3), (12, 3), (12, 7), (8, 7)], [(28, 13), (32, 13), (32, 17), (28, 17)]]
    part = plate("holes", square, holes)
    up, down = landings_of_outline(part)
    planned = plan_landings((up, down), ToleranceSensor(0.5), uncertainty=IDEAL)
    (pair,) = planned.indistinguishable
    assert pair.witness.kind == "same-push-diameter"
    assert any({r.landing for r in leaf} == {"up", "down"} for leaf in planned.leaves())
    # The same holes on one diagonal's mirror axis make one landing.
    sym = plate("sym-holes", square, [holes[0], [(28, 3), (32, 3), (32, 7), (28, 7)]])
    assert len(landings_of_outline(sym)) == 1


def test_congruence_finds_the_rotation():
    part = ell()
    turned = make_part(
        make_outline(
            "turned",
            [(-y, x) for x, y in part.outline.vertices],
            [[(-y, x) for x, y in part.outline.holes[0]]],
        )
    )
    assert congruence_rotations(part, turned) == [pytest.approx(90.0)]
    moved_hole = plate(
        "moved",
        list(part.outline.vertices),
        [[(x - 20, y) for x, y in part.outline.holes[0]]],
    )
    assert not congruent(part, moved_hole)


@pytest.mark.parametrize("p", [0.0, 1.0, -0.5, 1.5, float("nan"), True, "0.5"])
def test_side_probability_must_lie_strictly_between_0_and_1(p):
    with pytest.raises(InputError, match="strictly between 0 and 1"):
        landings_of_outline(ell(), side_probability=p)


def test_select_landings_names_the_ones_there_are():
    landings = landings_of_outline(ell())
    assert select_landings(landings, "all") == landings
    assert [x.name for x in select_landings(landings, ["down"])] == ["down"]
    with pytest.raises(InputError, match="no landing pose-3; its landings: up, down"):
        select_landings(landings, ["pose-3"])
    with pytest.raises(InputError, match="invalid landing"):
        select_landings(landings, ["sideways"])


@pytest.fixture(scope="module")
def box_landings(tmp_path_factory):
    path = tmp_path_factory.mktemp("box") / "box.stl"
    trimesh.creation.box((10.0, 20.0, 30.0)).export(path)
    return landings_of_mesh(path, name="box")


def test_box_has_three_landings_with_solid_angle_probabilities(box_landings):
    assert [x.name for x in box_landings] == ["pose-0", "pose-2", "pose-4"]
    assert [len(x.merged) for x in box_landings] == [1, 1, 1]
    expected = [
        2 * solid_angle_share(15.0, 10.0, 5.0),  # on a 30 x 20 face
        2 * solid_angle_share(15.0, 5.0, 10.0),  # on a 30 x 10 face
        2 * solid_angle_share(10.0, 5.0, 15.0),  # on a 20 x 10 face
    ]
    assert [x.probability for x in box_landings] == pytest.approx(expected, abs=1e-3)
    assert sum(x.probability for x in box_landings) == pytest.approx(1.0, abs=1e-6)
    sides = [sorted(x.part.outline.polygon().bounds[2:]) for x in box_landings]
    assert sides == [pytest.approx([10, 15]), pytest.approx([5, 15]), pytest.approx([5, 10])]


def test_box_landings_are_told_apart_by_a_sensor(box_landings):
    planned = plan_landings(box_landings, ToleranceSensor(0.5))
    assert planned.indistinguishable == ()
    for leaf in planned.leaves():
        assert len({r.landing for r in leaf}) == 1  # symmetric states of one landing only
    assert {r.landing for leaf in planned.leaves() for r in leaf} == {"pose-0", "pose-2", "pose-4"}


def test_plan_landings_refuses_nothing_and_duplicates():
    landings = landings_of_outline(ell())
    with pytest.raises(InputError, match="no landings"):
        plan_landings((), ToleranceSensor(0.5))
    with pytest.raises(InputError, match="given twice"):
        plan_landings((landings[0], landings[0]), ToleranceSensor(0.5))


def test_a_chiral_plate_as_a_mesh_lands_on_its_two_mirror_image_faces(tmp_path):
    # The extruded L's two big faces are its up and down sides: their footprints (the
    # convex hull from above) are mirror images, not congruent, each about 45 % likely.
    import fixtures_cad as fx

    ell_ring = [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)]
    path = fx.write_mesh(fx.prism(ell_ring, 3.0), tmp_path / "ell.stl")
    first, second, *rest = landings_of_mesh(path, name="ell")
    assert (first.name, second.name) == ("pose-0", "pose-1")
    assert first.probability == pytest.approx(second.probability, abs=1e-6)
    assert first.probability > max(x.probability for x in rest)
    assert not congruent(first.part, second.part)
    assert congruent(mirror_part(first.part), second.part)
