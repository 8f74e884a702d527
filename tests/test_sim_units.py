"""The simulator's pure pieces and its command line's errors; none of this needs MuJoCo."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from test_sim_plans import build_plan, pentagon, rectangle

from feederkit.errors import CheckFailed, InputError
from feederkit.plans.model import Leaf, Step, push_function_of
from feederkit.plans.readplan import plan_from_dict
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor
from feederkit.sim.massprops import plate_inertia, region_moments
from feederkit.sim.scene import SceneConfig, scene_xml

RUN = "from feederkit.cli.app import run; run()"


def test_plate_inertia_of_a_rectangle_with_a_hole() -> None:
    outer = [(0, 0), (2, 0), (2, 1), (0, 1)]
    hole = [(0.5, 0.25), (1.5, 0.25), (1.5, 0.75), (0.5, 0.75)]
    assert region_moments(outer, [hole]).area == pytest.approx(1.5)
    p = plate_inertia(outer, [hole], (1.0, 0.5), thickness=1.0, density=1.0)
    assert p.mass == pytest.approx(1.5)
    izz = 2 * (4 + 1) / 12 - 0.5 * (1 + 0.25) / 12
    assert p.inertia[2] == pytest.approx(izz)
    assert p.inertia[3] == pytest.approx(0.0)


def test_plate_inertia_moves_to_the_users_com() -> None:
    tri = [(0, 0), (1, 0), (0, 1)]
    at_centroid = plate_inertia(tri, [], (1 / 3, 1 / 3), 1.0, 1.0)
    assert at_centroid.inertia[3] == pytest.approx(1 / 72)  # -(product of inertia)
    shifted = plate_inertia(tri, [], (0.4, 0.3), 1.0, 1.0)
    d2 = (0.4 - 1 / 3) ** 2 + (0.3 - 1 / 3) ** 2
    assert shifted.inertia[2] == pytest.approx(at_centroid.inertia[2] + 0.5 * d2)


def test_readings_follow_the_plans_sensor_model() -> None:
    assert NoSensor().read(20.3) is None
    assert ToleranceSensor(0.5).read(20.3) == 20.3
    assert LedSensor(2.0).read(20.3) == pytest.approx(20.0)  # beams at 2, 4, ..., 20
    assert LedSensor(2.0).read(19.9) == pytest.approx(18.0)


def test_scene_has_priority_belt_and_fence_a_free_part_and_a_2ms_step() -> None:
    part = pentagon()
    xml = scene_xml(part, SceneConfig())
    assert xml.count('priority="1"') == 2
    assert "<freejoint" in xml and 'type="slide"' in xml
    assert 'timestep="0.002"' in xml
    mesh = xml.split('<mesh name="part" vertex="')[1].split('"')[0].split()
    assert len(mesh) == 3 * 2 * len(part.hull)


def test_the_plan_model_rebuilds_parts_and_the_tree() -> None:
    plan = plan_from_dict(build_plan(rectangle(), 1.0))
    assert [p.name for p in plan.parts] == ["rect-2x1"]
    assert isinstance(plan.root, Step) and plan.root.action_deg is None
    assert plan.stats.min_margin_deg == pytest.approx(4.68, abs=0.01)
    first = plan.root.branches[0].next
    assert isinstance(first, Step) and first.action_deg is not None
    assert all(isinstance(b.next, Leaf) for b in first.branches)
    assert {s.id for s in push_function_of(plan.parts[0]).states} == {0, 1, 2, 3}


def test_branches_hold_closed_intervals_and_shared_endpoints() -> None:
    root = plan_from_dict(build_plan(rectangle(), 1.0)).root
    assert root.follow(19.0) == 0 and root.follow(21.0) == 0
    assert root.follow(39.0) == 1
    assert root.follow(30.0) is None
    assert root.follow(None) is None


def _broken(mutate) -> dict:
    plan = build_plan(rectangle(), 1.0)
    mutate(plan)
    return plan


@pytest.mark.parametrize(
    ("mutate", "words"),
    [
        (lambda p: p.update(format="other"), "not a feederkit plan"),
        (lambda p: p.update(version=3), "version"),
        (lambda p: p.update(version=1.0), "version"),
        (lambda p: p.update(version=True), "version"),
        (lambda p: p.update(parts=[]), "parts"),
        (lambda p: p["parts"][0].update(com=[99, 99]), "outside the contact hull"),
        (lambda p: p["root"]["branches"][0]["next"].update(action_deg=None), "action_deg"),
        (lambda p: p["root"].update(branches=[]), "no branches"),
        (lambda p: p["root"]["branches"][0].update(reading=[5, 1]), "lo > hi"),
        (lambda p: p["root"]["branches"][0].update(reading="x"), "a pair"),
        (lambda p: p.update(sensor={"model": "laser"}), "unknown sensor model"),
        (lambda p: p["stats"].update(length=7), "stats length"),
        (lambda p: p["stats"].pop("min_margin_deg"), "min_margin_deg"),
        (lambda p: p.pop("stats"), "stats"),
        (
            lambda p: p["root"]["branches"][0]["next"]["branches"][0]["next"].update(
                result=[{"part": "rect-2x1", "state": 9}]
            ),
            "state 9",
        ),
    ],
)
def test_bad_plans_are_one_line_input_errors(mutate, words: str) -> None:
    from feederkit.sim import simulate_plan

    with pytest.raises(InputError) as exc:
        simulate_plan(_broken(mutate), trials=1, seed=0)
    assert words in str(exc.value)
    assert "\n" not in str(exc.value)


def _inflate_first_margin(plan: dict) -> None:
    """Widen the first rotation's margin to ±170 degrees, the stats kept consistent."""
    step = plan["root"]["branches"][0]["next"]
    step["margin_deg"] = 170.0
    plan["stats"]["min_margin_deg"] = min(
        b["next"]["margin_deg"] for b in plan["root"]["branches"] if "margin_deg" in b["next"]
    )


