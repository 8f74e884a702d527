"""The simulated feeder breathes on a resting part with the vibration the plan's model assumes.

A riser (a half disk of 30 facets of 6 degrees under a block) has its COM 3 mm above the
arc's centre: the arc's lowest point is a maximum of its radius function, and the two facets
there are stable edges a breath of vibration rolls the part off (their barriers 0.0052 mm
against 0.024 mm). The model has no state there (docs/uncertainty.md); MuJoCo, without
vibration, leaves the part on them (docs/simulation.md, "A breath of vibration").
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from feederkit.mechanics.analysis import FRAGILE_BARRIER_REL
from feederkit.mechanics.push import push_function
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.outline import make_outline
from feederkit.part import Part, make_part
from feederkit.plans.make import make_plan
from feederkit.sensors import ToleranceSensor
from feederkit.sim import api
from feederkit.sim.pushalign import BREATH_STEP_DEG, PushAligner, breath_turn, fence_heights
from feederkit.sim.scene import SceneConfig
from feederkit.uncertainty import Uncertainty

SAMPLES = Path(__file__).resolve().parents[1].parent / "shared" / "samples"


def _riser() -> Part:
    arc = [
        (10.0 * math.cos(math.radians(180 + 6 * k)), 10.0 * math.sin(math.radians(180 + 6 * k)))
        for k in range(31)
    ]
    return make_part(make_outline("riser", [*arc, (10.0, 14.0), (-10.0, 14.0)]), hull_tolerance=0.0)


RISER = _riser()
HUMP_BARRIER = 0.00523  # mm, the hump facets' lower barrier


def _rests(vibration_mm: float, theta_deg: float) -> float:
    """The normal (deg) of the edge the riser rests on, dropped at ``theta_deg``."""
    aligner = PushAligner(RISER, SceneConfig(), vibration_mm=vibration_mm)
    out = aligner.align(theta_deg)
    assert out.settled
    (state,) = [s for s in push_function(RISER).states if s.edge == out.edge]
    return state.normal_deg


def test_the_risers_hump_facets_are_stable_edges_the_model_drops():
    pf = push_function(RISER)
    hump = [s for s in pf.states if abs(s.normal_deg - 270.0) < 4.0]
    assert [round(s.normal_deg) for s in hump] == [273, 267]
    assert all(s.barrier_mm == pytest.approx(HUMP_BARRIER, abs=1e-5) for s in hump)
    mech = uncertain_mechanics(RISER, Uncertainty(1.0, 0.0, 0.0))
    assert mech.vibration_mm == pytest.approx(FRAGILE_BARRIER_REL * RISER.size)
    assert [mech.state_of[s.id] for s in hump] == [None, None]


@pytest.mark.parametrize("theta", [272.0, 268.0])
def test_without_vibration_mujoco_leaves_the_part_on_a_hump_facet(theta):
    assert abs(_rests(0.0, theta) - 270.0) == pytest.approx(3.0, abs=1e-6)


@pytest.mark.parametrize(("theta", "side"), [(272.0, 0.0), (268.0, 180.0)])
def test_a_breath_above_the_facets_barrier_rolls_the_part_off_the_hump(theta, side):
    assert _rests(FRAGILE_BARRIER_REL * RISER.size, theta) == pytest.approx(side, abs=1e-6)
    assert _rests(1.3 * HUMP_BARRIER, theta) == pytest.approx(side, abs=1e-6)


@pytest.mark.parametrize("theta", [272.0, 268.0])
def test_a_breath_below_the_facets_barrier_leaves_the_part_on_it(theta):
    assert abs(_rests(0.7 * HUMP_BARRIER, theta) - 270.0) == pytest.approx(3.0, abs=1e-6)


@pytest.mark.parametrize(("theta", "side"), [(100.0, 90.0), (20.0, 0.0), (200.0, 180.0)])
def test_a_breath_leaves_a_deep_state_alone(theta, side):
    aligner = PushAligner(RISER, SceneConfig(), vibration_mm=FRAGILE_BARRIER_REL * RISER.size)
    out = aligner.align(theta)
    assert out.settled
    assert abs((out.theta_end_deg - side + 180.0) % 360.0 - 180.0) < 1.0


def _standing(w: float, h: float) -> np.ndarray:
    """A w x h rectangle about its COM, standing on its side of length w on the fence."""
    return np.array([(-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2)])


def test_a_breath_rolls_a_part_over_a_barrier_below_its_lift_only():
    # On its short side the COM stands 10 over the fence; over a corner 11.18; on a long
    # side 5: the barrier is 1.18, and the breath takes it to the long side, a quarter turn.
    barrier = math.hypot(10.0, 5.0) - 10.0
    assert breath_turn(_standing(10.0, 20.0), 0.9 * barrier) is None
    turn = breath_turn(_standing(10.0, 20.0), 1.1 * barrier)
    assert turn is not None
    assert abs(math.degrees(turn)) == pytest.approx(90.0, abs=BREATH_STEP_DEG)
    # On a long side no lift takes it lower.
    assert breath_turn(_standing(20.0, 10.0), 10.0) is None
    assert fence_heights(_standing(10.0, 20.0), np.radians([0.0, 90.0])) == pytest.approx(
        [10.0, 5.0]
    )


def test_a_part_held_a_little_off_its_wells_bottom_is_judged_from_the_bottom():
    rel = _standing(10.0, 20.0)
    c, s = math.cos(math.radians(2.0)), math.sin(math.radians(2.0))
    tilted = rel @ np.array([[c, s], [-s, c]])  # turned 2 degrees, up its well's wall
    barrier = math.hypot(10.0, 5.0) - 10.0
    assert breath_turn(tilted, 0.9 * barrier) is None


def test_simulate_breathes_with_the_vibration_of_the_plans_model(monkeypatch):
    made = make_plan([push_function(RISER)], ToleranceSensor(0.24), uncertainty=Uncertainty(1.0))
    seen: list[float] = []

    class Spy(PushAligner):
        def __init__(self, *args, vibration_mm: float = 0.0, **kwargs) -> None:
            seen.append(vibration_mm)
            super().__init__(*args, vibration_mm=vibration_mm, **kwargs)

    monkeypatch.setattr(api, "PushAligner", Spy)
    summary = api.simulate_plan(made.plan, 12, seed=0)
    assert summary.successes == 12
    assert seen and all(v == pytest.approx(FRAGILE_BARRIER_REL * RISER.size) for v in seen)


@pytest.mark.slow
@pytest.mark.skipif(not SAMPLES.is_dir(), reason=f"{SAMPLES} is absent")
@pytest.mark.parametrize("own", [False, True], ids=["hull", "own-outline"])
def test_the_idler_risers_plan_succeeds_in_every_trial(own):
    from feederkit.loading import load_parts
    from feederkit.plans.readplan import as_plan
    from feederkit.sim.real import real_parts

    source = str(SAMPLES / "trimesh__idler_riser.STL")
    (pf,) = load_parts([source], leave_out_not_orientable=True).push_functions
    sensor = ToleranceSensor(float(f"{pf.part.size / 100.0:.3g}"))
    plan = make_plan([pf], sensor, uncertainty=Uncertainty(1.0)).plan
    real = real_parts(as_plan(plan), [source]) if own else ()
    summary = api.simulate_plan(plan, 200, seed=0, real=real)
    assert summary.successes == 200  # 192 on its hull, 194 on its own outline, unbreathed


def _turned(rel: np.ndarray, theta_deg: float) -> np.ndarray:
    """``rel`` (part frame) with the fence at part-frame orientation ``theta_deg`` below it."""
    a = math.radians(-90.0 - theta_deg)
    return rel @ np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])


def test_a_breath_leaves_no_orientation_on_the_hill_of_an_off_centre_disk():
    # A 128-gon of radius 30 with its COM 1.14 off the centre: its chords within 35 degrees of
    # the maximum at 180 are stable edges with barriers up to 0.009 mm, the vibration 0.06.
    # A part held just past the last hilltop, where the fence height falls all the way, goes
    # down too (MuJoCo held the disk 0.06 degree past one).
    ring = [
        (30 * math.cos(2 * math.pi * k / 128), 30 * math.sin(2 * math.pi * k / 128))
        for k in range(128)
    ]
    rel = np.asarray(ring) - np.array([1.14, 0.0])
    held = [t for t in np.arange(140.0, 220.0, 0.05) if breath_turn(_turned(rel, t), 0.06) is None]
    assert held == []
    assert breath_turn(_turned(rel, 0.0), 0.06) is None  # its lowest point
