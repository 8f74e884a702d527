"""``simulate --part``: a SOURCE refused for another scale or another part frame is told so.

The match check compares the SOURCE's hull with the plan's in the part frame. A file in inches
read as millimetres (a mesh carries no units), or the part exported turned or mirrored, lies
tens of millimetres from the plan's hull there, and the refusal used to offer
``--hull-tolerance``, which cannot help. Now the refusal names the units (``catalog add FILE
--units in``, then ``--part NAME=CATALOGNAME``: ``simulate`` has no ``--units``) or the frame
(``feederkit.sim.likeness``).
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path

import pytest
from shared import one_line_error

from feederkit.errors import InputError
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline, save_outline_json
from feederkit.part import Part, make_part
from feederkit.plans.fileformat import plan_json
from feederkit.plans.make import make_plan
from feederkit.plans.readplan import as_plan
from feederkit.sensors import NoSensor
from feederkit.sim.likeness import likely_units, likeness, scale_of
from feederkit.sim.real import check_match
from feederkit.sources import load_part

CATALOG = Path(__file__).resolve().parents[1] / "catalog"

needs_mujoco = pytest.mark.skipif(
    not __import__("feederkit.sim", fromlist=["mujoco_available"]).mujoco_available(),
    reason="MuJoCo is not installed here: pip install 'feederkit[sim]' to run these",
)


def _bracket() -> Part:
    return load_part(str(CATALOG / "l-bracket.json"))


@lru_cache(maxsize=1)
def _plan_text() -> str:
    return plan_json(make_plan([push_function(_bracket())], NoSensor()).plan)


def _moved(f) -> Part:
    """The l-bracket with every outline point mapped by ``f`` (the COM follows)."""
    o = _bracket().outline
    vertices = [f(x, y) for x, y in o.vertices]
    holes = [[f(x, y) for x, y in h] for h in o.holes]
    return make_part(make_outline("moved", vertices, holes=holes))


def _refusal(part: Part, source: str = "moved.json") -> str:
    with pytest.raises(InputError) as exc:
        check_match(as_plan(json.loads(_plan_text())), 0, part, source)
    line = str(exc.value)
    assert "\n" not in line and "not the part the plan was made for" in line
    return line


def test_unit_factors_are_read_from_the_size_ratio() -> None:
    assert likely_units(25.4) == ("in", "mm") and likely_units(25.0) == ("in", "mm")
    assert likely_units(1 / 25.4) == ("mm", "in")
    assert likely_units(1000.0) == ("m", "mm") and likely_units(10.0) == ("cm", "mm")
    assert likely_units(1.0) is None and likely_units(2.0) is None


def test_a_part_in_inches_is_told_its_units_not_the_hull_tolerance() -> None:
    line = _refusal(_moved(lambda x, y: (x / 25.4, y / 25.4)), "lb_inch.json")
    assert "its hull is 25.4 times smaller than the plan's" in line
    assert "the file's units differ from the plan's part (likely in inches, read as" in line
    assert "`feederkit catalog add its file --units in --name NAME`" in line
    assert "give --part l-bracket=NAME" in line
    assert "--hull-tolerance" not in line
    metres = _refusal(_moved(lambda x, y: (x / 1000, y / 1000)))
    assert "1000 times smaller" in metres and "--units m " in metres
    double = _refusal(_moved(lambda x, y: (2 * x, 2 * y)))
    assert "2 times larger than the plan's" in double and "a scale no unit explains" in double


def test_a_part_in_another_frame_is_told_its_frame() -> None:
    c, s = math.cos(math.radians(90)), math.sin(math.radians(90))
    turned = _refusal(_moved(lambda x, y: (c * x - s * y, s * x + c * y)))
    assert "turned by -90 deg about its COM" in turned and "mirrored" not in turned
    assert "the part's frame differs from the plan's" in turned
    assert "--hull-tolerance" not in turned
    mirrored = _refusal(_moved(lambda x, y: (-x, y)))
    assert "; mirrored about its COM, then moved by (" in mirrored
    assert "its hull is the plan's (then 0 mm apart)" in mirrored
    shifted = _refusal(_moved(lambda x, y: (x + 5.0, y - 2.0)))
    assert "; moved by (-5, 2) mm, its hull is the plan's" in shifted


def test_another_part_keeps_the_old_refusal() -> None:
    """A part no scale, turn or mirror brings onto the plan's: nothing of units or frames."""
    plate = make_part(make_outline("plate", [(0, 0), (60, 0), (60, 40), (0, 40)]))
    line = _refusal(plate)
    assert "units" not in line and "frame differs" not in line
    assert "give --hull-tolerance MM with the value it was imported with" in line
    # A part of another shape a unit's factor smaller is not told its units either.
    bolt = make_part(make_outline("bolt", [(0, 0), (6, 0), (0, 3.5)]))
    small = _refusal(bolt)
    assert "units" not in small and "frame differs" not in small


def test_the_likeness_is_exact_for_the_same_hull() -> None:
    part = _bracket()
    found = likeness(part.hull, part.com, part.hull, part.com, 1.0)
    assert found.distance_mm < 1e-9 and not found.mirrored and found.turn_deg == 0.0
    assert found.motion_words(part.size) == ""
    assert scale_of(part.hull, [(x / 25.4, y / 25.4) for x, y in part.hull]) == pytest.approx(25.4)


@needs_mujoco
def test_simulate_refuses_a_file_in_inches_naming_its_units(tmp_path: Path, capsys) -> None:
    plan = tmp_path / "lb.plan.json"
    plan.write_text(_plan_text(), encoding="utf-8")
    inch = tmp_path / "lb_inch.json"
    save_outline_json(_moved(lambda x, y: (x / 25.4, y / 25.4)).outline, inch)
    err = one_line_error(capsys, ["simulate", str(plan), "--trials", "1", "--part", str(inch)])
    assert f"`feederkit catalog add {inch} --units in --name NAME`" in err
    assert "--hull-tolerance" not in err
