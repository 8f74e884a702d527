"""The declared uncertainty through the plan model and its consumers; the physics check samples it.

design.md, "Uncertainty": a plan declares the rotation error, shape and COM tolerances it is
strong for, and its certificate. These tests check the model's round trip and validation, that
``run``, ``report`` and ``simulate`` verify at the declared uncertainty (a version-1 file as the
ideal model), and that the simulator's draws stay within the declared bounds, stop under
``--ideal``, and that a failed trial names its step, cause and whether the model predicted it.
"""

from __future__ import annotations

import copy
import json
import math
import re
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.mechanics.push import edge_normals, push, push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.plans.fileformat import plan_json, plan_to_dict
from feederkit.plans.make import make_plan
from feederkit.plans.model import PlanPart
from feederkit.plans.readplan import plan_from_dict
from feederkit.plans.verify import verify_declared
from feederkit.sensors import ToleranceSensor
from feederkit.sim.sampling import (
    FrictionRange,
    TrialDraw,
    draw_rotation_error,
    draw_trial,
    friction_range,
    perturbed_part,
)
from feederkit.sources import load_part
from feederkit.uncertainty import IDEAL, Uncertainty

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden"
V1 = GOLDEN / "v1" / "equilateral-triangle.tolerance.json"
"""A plan file of version 1 as the first release wrote it (no declared uncertainty)."""


@lru_cache(maxsize=8)
def _strong_text(name: str, shape: float = 0.0) -> str:
    part = load_part(str(ROOT / "catalog" / f"{name}.json"))
    pf = push_function(part)
    made = make_plan(
        [pf], ToleranceSensor(0.01 * part.size), uncertainty=Uncertainty(1.0, shape, shape)
    )
    return plan_json(made.plan)


def strong(name: str = "t-clip", shape: float = 0.0) -> dict:
    """A strong plan file's object (rotation error 1 degree, sensor 1 % of the size)."""
    return json.loads(_strong_text(name, shape))


# ---------------------------------------------------------------- the model and the file


def test_a_strong_plan_round_trips_byte_exactly_with_uncertainty_and_certificate():
    d = strong()
    text = plan_json(d)
    plan = plan_from_dict(d)
    assert plan.uncertainty == Uncertainty(1.0, 0.0, 0.0) and plan.uncertainty_declared
    cert = plan.stats.certificate
    assert cert is not None and cert.max_rotation_error_deg >= 1.0
    assert cert.to_dict() == d["stats"]["certificate"]
    assert plan_json(plan) == text
    keys = list(plan_to_dict(plan))
    assert keys[keys.index("sensor") + 1] == "uncertainty"
    assert list(plan_to_dict(plan)["stats"])[-1] == "certificate"
    assert plan_json(plan_from_dict(json.loads(plan_json(plan)))) == text


def test_a_version_1_file_reads_as_the_ideal_model_and_says_so():
    plan = plan_from_dict(json.loads(V1.read_text(encoding="utf-8")))
    assert plan.uncertainty == IDEAL and not plan.uncertainty_declared
    assert "none declared" in plan.uncertainty_words()
    assert plan.stats.certificate is None
    assert plan_to_dict(plan)["version"] == 2  # written back, it declares the ideal model


def _edited(edit) -> dict:
    d = copy.deepcopy(strong())
    edit(d)
    return d


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda d: d["uncertainty"].update(rotation_error_deg=-1.0), "not in [0, 90)"),
        (lambda d: d["uncertainty"].update(rotation_error_deg=90.0), "not in [0, 90)"),
        (lambda d: d["uncertainty"].update(rotation_error_deg="1"), "finite number"),
        (lambda d: d["uncertainty"].update(shape_tolerance_mm=-0.1), "must not be negative"),
        (lambda d: d["uncertainty"].update(com_tolerance_mm=math.inf), "finite number"),
        (lambda d: d["uncertainty"].update(shape_tolerance_mm=1e3), "half part"),
        (lambda d: d["uncertainty"].update(sigma=1.0), "unknown key"),
        (lambda d: d["uncertainty"].pop("com_tolerance_mm"), "no 'com_tolerance_mm'"),
        (lambda d: d.pop("uncertainty"), "no 'uncertainty'"),
        (lambda d: d.update(uncertainty=[1, 0, 0]), "must be a JSON object"),
        (
            lambda d: d["stats"]["certificate"].update(max_rotation_error_deg=0.5),
            "below the declared rotation error",
        ),
        (
            lambda d: d["stats"]["certificate"].update(max_rotation_error_deg=91.0),
            "not in [0, 90]",
        ),
        (lambda d: d["stats"]["certificate"].update(ideal_length=0), "at least 1"),
        (lambda d: d["stats"]["certificate"].update(ideal_length=1.5), "integer"),
        (lambda d: d["stats"]["certificate"].pop("ideal_length"), "no 'ideal_length'"),
        (lambda d: d["stats"].update(certificate=3), "must be a JSON object"),
    ],
)
def test_the_validator_checks_uncertainty_and_certificate(edit, words):
    with pytest.raises(InputError, match=re.escape(words)) as err:
        plan_from_dict(_edited(edit), "p.json")
    assert "\n" not in str(err.value) and str(err.value).startswith("p.json: ")


