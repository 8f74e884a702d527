"""The cell profile (feederkit.cell): parsing, validation, overrides and cycle time."""

from __future__ import annotations

import ast
import itertools
import math
from pathlib import Path

import pytest

from feederkit.cell import (
    BUILT_IN,
    CellProfile,
    CellProfileError,
    cycle_time,
    load_cell,
    operation_seconds,
    parse_cell,
    read_cell,
    resolve_settings,
    rotation_deg,
)
from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.mechanics.push import push_function
from feederkit.plans.make import make_plan
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor
from feederkit.sources import load_part

CATALOG = Path(__file__).resolve().parents[1] / "catalog"

EXAMPLE = """
[sensor]
model = "tolerance"
tolerance_mm = 0.2

[robot]
rotation_error_deg = 0.5
pick_place_s = 1.2
rotation_speed_deg_s = 180

[belt]
speed_m_s = 0.1
drop_to_fence_mm = 150
"""


def write(tmp_path: Path, text: str, name: str = "feederkit.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_the_documented_example_reads(tmp_path):
    profile = read_cell(write(tmp_path, EXAMPLE))
    assert profile.sensor.sensor() == ToleranceSensor(0.2)
    assert profile.robot.rotation_error_deg == 0.5
    assert profile.robot.pick_place_s == 1.2 and profile.robot.rotation_speed_deg_s == 180.0
    assert profile.belt.speed_m_s == 0.1 and profile.belt.drop_to_fence_mm == 150.0
    assert profile.source.endswith("feederkit.toml") and not profile.missing_timing()
    assert profile.to_dict()["robot"]["pick_place_s"] == 1.2


def test_the_docs_worked_example_is_the_tested_one():
    docs = (Path(__file__).resolve().parents[1] / "docs" / "cell.md").read_text()
    assert EXAMPLE.strip() in docs


def test_defaults_without_a_file(tmp_path):
    profile = load_cell(directory=tmp_path)
    assert profile == CellProfile() and profile.source == BUILT_IN
    assert profile.sensor.sensor() == NoSensor()
    assert profile.robot.rotation_error_deg == 1.0  # design.md's default
    assert set(profile.missing_timing()) == {
        "robot.pick_place_s",
        "robot.rotation_speed_deg_s",
        "belt.speed_m_s",
        "belt.drop_to_fence_mm",
    }


def test_the_working_directorys_profile_is_found(tmp_path):
    write(tmp_path, '[sensor]\nmodel = "led"\npitch_mm = 0.5\nnoise_mm = 0.1\n')
    profile = load_cell(directory=tmp_path)
    assert profile.sensor.sensor() == LedSensor(0.5, 0.1)
    assert profile.source == str(tmp_path / "feederkit.toml")


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("[sensor]\ncolour = 1\n", "unknown key sensor.colour"),
        ("[camera]\nfps = 30\n", "unknown section [camera]"),
        ('[sensor]\nmodel = "laser"\n', "sensor.model must be one of"),
        ('[sensor]\nmodel = "tolerance"\n', "sensor.tolerance_mm is required"),
        ('[sensor]\nmodel = "tolerance"\ntolerance_mm = -0.1\n', "sensor.tolerance_mm must be"),
        (
            '[sensor]\nmodel = "tolerance"\ntolerance_mm = 0.1\npitch_mm = 1\n',
            "sensor.pitch_mm goes",
        ),
        ('[sensor]\nmodel = "led"\npitch_mm = 0\n', "sensor.pitch_mm must be a finite positive"),
        ('[sensor]\nmodel = "led"\npitch_mm = 1\nnoise_mm = -1\n', "sensor.noise_mm must be"),
        ("[robot]\nrotation_error_deg = 200\n", "robot.rotation_error_deg must be"),
        ("[robot]\npick_place_s = -1\n", "robot.pick_place_s must be zero or a finite positive"),
        (
            "[robot]\nrotation_speed_deg_s = 0\n",
            "robot.rotation_speed_deg_s must be a finite positive",
        ),
        ('[robot]\npick_place_s = "fast"\n', "robot.pick_place_s must be"),
        ("[robot]\npick_place_s = true\n", "robot.pick_place_s must be"),
        ("[belt]\nspeed_m_s = nan\n", "belt.speed_m_s must be a finite positive"),
        ("[belt]\ndrop_to_fence_mm = -5\n", "belt.drop_to_fence_mm must be"),
        ("belt = 3\n", "belt must be a table"),
    ],
)
def test_each_bad_field_is_named(tmp_path, text, needle):
    with pytest.raises(CellProfileError) as info:
        read_cell(write(tmp_path, text))
    assert needle in str(info.value) and "\n" not in str(info.value)
    assert str(info.value).startswith(str(tmp_path))