@pytest.mark.parametrize(
    "mutate",
    [
        lambda p: p["parts"][0]["stable_states"][0].update(
            normal_deg=p["parts"][0]["stable_states"][0]["normal_deg"] + 0.01
        ),
        lambda p: p["parts"][0]["stable_states"][0].update(diameter=20.5),
        lambda p: p["parts"][0]["stable_states"].pop(),
        _inflate_first_margin,
    ],
)
def test_plans_wrong_for_their_geometry_fail_before_any_trial(mutate) -> None:
    from feederkit.sim import simulate_plan

    with pytest.raises(CheckFailed) as exc:
        simulate_plan(_broken(mutate), trials=1, seed=0)
    assert "failed verification" in str(exc.value) and "\n" not in str(exc.value)


def test_simulate_plan_refuses_impossible_settings() -> None:
    from feederkit.sim import simulate_plan

    plan = build_plan(rectangle(), 1.0)
    for kwargs in (
        {"trials": 0},
        {"trials": 2, "rotation_noise_deg": -1.0},
        {"trials": 2, "belt_speed": 0.0},
        {"trials": 2, "friction_belt": 0.0},
        {"trials": 2, "friction_fence": float("nan")},
    ):
        with pytest.raises(InputError):
            simulate_plan(plan, seed=0, **kwargs)


def _cli(args: list[str], *, hide_mujoco: bool = False) -> subprocess.CompletedProcess:
    code = ("import sys; sys.modules['mujoco'] = None; " if hide_mujoco else "") + RUN
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, check=False
    )


def test_without_mujoco_simulate_exits_2_saying_what_to_install(tmp_path: Path) -> None:
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(build_plan(rectangle(), 1.0)), encoding="utf-8")
    out = _cli(["simulate", str(path)], hide_mujoco=True)
    assert out.returncode == 2
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "install feederkit[sim]" in lines[0]
    assert out.stdout == ""


def test_bad_plan_files_exit_2_with_one_line(tmp_path: Path) -> None:
    pytest.importorskip("mujoco", reason="MuJoCo is not installed: the command stops before")
    missing = tmp_path / "nope.json"
    garbage = tmp_path / "garbage.json"
    garbage.write_text("{not json", encoding="utf-8")
    for path in (missing, garbage):
        out = _cli(["simulate", str(path)])
        assert out.returncode == 2
        lines = [line for line in out.stderr.splitlines() if line.strip()]
        assert len(lines) == 1 and str(path.name) in lines[0]