def test_a_certificate_below_a_declared_shape_tolerance_is_refused():
    d = strong("rectangle-2x1", 0.01)
    assert d["uncertainty"]["shape_tolerance_mm"] == pytest.approx(0.01)
    d["stats"]["certificate"]["max_shape_tolerance_mm"] = 0.005
    with pytest.raises(InputError, match="below the declared shape tolerance"):
        plan_from_dict(d)


# ---------------------------------------------------------------- one verification, dispatched


def test_verification_dispatches_on_the_declared_uncertainty():
    d = strong()
    assert verify_declared(d).ok
    assert verify_declared(json.loads(V1.read_text(encoding="utf-8"))).ok
    # beyond its certificate the plan must fail the strong check, naming the uncertainty
    d["uncertainty"]["rotation_error_deg"] = 40.0
    d["stats"]["certificate"]["max_rotation_error_deg"] = 40.0
    report = verify_declared(d)
    assert not report.ok and "rotation error ±40°" in (report.first_problem() or "")


def test_run_all_shows_the_uncertainty_and_certificate(tmp_path, capsys):
    path = tmp_path / "p.json"
    path.write_text(plan_json(strong()), encoding="utf-8")
    assert main(["run", str(path), "--all"]) == 0
    out = capsys.readouterr().out
    assert "declared uncertainty: rotation error ±1°" in out
    assert "certificate: holds up to rotation error" in out and "robust / ideal model" in out
    assert "strong plan" in out


def test_run_all_fails_a_plan_beyond_its_certificate(tmp_path, capsys):
    d = strong()
    d["uncertainty"]["rotation_error_deg"] = 40.0
    d["stats"]["certificate"]["max_rotation_error_deg"] = 40.0
    path = tmp_path / "p.json"
    path.write_text(plan_json(d), encoding="utf-8")
    assert main(["run", str(path), "--all"]) == 1
    assert "declared uncertainty" in capsys.readouterr().err


def test_a_version_1_file_still_runs(capsys):
    assert main(["run", str(V1), "--all"]) == 0
    out = capsys.readouterr().out
    assert "none declared (a version-1 plan)" in out and "kinematic model" in out


def test_a_version_1_file_still_reports(tmp_path):
    out = tmp_path / "r.html"
    assert main(["report", str(V1), "-o", str(out)]) == 0
    html = out.read_text(encoding="utf-8")
    assert "none declared (a version-1 plan)" in html and 'id="verification"' not in html


def test_the_report_shows_the_certificate_beside_the_ideal_length(tmp_path):
    path, out = tmp_path / "p.json", tmp_path / "r.html"
    d = strong()
    path.write_text(plan_json(d), encoding="utf-8")
    assert main(["report", str(path), "-o", str(out)]) == 0
    html = out.read_text(encoding="utf-8")
    ideal = d["stats"]["certificate"]["ideal_length"]
    assert "certified rotation error" in html and "certified shape tolerance" in html
    assert f"{d['stats']['length']} / {ideal}" in html


# ---------------------------------------------------------------- the sampler (no MuJoCo)