def test_every_bad_field_gets_its_own_line():
    with pytest.raises(CellProfileError) as info:
        parse_cell({"robot": {"pick_place_s": -1, "speed": 2}, "belt": {"speed_m_s": 0}}, "x")
    assert len(info.value.problems) == 3


def test_a_bad_required_value_is_named_once_not_also_missing():
    with pytest.raises(CellProfileError) as info:
        parse_cell({"sensor": {"model": "tolerance", "tolerance_mm": -1}}, "x")
    assert info.value.problems == (
        "sensor.tolerance_mm must be a finite positive number of mm, got -1",
    )
    with pytest.raises(CellProfileError) as info:
        parse_cell({"sensor": {"model": "led"}}, "x")
    assert info.value.problems == ("sensor.pitch_mm is required with model = 'led'",)


def test_broken_and_missing_files_are_one_line(tmp_path):
    with pytest.raises(InputError, match="not a valid TOML file"):
        read_cell(write(tmp_path, "[sensor\nmodel = 1\n"))
    with pytest.raises(InputError, match="no such cell profile"):
        load_cell(tmp_path / "absent.toml")


def test_command_line_options_override_the_profile(tmp_path):
    profile = read_cell(write(tmp_path, EXAMPLE))
    plain = resolve_settings(profile)
    assert plain.sensor == ToleranceSensor(0.2) and plain.rotation_error_deg == 0.5
    assert plain.overrides == () and plain.describe().endswith("feederkit.toml")
    led = resolve_settings(profile, led_pitch=0.3, noise=0.05, rotation_error=2.0)
    assert led.sensor == LedSensor(0.3, 0.05) and led.rotation_error_deg == 2.0
    assert led.overrides == ("--led-pitch", "--noise", "--rotation-error")
    assert "overridden: --led-pitch" in led.describe()
    assert resolve_settings(profile, sensorless=True).sensor == NoSensor()
    with pytest.raises(InputError, match="--noise goes with"):
        resolve_settings(profile, noise=0.1)
    with pytest.raises(InputError, match="--rotation-error"):
        resolve_settings(profile, rotation_error=-1.0)
    with pytest.raises(InputError):
        resolve_settings(profile, tolerance=0.1, led_pitch=0.2)
    led_profile = parse_cell({"sensor": {"model": "led", "pitch_mm": 0.5, "noise_mm": 0.1}}, "p")
    assert resolve_settings(led_profile, noise=0.2).sensor == LedSensor(0.5, 0.2)
    assert resolve_settings(led_profile, led_pitch=0.25).sensor == LedSensor(0.25, 0.1)


def timing(pick: float, speed: float, belt: float, travel: float) -> CellProfile:
    return parse_cell(
        {
            "robot": {"pick_place_s": pick, "rotation_speed_deg_s": speed},
            "belt": {"speed_m_s": belt, "drop_to_fence_mm": travel},
        },
        "test",
    )


@pytest.fixture(scope="module")
def mix_plan():
    pfs = [
        push_function(load_part(str(CATALOG / f"{n}.json")))
        for n in ("quadrilateral", "rectangle-2x1", "l-bracket")
    ]
    return make_plan(pfs, ToleranceSensor(0.3))


