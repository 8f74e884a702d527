"""A strong plan's claims beyond its paths: each margin and the certificate (design.md, plan
file; docs/plans.md). The verifier refuses a file that overstates them, and the margins the
planner writes hold on the reference model of tests/test_strong_plans.py, which pushes the
polygon itself."""

from __future__ import annotations

import copy
import json
import random
from pathlib import Path

import pytest
from test_strong_plans import _usable, perturbed, random_pf, run_plan

from feederkit.cli.app import main
from feederkit.errors import CheckFailed, PlanningError
from feederkit.plans.fileformat import result_nodes
from feederkit.plans.make import make_plan
from feederkit.plans.strong import action_nodes, certificate_problems, verify_strong
from feederkit.plans.verify import verify_declared
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import Uncertainty

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


@pytest.fixture(scope="module")
def bracket(tmp_path_factory) -> dict:
    """The l-bracket over both landings with an LED array (three rotations, two of them
    shared subplans), as `plan` writes it."""
    path = tmp_path_factory.mktemp("claims") / "lb.plan.json"
    args = ["plan", str(CATALOG / "l-bracket.json"), "--led-pitch", "0.5", "--noise", "0.1"]
    assert main([*args, "-o", str(path)]) == 0
    return json.loads(path.read_text())


def tampered(plan: dict, edit) -> dict:
    out = copy.deepcopy(plan)
    edit(out)
    return out


def actions(plan: dict) -> list[dict]:
    """The plan's distinct rotation nodes (shared subplans once), in the tree's order."""
    return action_nodes(plan)


def test_the_written_claims_hold(bracket):
    assert len(actions(bracket)) >= 2
    assert verify_declared(bracket).ok
    verify_strong(bracket)  # the paths and the margins
    assert certificate_problems(bracket) == []


def test_an_inflated_margin_is_refused(bracket):
    smallest = bracket["stats"]["min_margin_deg"]
    wide = [k for k, a in enumerate(actions(bracket)) if a["margin_deg"] > smallest]
    assert wide  # the smallest margin is also the stats' (the loader checks that)
    for node in wide:
        bad = tampered(bracket, lambda p, k=node: actions(p)[k].__setitem__("margin_deg", 179.0))
        report = verify_declared(bad)
        assert not report.ok and "more than it keeps" in report.first_problem()


def test_a_shifted_rotation_keeps_no_false_margin(bracket):
    """Moved 15 degrees, the rotation still orients (the paths pass) but keeps less slack."""

    def shift(p):
        a = actions(p)[0]
        a["action_deg"] = (a["action_deg"] + 15.0) % 360.0

    bad = tampered(bracket, shift)
    with pytest.raises(CheckFailed, match="beyond the declared ±1°"):
        verify_strong(bad)
    assert not verify_declared(bad).ok


def test_an_overstated_certificate_is_refused(bracket):
    cert = bracket["stats"]["certificate"]
    rot = tampered(
        bracket, lambda p: p["stats"]["certificate"].__setitem__("max_rotation_error_deg", 89.0)
    )
    assert "rotation error ±89°" in verify_declared(rot).first_problem()
    just = tampered(
        bracket,
        lambda p: p["stats"]["certificate"].__setitem__(
            "max_rotation_error_deg", cert["max_rotation_error_deg"] + 1e-3
        ),
    )
    assert certificate_problems(just)
    shape = tampered(
        bracket, lambda p: p["stats"]["certificate"].__setitem__("max_shape_tolerance_mm", 3.0)
    )
    assert "shape tolerance 3 mm" in verify_declared(shape).first_problem()


def test_run_all_exits_1_on_an_inflated_margin(bracket, tmp_path, capsys):
    path = tmp_path / "bad.plan.json"
    smallest = bracket["stats"]["min_margin_deg"]
    k = next(k for k, a in enumerate(actions(bracket)) if a["margin_deg"] > smallest)
    bad = tampered(bracket, lambda p: actions(p)[k].__setitem__("margin_deg", 179.0))
    path.write_text(json.dumps(bad))
    assert main(["run", str(path), "--all"]) == 1
    assert "more than it keeps" in capsys.readouterr().err


@pytest.mark.parametrize("chunk", range(2))
def test_written_margins_hold_on_the_reference(chunk):
    """Random parts' strong plans run on the reference with every rotation off by up to the
    declared error plus 0.99 of the plan's smallest margin: every run ends in its result."""
    planned, seed = 0, 20_000 * (chunk + 1)
    unc = Uncertainty(1.0)
    while planned < 12:
        seed += 1
        pf = random_pf(seed)
        if not _usable(pf, unc):
            continue
        sensor = ToleranceSensor(0.05) if seed % 2 else NoSensor()
        try:
            made = make_plan([pf], sensor, uncertainty=unc, certify=False)
        except PlanningError:
            continue
        margin = made.plan["stats"]["min_margin_deg"]
        if margin is None:
            continue
        planned += 1
        hull = [tuple(v) for v in made.plan["parts"][0]["hull"]]
        com = tuple(made.plan["parts"][0]["com"])
        rng = random.Random(seed)
        err = unc.rotation_error_deg + 0.99 * margin
        e = made.plan["sensor"].get("tolerance_mm", 0.0)
        for _ in range(12):
            poly, c = perturbed(hull, com, 0.0, 0.0, rng)
            assert not run_plan(made.plan, 0, poly, c, err, e, rng), (seed, err)