@pytest.mark.parametrize(
    ("mutate", "code", "words"),
    [
        (lambda p: p.pop("stats"), 2, "stats"),
        (lambda p: p["root"]["branches"][0]["next"].pop("margin_deg"), 2, "margin_deg"),
        (lambda p: p["parts"][0]["stable_states"][0].update(diameter=20.5), 1, "diameter"),
    ],
)
def test_simulate_checks_plan_files_as_run_and_report_do(tmp_path: Path, mutate, code, words):
    pytest.importorskip("mujoco", reason="MuJoCo is not installed: the command stops before")
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(_broken(mutate)), encoding="utf-8")
    out = _cli(["simulate", str(path), "--trials", "1"])
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert out.returncode == code, out.stderr
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in out.stderr


# --- plans over landings (design.md, "Landings") ----------------------------------------------


def test_a_leaf_names_a_member_by_its_landing() -> None:
    from feederkit.plans.model import ResultEntry
    from feederkit.sim.trial import leaf_holds

    accept = Leaf((ResultEntry("bracket", 2, 0.0, "up"),))
    reject = Leaf((ResultEntry("bracket", 2, 0.0, "down"),), reject=True)
    assert leaf_holds(accept, "bracket", 2, "up")
    assert not leaf_holds(accept, "bracket", 2, "down")
    assert not leaf_holds(accept, "bracket", 1, "up")
    assert leaf_holds(reject, "bracket", 2, "down")
    old = Leaf((ResultEntry("bracket", 2, 0.0),))  # a plan not made over landings
    assert leaf_holds(old, "bracket", 2, None) and not leaf_holds(old, "bracket", 2, "up")


def test_wrong_accepts_are_counted_apart_from_rejects() -> None:
    from simsummaries import sim_summary

    from feederkit.sim.summary import TrialResult

    def trial(i: int, outcome: str, rejected: bool, cause: str | None = None) -> TrialResult:
        return TrialResult(
            i,
            "bracket",
            0.0,
            outcome,
            None,
            None,
            0,
            (),
            cause=cause,
            predicted=None if outcome == "success" else True,
            landing="down",
            rejected=rejected,
        )

    wrong_accept = trial(2, "failure", False, "wrong result")
    wrong_reject = trial(3, "failure", True, "wrong result")
    no_branch = trial(4, "failure", False, "reading in no branch")
    assert wrong_accept.wrong_accept and not wrong_reject.wrong_accept
    assert not no_branch.wrong_accept and not trial(1, "success", True).wrong_accept
    s = sim_summary(
        {"bracket (up)": (1, 1), "bracket (down)": (1, 4)},
        min_margin_deg=None,
        failures=(wrong_accept, wrong_reject, no_branch),
        rejects=1,
    )
    d = s.to_dict()
    assert (d["rejects"], d["wrong_accepts"]) == (1, 1)
    assert [r["landing"] for r in d["failures"]] == ["down"] * 3
    assert [r["rejected"] for r in d["failures"]] == [False, True, False]


def test_members_are_drawn_by_their_shares() -> None:
    from dataclasses import replace

    from feederkit.sim.api import _member_shares

    plan = plan_from_dict(build_plan(rectangle(), 1.0))
    assert _member_shares(plan) is None  # no shares: equally likely, drawn as before
    two = replace(plan, parts=(plan.parts[0], replace(plan.parts[0], name="copy")))
    assert _member_shares(two) is None
    if not hasattr(plan.parts[0], "share"):
        pytest.skip("plan parts carry no share in this version of the plan model")
    shares = replace(
        two, parts=tuple(replace(p, share=w) for p, w in zip(two.parts, (3.0, 1.0), strict=True))
    )
    assert _member_shares(shares).tolist() == pytest.approx([0.75, 0.25])
    bad = replace(
        two, parts=tuple(replace(p, share=w) for p, w in zip(two.parts, (0.0, 0.0), strict=True))
    )
    with pytest.raises(InputError, match="shares"):
        _member_shares(bad)