def test_rotation_goes_the_shorter_way():
    assert rotation_deg(90.0) == 90.0 and rotation_deg(270.0) == 90.0
    assert rotation_deg(-30.0) == pytest.approx(30.0) and rotation_deg(360.0) == 0.0


def test_drift_only_counts_operations(mix_plan):
    # One second of drift per operation, nothing else: the seconds are the operation counts.
    t = cycle_time(mix_plan, timing(0.0, 1e12, 0.1, 100.0))
    assert t.expected_s == pytest.approx(mix_plan.result.expected_length, rel=1e-9)
    assert t.worst_s == pytest.approx(mix_plan.result.length, rel=1e-9)
    assert t.parts_per_minute == pytest.approx(60.0 / t.expected_s)


def test_pick_and_place_comes_after_the_first_alignment(mix_plan):
    t = cycle_time(mix_plan.result, timing(2.0, 1e12, 1.0, 0.0))
    assert t.expected_s == pytest.approx(2.0 * (mix_plan.result.expected_length - 1.0))
    assert t.worst_s == pytest.approx(2.0 * (mix_plan.result.length - 1))


def test_rotation_time_follows_the_plans_angles():
    # A sensorless plan for one part is one path: its time is the sum along it.
    pf = push_function(load_part(str(CATALOG / "quadrilateral.json")))
    made = make_plan([pf], NoSensor())
    angles = []
    node = made.plan["root"]
    while "branches" in node:
        if node["action_deg"] is not None:
            angles.append(node["action_deg"])
        (branch,) = node["branches"]
        node = branch["next"]
        if "ref" in node:
            node = made.plan["nodes"][node["ref"]]
    assert angles
    speed = 90.0
    want = sum(min(a % 360, 360 - a % 360) / speed for a in angles)
    t = cycle_time(made, timing(0.0, speed, 1.0, 0.0))
    assert t.expected_s == pytest.approx(want, rel=1e-9)
    assert t.worst_s == pytest.approx(want, rel=1e-9)


def test_a_cycle_time_needs_the_timing_fields(mix_plan):
    with pytest.raises(InputError, match="robot.pick_place_s"):
        cycle_time(mix_plan, CellProfile())
    assert operation_seconds(None, timing(1.0, 90.0, 0.5, 100.0)) == pytest.approx(0.2)
    assert operation_seconds(90.0, timing(1.0, 90.0, 0.5, 100.0)) == pytest.approx(2.2)


def test_no_time_means_no_parts_per_minute():
    from feederkit.cell import CycleTime

    assert CycleTime(0.0, 0.0).parts_per_minute is None
    assert CycleTime(0.0, 0.0).to_dict()["worst_parts_per_minute"] is None
    assert CycleTime(2.0, 4.0).worst_parts_per_minute == pytest.approx(15.0)


def test_cycle_time_follows_outcome_sets_under_uncertainty():
    # Strong plans: a state's mass follows its outcome set (docs/planning.md); free turns
    # and one second per operation make the seconds the expected operations again.
    from feederkit.uncertainty import Uncertainty

    pfs = [
        push_function(load_part(str(CATALOG / f"{n}.json"))) for n in ("t-clip", "chamfered-plate")
    ]
    made = make_plan(pfs, ToleranceSensor(0.5), uncertainty=Uncertainty(1.0, 0.0, 0.0))
    t = cycle_time(made, timing(0.0, 1e12, 0.1, 100.0))
    assert t.expected_s == pytest.approx(made.result.expected_length, rel=1e-9)
    assert t.worst_s == pytest.approx(made.result.length, rel=1e-9)


def _members(*rows):
    from types import SimpleNamespace

    return [SimpleNamespace(name=n, landing=landing, share=share) for n, landing, share in rows]