def test_a_margin_at_a_critical_tolerance_is_checked_on_the_paths_only(monkeypatch):
    """At a critical tolerance a reading interval touches a branch's end: the expected-length
    walk follows that branch with a rounding-level probability (~1e-16), the verified paths
    do not. A margin is checked where the paths go, so the planner's margin stands (it was
    lowered from 51.06 to 32.58 degrees by a state only the expected walk put at the node)."""
    import numpy as np
    from test_design_critical import random_pf as design_pf

    import feederkit.plans.make as make
    from feederkit.design.strong import StrongMix, strong_mix_critical

    rng = np.random.default_rng(10)
    for k in range(3):
        pfs = [design_pf(rng, f"a{k}"), design_pf(rng, f"b{k}")]
    (pair,) = strong_mix_critical(StrongMix(pfs, Uncertainty(1.0))).pairs
    made = make_plan(pfs, ToleranceSensor(pair.critical_tolerance), certify=False)
    verify_strong(made.plan)  # every margin holds for every state its paths bring to its node
    margins = [a["margin_deg"] for a in actions(made.plan)]
    assert made.plan["stats"]["min_margin_deg"] == min(margins) == made.result.min_margin
    # The same plan, its margins checked without lowering: nothing fails.
    seen: list[int] = []
    real = make.verify_strong

    def strict(plan, *args, **kwargs):
        kwargs["tighten_margins"] = False
        report = real(plan, *args, **kwargs)
        seen.append(1)
        return report

    monkeypatch.setattr(make, "verify_strong", strict)
    again = make_plan(pfs, ToleranceSensor(pair.critical_tolerance), certify=False)
    assert seen
    # Nothing was lowered: the file's margins are the planner's (once 51.06 degrees went to
    # 32.58 for a state only the expected walk put at its node).
    assert [a["margin_deg"] for a in actions(again.plan)] == margins


def test_a_margin_lowered_below_the_floor_is_said(monkeypatch):
    """Should the lowering take a margin below --min-margin, the plan says so (the file keeps
    what holds)."""
    import feederkit.plans.make as make

    real = make.verify_strong

    def lowering(plan, *args, **kwargs):
        report = real(plan, *args, **kwargs)
        for node in action_nodes(plan):
            node["margin_deg"] = 0.5
        plan["stats"]["min_margin_deg"] = 0.5
        return report

    monkeypatch.setattr(make, "verify_strong", lowering)
    pf = random_pf(20_001)
    from feederkit.planning.options import PlanningOptions

    made = make_plan([pf], NoSensor(), PlanningOptions(min_margin_deg=1.0), certify=False)
    assert made.result.min_margin == 0.5
    assert any("less than --min-margin 1" in w for w in made.warnings)


def test_a_sensed_certificate_at_the_declared_shape_tolerance_says_why(capsys):
    """Reading branches end at the declared widths, so a sensed plan's certified shape
    tolerance is the declared one; the table says so rather than only "largest"."""
    args = ["plan", str(CATALOG / "t-clip.json"), "--tolerance", "0.1", "--shape-tolerance"]
    assert main([*args, "0.05"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "0.05 mm (the declared: reading" in out
    assert main([*args[:-3], "--sensorless", "--shape-tolerance", "0.05"]) in (0, 1)
    assert "(the declared: reading" not in " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize("rotation_error", ["1", "0"])
def test_a_result_naming_a_state_no_path_ends_in_is_refused(tmp_path, capsys, rotation_error):
    # A controller may take any entry of a result as the answer (design.md): an entry for a
    # state that never ends there (and reads otherwise) would send the part to a wrong pose.
    path = tmp_path / "irt.plan.json"
    src = str(CATALOG / "isosceles-right-triangle.json")
    args = [src, "--tolerance", "0.01", "--rotation-error", rotation_error]
    assert main(["plan", *args, "-o", str(path)]) == 0
    plan = json.loads(path.read_text())
    assert verify_declared(plan).ok
    leaf = next(leaf for leaf in result_nodes(plan) if len(leaf["result"]) == 1)
    arrived = leaf["result"][0]["state"]
    states = plan["parts"][0]["stable_states"]
    other = next(s for s in states if s["id"] != arrived)
    leaf["result"].append(
        {"part": leaf["result"][0]["part"], "landing": leaf["result"][0].get("landing"),
         "state": other["id"], "pose_deg": other["pose_deg"]}
    )  # fmt: skip
    if leaf["result"][0].get("landing") is None:
        del leaf["result"][-1]["landing"]
    report = verify_declared(plan)
    assert not report.ok
    assert f"state {other['id']}" in report.first_problem()
    assert "ends there" in report.first_problem()
    bad = tmp_path / "bad.plan.json"
    bad.write_text(json.dumps(plan))
    capsys.readouterr()
    assert main(["run", str(bad), "--all"]) == 1
    assert "ends there" in capsys.readouterr().err


def test_a_state_unlike_its_geometry_says_how(bracket):
    # A COM moved 3 mm keeps edge, normal and diameter: the resting range tells them apart,
    # and the message must show it (it printed two equal sides).
    bad = tampered(
        bracket, lambda p: p["parts"][0]["com"].__setitem__(0, p["parts"][0]["com"][0] + 3.0)
    )
    report = verify_declared(bad)
    assert not report.ok
    problem = report.first_problem()
    said, given = problem.split(", but its hull and COM give ")
    assert "resting range" in said and said.split(" says ")[1] != given