@settings(max_examples=60, deadline=None)
@given(
    r=st.floats(0.0, 89.0),
    t=st.floats(0.0, 2.0),
    c=st.floats(0.0, 2.0),
    n=st.integers(3, 12),
    belt=st.tuples(st.floats(0.01, 2.0), st.floats(0.0, 1.0)),
    fence=st.tuples(st.floats(0.0, 2.0), st.floats(0.0, 1.0)),
    seed=st.integers(0, 2**32 - 1),
)
def test_draws_stay_within_the_declared_bounds(r, t, c, n, belt, fence, seed):
    fb = FrictionRange(belt[0], belt[0] + belt[1])
    ff = FrictionRange(fence[0], fence[0] + fence[1])
    rng = np.random.default_rng(seed)
    draw = draw_trial(rng, n, Uncertainty(r, t, c), fb, ff)
    assert len(draw.vertex_offsets) == n
    assert all(math.hypot(dx, dy) <= t * (1 + 1e-12) for dx, dy in draw.vertex_offsets)
    assert math.hypot(*draw.com_offset) <= c * (1 + 1e-12)
    assert fb.lo <= draw.friction_belt <= fb.hi and ff.lo <= draw.friction_fence <= ff.hi
    errors = [draw_rotation_error(rng, r) for _ in range(20)]
    assert all(-r <= e <= r for e in errors)


def test_draws_fill_their_bounds():
    rng = np.random.default_rng(5)
    unc = Uncertainty(2.0, 0.5, 0.3)
    draws = [
        draw_trial(rng, 4, unc, FrictionRange(0.4, 0.6), FrictionRange(0.1, 0.3))
        for _ in range(400)
    ]
    radii = [math.hypot(dx, dy) for d in draws for dx, dy in d.vertex_offsets]
    assert max(radii) > 0.45 and min(radii) < 0.05  # the whole disc, not its rim or centre
    errors = [draw_rotation_error(rng, 2.0) for _ in range(400)]
    assert max(errors) > 1.9 and min(errors) < -1.9


def test_zero_bounds_draw_nothing():
    class NoDraws:
        def uniform(self, *args):  # pragma: no cover - must not be called
            raise AssertionError("drew from a zero bound")

    draw = draw_trial(NoDraws(), 5, IDEAL, FrictionRange(0.5, 0.5), FrictionRange(0.2, 0.2))  # type: ignore[arg-type]
    assert not draw.perturbs_shape and draw.friction_belt == 0.5
    assert draw_rotation_error(NoDraws(), 0.0) == 0.0  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("text", "lo", "hi"), [("0.4:0.6", 0.4, 0.6), ("0.5", 0.5, 0.5), (" 0:0.3 ", 0.0, 0.3)]
)
def test_friction_ranges_parse(text, lo, hi):
    fr = friction_range(text, "--friction-belt")
    assert (fr.lo, fr.hi) == pytest.approx((lo, hi))


@pytest.mark.parametrize("text", ["a:b", "0.6:0.4", "-1", "0.1:0.2:0.3", "nan", "7", ""])
def test_bad_friction_ranges_are_one_line_input_errors(text):
    with pytest.raises(InputError, match="--friction-fence") as err:
        friction_range(text, "--friction-fence")
    assert "\n" not in str(err.value)


def test_an_unperturbed_part_maps_its_edges_to_its_stable_states():
    plan = plan_from_dict(strong())
    pp = plan.parts[0]
    pf = push_function(load_part(str(ROOT / "catalog" / "t-clip.json")))
    zero = draw_trial(
        np.random.default_rng(0),
        len(pp.hull),
        IDEAL,
        FrictionRange(0.5, 0.5),
        FrictionRange(0.2, 0.2),
    )
    got = perturbed_part(pp, pf, zero)
    for s in pf.states:
        assert got.basin_of_edge[s.edge] == s.id


def test_a_perturbed_part_stays_within_its_tolerance():
    plan = plan_from_dict(strong())
    pp = plan.parts[0]
    pf = push_function(load_part(str(ROOT / "catalog" / "t-clip.json")))
    rng = np.random.default_rng(3)
    draw = draw_trial(
        rng,
        len(pp.hull),
        Uncertainty(1.0, 0.2, 0.2),
        FrictionRange(0.5, 0.5),
        FrictionRange(0.2, 0.2),
    )
    got = perturbed_part(pp, pf, draw)
    for v in got.part.hull:
        assert min(math.dist(v, w) for w in pp.hull) <= 0.2 + 1e-9
    assert math.dist(got.part.com, pp.com) <= 0.2 + 1e-9
    assert set(b for b in got.basin_of_edge if b is not None) <= {s.id for s in pf.states}