@pytest.mark.parametrize(
    ("rows", "words"),
    [
        ([("a", None, None)], "uniform start orientation"),
        ([("a", None, None), ("b", None, None)], "parts equally likely, uniform start orientation"),
        ([("a", None, 0.7), ("b", None, 0.3)], "over the mix shares, uniform start orientation"),
        (
            [("a", "up", 0.5), ("a", "down", 0.5)],
            "over the landing probabilities, uniform start orientation",
        ),
        (
            [("a", "up", 0.35), ("a", "down", 0.35), ("b", "up", 0.3)],
            "over the mix shares × landing probabilities, uniform start orientation",
        ),
    ],
)
def test_the_expectation_is_named_for_what_it_averages_over(rows, words):
    from feederkit.cell import expectation_words

    assert expectation_words(_members(*rows)) == words


def test_the_statistics_table_says_the_mix_shares_weigh_the_expectation(mix_plan):
    from rich.console import Console

    from feederkit.cli.plan_render import stats_table
    from feederkit.plans.readplan import as_plan

    pfs = [
        push_function(load_part(str(CATALOG / f"{n}.json")))
        for n in ("quadrilateral", "rectangle-2x1")
    ]
    weighted = make_plan(pfs, ToleranceSensor(0.3), weights=[0.7, 0.3], certify=False)

    def label(made):
        console = Console(width=200, record=True)
        console.print(stats_table(as_plan(made.plan)))
        return next(ln for ln in console.export_text().splitlines() if "expected operations" in ln)

    assert "(over the mix shares, uniform start orientation)" in label(weighted)
    assert "(parts equally likely, uniform start orientation)" in label(mix_plan)


def _block(text: str, start: str) -> str:
    """The fenced block that opens with ``start`` (its body)."""
    i = text.index(start) + len(start)
    return text[i : text.index("```", i)]


def _printed(text: str, after: str) -> list[str]:
    """The indented lines of the first output block after ``after``."""
    rest = text[text.index(after) + len(after) :].split("\n")[2:]
    return [x[4:] for x in itertools.takewhile(lambda x: x.startswith("    "), rest)]


def test_the_worked_example_prints_what_the_docs_say(tmp_path, monkeypatch, capsys):
    """docs/cell.md's snippet, run with its profile: the printed figures are the page's."""
    root = Path(__file__).resolve().parents[1]
    docs = (root / "docs" / "cell.md").read_text(encoding="utf-8")
    worked = docs[docs.index("## Worked example") :]
    write(tmp_path, _block(worked, "```toml\n"))
    (tmp_path / "catalog").symlink_to(root / "catalog")
    monkeypatch.chdir(tmp_path)
    exec(compile(_block(worked, "```python\n"), "cell.md", "exec"), {})
    got = capsys.readouterr().out.strip().split("\n")
    want = _printed(worked, "prints (")
    assert len(got) == len(want) == 6
    for g, w in zip(got, want, strict=True):
        if g.startswith("{"):
            gd, wd = ast.literal_eval(g), ast.literal_eval(w)
            assert gd.keys() == wd.keys()
            assert all(math.isclose(gd[k], wd[k], abs_tol=1.5e-3) for k in gd), (g, w)
        else:
            assert g == w


def test_a_belt_faster_than_the_model_was_measured_at_is_named(tmp_path, capsys):
    # The overshoot of shallow states was measured at 0.1 m/s (docs/uncertainty.md).
    root = Path(__file__).resolve().parents[1]
    fast = tmp_path / "fast.toml"
    fast.write_text('[sensor]\nmodel = "tolerance"\ntolerance_mm = 0.5\n[belt]\nspeed_m_s = 0.3\n')
    part = str(root / "catalog" / "t-clip.json")
    assert main(["plan", part, "--cell", str(fast), "-o", str(tmp_path / "p.json")]) == 0
    err = capsys.readouterr().err
    assert "the belt runs at 0.3 m/s" in err and "9 times here" in err
    assert "simulate --belt-speed 0.3" in err
    slow = tmp_path / "slow.toml"
    slow.write_text('[sensor]\nmodel = "tolerance"\ntolerance_mm = 0.5\n[belt]\nspeed_m_s = 0.1\n')
    assert main(["plan", part, "--cell", str(slow), "-o", str(tmp_path / "q.json")]) == 0
    assert "the belt runs at" not in capsys.readouterr().err
