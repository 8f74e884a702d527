"""The simulator's pure pieces and its command line's errors; none of this needs MuJoCo."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from test_sim_plans import build_plan, pentagon, rectangle

from feederkit.errors import InputError
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor
from feederkit.sim.massprops import plate_inertia, region_moments
from feederkit.sim.planfile import Leaf, Step, read_plan
from feederkit.sim.readings import reading_of
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
    assert reading_of(NoSensor(), 20.3) is None
    assert reading_of(ToleranceSensor(0.5), 20.3) == 20.3
    assert reading_of(LedSensor(2.0), 20.3) == pytest.approx(20.0)  # beams at 2, 4, ..., 20
    assert reading_of(LedSensor(2.0), 19.9) == pytest.approx(18.0)


def test_scene_has_priority_belt_and_fence_a_free_part_and_a_2ms_step() -> None:
    part = pentagon()
    xml = scene_xml(part, SceneConfig())
    assert xml.count('priority="1"') == 2
    assert "<freejoint" in xml and 'type="slide"' in xml
    assert 'timestep="0.002"' in xml
    mesh = xml.split('<mesh name="part" vertex="')[1].split('"')[0].split()
    assert len(mesh) == 3 * 2 * len(part.hull)


def test_read_plan_rebuilds_parts_and_the_tree() -> None:
    plan = read_plan(build_plan(rectangle(), 1.0))
    assert [p.name for p in plan.parts] == ["rect-2x1"]
    assert isinstance(plan.root, Step) and plan.root.action_deg is None
    assert plan.min_margin_deg == pytest.approx(4.68, abs=0.01)
    first = plan.root.branches[0].next
    assert isinstance(first, Step) and first.action_deg is not None
    assert all(isinstance(b.next, Leaf) for b in first.branches)
    assert set(plan.parts[0].state_of_edge.values()) == {0, 1, 2, 3}


def test_branches_hold_closed_intervals_and_shared_endpoints() -> None:
    root = read_plan(build_plan(rectangle(), 1.0)).root
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
        (lambda p: p.update(version=2), "version"),
        (lambda p: p.update(parts=[]), "parts"),
        (lambda p: p["parts"][0]["stable_states"][0].update(normal_deg=13.0), "not a stable edge"),
        (lambda p: p["parts"][0]["stable_states"].pop(), "lists 3 stable states"),
        (lambda p: p["parts"][0].update(com=[99, 99]), "outside the contact hull"),
        (lambda p: p["root"]["branches"][0]["next"].update(action_deg=None), "no action_deg"),
        (lambda p: p["root"].update(branches=[]), "non-empty list of branches"),
        (lambda p: p["root"]["branches"][0].update(reading=[5, 1]), "lo > hi"),
        (lambda p: p["root"]["branches"][0].update(reading="x"), "a pair lo, hi or null"),
        (lambda p: p.update(sensor={"model": "laser"}), "unknown sensor model"),
        (
            lambda p: p["root"]["branches"][0]["next"]["branches"][0]["next"].update(
                result=[{"part": "rect-2x1", "state": 9}]
            ),
            "state 9",
        ),
    ],
)
def test_bad_plans_are_one_line_input_errors(mutate, words: str) -> None:
    with pytest.raises(InputError) as exc:
        read_plan(_broken(mutate))
    assert words in str(exc.value)
    assert "\n" not in str(exc.value)


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