# A review's part: edge 2 is near-metastable (its normal 0.79 deg, its resting range ends at
# 0.976 deg), so a displaced vertex can turn that edge's normal past the range's end.
NEAR_METASTABLE = [
    [-17.604, 18.516], [-28.628, 4.723], [-19.767, -0.687], [-19.285, -3.432],
    [-2.459, -28.549], [16.287, -23.487], [19.661, -14.399], [19.499, -2.659],
]  # fmt: skip


def test_a_displaced_stable_edge_is_its_own_state_past_its_drawn_range():
    """A rest on a drawn stable edge is that state's pose however far its normal moved; the
    drawn range's basin named the neighbour (a physics check scored parts resting on edge 2,
    reading its width and given its result, as wrong accepts)."""
    pf = push_function(make_part(make_outline("rp1", NEAR_METASTABLE, com=(-3.862, -3.057))))
    pp = PlanPart("rp1", None, pf.part.com, pf.part.hull, pf.states)
    near = next(s for s in pf.states if s.edge == 2)
    hi = near.resting_range_deg[1]
    offsets = [(0.0, 0.0)] * len(pp.hull)
    turn = math.radians(edge_normals(pp.hull)[2])
    offsets[3] = (-0.05 * math.cos(turn), -0.05 * math.sin(turn))  # within t = 0.05 mm
    got = perturbed_part(pp, pf, TrialDraw(tuple(offsets), (0.0, 0.0), 0.5, 0.2))
    normal = edge_normals(got.part.hull)[2]
    assert normal > hi + 0.01  # past the drawn range: its basin is the neighbour's
    assert push(pf, normal).edge != 2
    assert got.basin_of_edge[2] == near.id
    # Every other edge keeps its own state too.
    for s in pf.states:
        assert got.basin_of_edge[s.edge] == s.id


# ---------------------------------------------------------------- the simulator (MuJoCo)

mujoco = pytest.importorskip(
    "mujoco", reason="MuJoCo is not installed here: pip install 'feederkit[sim]' to run these"
)

from feederkit.sim import api as sim_api  # noqa: E402
from feederkit.sim import simulate_plan  # noqa: E402


def test_ideal_makes_no_draws(monkeypatch):
    def refuse(seed, trial):
        raise AssertionError("--ideal drew from nature")

    monkeypatch.setattr(sim_api, "nature_rng", refuse)
    s = simulate_plan(strong(), 4, seed=1, ideal=True)
    assert s.settings.ideal and s.settings.sampled == IDEAL and s.settings.rotation_noise_deg == 0.0
    trials = [*s.failures, *s.unsettled]
    assert s.successes + len(trials) == 4
    assert s.to_dict()["settings"]["ideal"] is True


def test_sampling_draws_once_per_trial_within_the_declared_error(monkeypatch):
    calls = []
    real = sim_api.nature_rng

    def counting(seed, trial):
        calls.append(trial)
        return real(seed, trial)

    monkeypatch.setattr(sim_api, "nature_rng", counting)
    s = simulate_plan(strong(), 4, seed=1, friction_belt="0.45:0.55")
    assert calls == [0, 1, 2, 3]
    assert s.settings.sampled == Uncertainty(1.0, 0.0, 0.0)
    assert s.settings.friction_belt_range == FrictionRange(0.45, 0.55)
    d = s.to_dict()
    assert d["settings"]["friction_belt_range"] == [0.45, 0.55]


def test_a_failed_trial_names_step_cause_and_prediction():
    d = strong("rectangle-2x1")
    # a plan whose results are wrong: the model predicts every outcome, the plan is at fault
    stack = [d["root"]]
    while stack:
        node = stack.pop()
        if "result" in node:
            for e in node["result"]:
                e["state"] = (e["state"] + 1) % len(d["parts"][0]["stable_states"])
        else:
            stack.extend(b["next"] for b in node["branches"])
    s = simulate_plan(d, 3, seed=0, check=False, ideal=True)
    assert s.successes == 0 and len(s.failures) == 3
    for r in s.failures:
        assert r.cause == "wrong result" and r.predicted is True
        assert r.step == len(r.pushes) and r.final_state is not None
        assert r.to_dict()["cause"] == "wrong result" and r.to_dict()["predicted"] is True


