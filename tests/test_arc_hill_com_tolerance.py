"""A cam's round ends stay hills, and its flanks stay apart, under a COM tolerance.

A cam (an R15 and an R6 end joined by tangent flanks) drawn with its arcs as chords: at a
COM tolerance of 0.02-0.1 mm the model let it rest on the top of its R15 end (the chords
there counted ``2 (t + c)`` of barrier growth, while a COM moved by ``c`` changes a barrier
between a normal and a hilltop ``s`` radians away by at most ``c s``), and let a push from
one flank's capture end on the other flank (one descent level for a whole gap between bands,
its highest start beside the R6 end's band). ``plan --com-tolerance 0.02`` said "no strong
plan exists", while the ideal plan passed 100 of 100 physics trials with the COM so moved;
the plan now found passes 100 of 100 in ``feederkit simulate`` (docs/uncertainty.md).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from feederkit.cli.app import main
from feederkit.mechanics.push import push_function
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.uncertainty import Uncertainty


def _cam_points() -> tuple[list, list]:
    r1, r2, d = 15.0, 6.0, 25.0
    phi = math.acos((r1 - r2) / d)
    ring = [(r1 * math.cos(a), r1 * math.sin(a)) for a in np.linspace(phi, 2 * math.pi - phi, 60)]
    ring += [(d + r2 * math.cos(a), r2 * math.sin(a)) for a in np.linspace(-phi, phi, 30)]
    hole = [
        (-6 + 2 * math.cos(a), 5 + 2 * math.sin(a))
        for a in np.linspace(0, 2 * math.pi, 24, endpoint=False)
    ]
    return ring, hole[::-1]


def _cam():
    ring, hole = _cam_points()
    return make_part(make_outline("cam", ring, [hole]))


def test_the_top_of_a_round_end_is_no_resting_state_under_a_com_tolerance() -> None:
    part = _cam()
    pf = push_function(part)
    top = [i for i, s in enumerate(pf.states) if 170.0 < s.normal_deg < 190.0]
    assert len(top) == 3  # the R15 end's top chords, stable on the drawing
    for c in (0.0, 0.02, 0.1):
        mech = uncertain_mechanics(part, Uncertainty(1.0, 0.0, c))
        assert all(mech.state_of[i] is None for i in top), c


def test_a_flank_keeps_its_own_capture_under_a_com_tolerance() -> None:
    part = _cam()
    pf = push_function(part)
    flank = next(i for i, s in enumerate(pf.states) if abs(s.normal_deg - 291.1) < 0.5)
    mech = uncertain_mechanics(part, Uncertainty(1.0, 0.0, 0.02))
    own = mech.state_of[flank]
    # Fence orientations well inside the flank's capture, away from both round ends' bands.
    for theta in (220.0, 260.0, 300.0, 340.0):
        cell = next(c for c in mech.cells if c.lo <= theta < c.hi or c.lo <= theta + 360 < c.hi)
        assert cell.targets == frozenset({own}), theta


def test_the_cam_has_its_ideal_plan_under_a_com_tolerance(tmp_path: Path, capsys) -> None:
    ring, hole = _cam_points()
    src = tmp_path / "cam.json"
    src.write_text(json.dumps({"name": "cam", "vertices": ring, "holes": [hole]}))
    out = tmp_path / "cam.plan.json"
    args = ["plan", str(src), "--sensorless", "--landings", "up", "--com-tolerance", "0.1"]
    assert main([*args, "-o", str(out)]) == 0, capsys.readouterr().err
    assert json.loads(out.read_text())["stats"]["length"] == 2
