"""The chords of an arc where its radius function has a maximum are no resting state.

A D60 disk with an off-centre window has its COM 1.14 mm off the centre: its radius function
30 + 1.14 cos(theta) has one minimum and one maximum, and one push orients it. Flattened, the
arc makes stable chords within about 35 degrees of either; a breath of vibration merges each
group, and the group at the maximum is a hill the part rolls off (docs/uncertainty.md,
"Physical resting states"), however the circle is drawn.
"""

from __future__ import annotations

import json
import math

import fixtures_cad as fx
import pytest

from feederkit.cli.app import main
from feederkit.importers.model import ImportOptions
from feederkit.importers.reader import import_parts
from feederkit.mechanics.modelerror import _resting
from feederkit.mechanics.push import push_function
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.uncertainty import Uncertainty

WINDOW = [(5.0, -5.0), (25.0, -5.0), (25.0, 5.0), (5.0, 5.0)]


def _circle_disk(msp) -> None:
    msp.add_circle((0.0, 0.0), 30.0)
    msp.add_lwpolyline(WINDOW, close=True)


def _spline_disk(msp) -> None:
    """The same disk, its circle a rational quadratic SPLINE (as SolidWorks-type exporters
    write circles): nine control points, weights 1 and sqrt(2) / 2."""
    r, w = 30.0, math.sqrt(2.0) / 2.0
    ctrl = [(r, 0), (r, r), (0, r), (-r, r), (-r, 0), (-r, -r), (0, -r), (r, -r), (r, 0)]
    knots = [0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4]
    msp.add_rational_spline(ctrl, [1, w, 1, w, 1, w, 1, w, 1], degree=2, knots=knots)
    msp.add_lwpolyline(WINDOW, close=True)


def _sensorless_plan(tmp_path, capsys, path) -> dict:
    out = tmp_path / "plan.json"
    rc = main(["plan", str(path), "--sensorless", "-o", str(out)])
    err = capsys.readouterr().err
    assert rc == 0, err
    return json.loads(out.read_text())


@pytest.mark.parametrize("draw", [_circle_disk, _spline_disk], ids=["circle", "spline"])
def test_an_off_centre_disk_rests_in_one_state_and_one_push_orients_it(tmp_path, capsys, draw):
    path = fx.write_entities(tmp_path / "disk.dxf", draw)
    (ip,) = import_parts(path, ImportOptions())[1]
    assert ip.part.com[0] == pytest.approx(-1.142, abs=1e-3)
    (note,) = [w for w in ip.warnings if w.startswith("hull tolerance")]
    assert note.endswith("outline 1)")  # was "outline 2": the hilltop's chords counted
    mech = uncertain_mechanics(ip.part, Uncertainty())
    (state,) = mech.states
    lo, hi = state.rest_deg
    assert lo < 180.0 < hi and hi - lo < 90.0  # the chords around the minimum, one state
    pf = push_function(ip.part)
    top = [s.id for s in pf.states if math.cos(math.radians(s.normal_deg)) > 0.5]
    assert len(top) > 10  # the hilltop's chords: stable edges of the drawn hull
    assert all(mech.state_of[i] is None for i in top)
    assert all(mech.destinations[i] == {0} for i in top)  # the part rolls to the minimum
    assert _resting(ip.part).n == 1
    assert _sensorless_plan(tmp_path, capsys, path)["stats"]["length"] == 1


def test_with_a_sensor_the_spline_disk_gets_its_one_push_plan(tmp_path, capsys):
    """It was refused: "no strong plan exists" between the hilltop's group and the minimum's."""
    path = fx.write_entities(tmp_path / "disk.dxf", _spline_disk)
    out = tmp_path / "plan.json"
    rc = main(["plan", str(path), "--tolerance", "0.2", "-o", str(out)])
    assert rc == 0, capsys.readouterr().err
    assert json.loads(out.read_text())["stats"]["length"] == 1


def test_a_shape_tolerance_that_may_deepen_the_chords_keeps_them(tmp_path):
    """The hilltop's chords go only when every shape in the tolerance zone leaves them: their
    barriers (up to 0.009 mm) plus twice the shape tolerance below the vibration (0.06 mm)."""
    path = fx.write_entities(tmp_path / "disk.dxf", _circle_disk)
    (ip,) = import_parts(path, ImportOptions())[1]
    top = [s.id for s in push_function(ip.part).states if s.normal_deg < 10.0]
    assert top
    gone = uncertain_mechanics(ip.part, Uncertainty(1.0, 0.02, 0.0))
    kept = uncertain_mechanics(ip.part, Uncertainty(1.0, 0.03, 0.0))
    assert all(gone.state_of[i] is None for i in top)
    assert all(kept.state_of[i] is not None for i in top) and kept.n == 2


def test_the_import_lowers_a_tolerance_whose_chord_rests_where_the_outline_rolls(tmp_path):
    """With its COM 18 mm off the centre the disk rests on one chord across the top of its
    radius function at 0.05 mm, where the outline's finer chords are a hill: the import takes
    0.025 mm, at which the top's chords are a hill too."""
    path = fx.write_entities(tmp_path / "disk.dxf", lambda msp: msp.add_circle((0, 0), 30.0))
    (ip,) = import_parts(path, ImportOptions(com=(-18.0, 0.0)))[1]
    assert ip.hull_tolerance == pytest.approx(0.025)
    (note,) = [w for w in ip.warnings if w.startswith("hull tolerance")]
    assert note.endswith("simplified 2, outline 1)")
    (state,) = _resting(ip.part).states
    assert state.rest_deg[0] < 180.0 < state.rest_deg[1]


def test_a_centred_disk_is_still_disk_like(tmp_path, capsys):
    path = fx.write_entities(tmp_path / "disk.dxf", lambda msp: msp.add_circle((0, 0), 30.0))
    (ip,) = import_parts(path, ImportOptions())[1]
    assert not ip.orientability.orientable and "disk-like" in ip.orientability.reason
    (state,) = _resting(ip.part).states  # every chord merged: one state all round
    assert state.rest_deg[1] - state.rest_deg[0] == pytest.approx(360.0)
    assert main(["plan", str(path), "--sensorless"]) == 2
    assert "the part is disk-like" in capsys.readouterr().err


# A near-regular 12-gon (drawn radii 19.4-20.6 mm) with two real shallow states between hilltop
# 1 and the deep state 6: edges of 4.9 and 1.0 mm whose barriers (0.0056 and 0.0017 mm) are
# below the vibration (0.039 mm). They merge into one state, which steps down a slope: no hill.
TWELVE_GON = [
    (-16.102, 11.780),
    (-19.494, -4.482),
    (-17.927, -9.170),
    (-17.538, -10.133),
    (-16.401, -11.301),
    (-15.986, -11.605),
    (4.509, -19.680),
    (9.466, -17.198),
    (17.919, -7.906),
    (19.208, -7.352),
    (19.387, -5.517),
    (19.403, -2.472),
]


def test_a_12_gon_keeps_its_real_shallow_states():
    part = make_part(make_outline("twelve", TWELVE_GON), (1.2124, -2.2735))
    pf = push_function(part)
    shallow = [s for s in pf.states if s.barrier_mm < 0.01]
    mech = uncertain_mechanics(part, Uncertainty())
    assert len(shallow) == 2 and all(s.barrier_mm < mech.vibration_mm / 5 for s in shallow)
    assert all(x is not None for x in mech.state_of)
    assert sorted(len(s.members) for s in mech.states) == [1, 1, 1, 1, 1, 2]
    assert mech.state_of[shallow[0].id] == mech.state_of[shallow[1].id]