def test_an_outcome_the_model_did_not_predict_is_a_model_error_listed_first():
    # rotation errors far beyond the declared one send the part where the model says it cannot go
    s = simulate_plan(strong("rectangle-2x1"), 6, seed=2, rotation_noise_deg=80.0)
    wrong = s.went_wrong
    assert wrong, "80 degree errors on a plan strong for 1 degree must go wrong"
    assert any(r.predicted is False for r in wrong)
    flags = [bool(r.predicted) for r in wrong]
    assert flags == sorted(flags)  # model errors first
    first = wrong[0]
    assert first.predicted is False and first.step is not None and first.cause
    assert "model" in (first.reason or "")
    assert s.model_errors == sum(not f for f in flags)


def test_simulate_cli_reads_friction_ranges_and_ideal(tmp_path, capsys):
    path = tmp_path / "p.json"
    path.write_text(plan_json(strong()), encoding="utf-8")
    assert main(["simulate", str(path), "--trials", "2", "--friction-fence", "0.15:0.25"]) == 0
    out = capsys.readouterr().out
    assert "declared uncertainty: rotation error ±1°" in out and "fence 0.15:0.25" in out
    assert main(["simulate", str(path), "--trials", "2", "--ideal", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["settings"]["ideal"] is True and d["uncertainty"]["rotation_error_deg"] == 1.0
    (entry,) = d["per_part"]
    assert entry["name"] == entry["part"] and entry["landing"] is None
    assert main(["simulate", str(path), "--friction-belt", "0:0.5"]) == 2
    err = capsys.readouterr().err
    assert "frictionless belt" in err and "Traceback" not in err


def test_a_version_1_file_still_simulates():
    s = simulate_plan(json.loads(V1.read_text(encoding="utf-8")), 3, seed=0)
    assert s.settings.sampled == IDEAL and s.settings.rotation_noise_deg == 0.0
    assert s.successes + len(s.failures) + len(s.unsettled) == 3


def test_a_shape_tolerance_perturbs_every_trial(monkeypatch):
    made = []
    real = sim_api.perturbed_part

    def spy(pp, pf, draw):
        assert draw.perturbs_shape
        assert all(math.hypot(dx, dy) <= 0.01 + 1e-12 for dx, dy in draw.vertex_offsets)
        made.append(real(pp, pf, draw))
        return made[-1]

    monkeypatch.setattr(sim_api, "perturbed_part", spy)
    s = simulate_plan(strong("rectangle-2x1", 0.01), 3, seed=4)
    assert len(made) == 3 and len({p.part.hull for p in made}) == 3
    assert s.settings.sampled.shape_tolerance_mm == pytest.approx(0.01)
    assert s.successes + len(s.failures) + len(s.unsettled) == 3


@pytest.mark.slow
def test_strong_catalog_plans_succeed_in_the_physics_check():
    for name in ("rectangle-2x1", "t-clip", "quadrilateral"):
        s = simulate_plan(strong(name), 100, seed=7)
        assert s.success_rate >= 0.97, (name, s.by_cause())


@pytest.mark.slow
def test_a_plan_over_landings_draws_members_by_share_and_counts_rejects():
    """The l-bracket dropped up (70 %) or down, the next station taking only ``up``: every
    ``down`` trial ends in the reject leaf naming it, none in an accepting leaf (design.md,
    "Landings")."""
    from feederkit.landing.model import landings_of_outline
    from feederkit.landing.plan import plan_landings
    from feederkit.sim import simulate_plan

    part = load_part(str(ROOT / "catalog" / "l-bracket.json"))
    landings = landings_of_outline(part, 0.7)
    made = plan_landings(
        landings, ToleranceSensor(0.01 * part.size), uncertainty=Uncertainty(1.0), accept={"up"}
    ).made
    s = simulate_plan(made.plan, 40, seed=0)
    assert s.parts == ("l-bracket (up)", "l-bracket (down)")
    up, down = s.part_trials
    assert up + down == 40 and 18 <= up <= 36  # 28 expected at a 70 % share
    assert s.successes == 40 and s.wrong_accepts == 0
    assert s.rejects == down
    d = s.to_dict()
    assert (d["rejects"], d["wrong_accepts"]) == (down, 0)
    # Each member by its name and landing too, not only by its label.
    assert [(e["name"], e["landing"]) for e in d["per_part"]] == [
        ("l-bracket", "up"),
        ("l-bracket", "down"),
    ]
