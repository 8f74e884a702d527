"""What a plan says of the cell profile it was made with (design.md, "Cell profile": every
output names the profile it used): the plan file and ``--json`` name it also when it gives
no timing (``stats.cell_profile``, ``"cycle_time": null``), and so does the ``--json`` of
a plan refused; the unknown cycle time names the fields the profile lacks; a profile whose
sensor is none is named as the reason a plan is sensorless; a rate past a million is
printed in powers of ten."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
T_CLIP = str(CATALOG / "t-clip.json")


def words(text: str) -> str:
    return " ".join(text.split())


@pytest.fixture
def here(tmp_path, monkeypatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


def profile(folder: Path, name: str, text: str) -> str:
    (folder / name).write_text(text)
    return name


def test_the_plan_file_names_a_profile_without_timing(here, capsys):
    cell = profile(here, "intval.toml", '[sensor]\nmodel = "tolerance"\ntolerance_mm = 1\n')
    assert main(["plan", T_CLIP, "--cell", cell, "--json"]) == 0
    stats = json.loads(capsys.readouterr().out)["stats"]
    assert stats["cell_profile"] == "intval.toml"
    assert "cycle_time" in stats and stats["cycle_time"] is None


def test_a_refused_plan_names_its_profile_in_json(here, capsys):
    cell = profile(here, "intval.toml", '[sensor]\nmodel = "tolerance"\ntolerance_mm = 1\n')
    assert main(["plan", T_CLIP, "--cell", cell, "--min-margin", "100", "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["cell"]["profile"] == "intval.toml"


def test_an_unknown_cycle_time_names_what_the_profile_lacks(here, capsys):
    cell = profile(here, "partial.toml", "[robot]\npick_place_s = 1\n")
    assert main(["plan", T_CLIP, "--cell", cell, "-o", "p.json"]) == 0
    out = words(capsys.readouterr().out)
    assert (
        "cycle time: not known, the cell profile gives no robot.rotation_speed_deg_s, "
        "belt.speed_m_s, belt.drop_to_fence_mm (partial.toml)"
    ) in out
    assert json.loads((here / "p.json").read_text())["stats"]["cell_profile"] == "partial.toml"


def test_a_profile_without_a_sensor_is_named_as_the_reason(here, capsys):
    cell = profile(here, "none.toml", '[sensor]\nmodel = "none"\n')
    assert main(["plan", T_CLIP, "--cell", cell, "-o", "p.json"]) == 0
    out = words(capsys.readouterr().out)
    assert "cell profile: none.toml" in out
    assert "sensor: none — no sensor option given, and the profile gives no sensor" in out


def test_a_rate_past_a_million_is_short(here, capsys):
    text = "[robot]\npick_place_s = 0\nrotation_speed_deg_s = 1e300\n"
    cell = profile(here, "zero.toml", text + "[belt]\nspeed_m_s = 0.1\ndrop_to_fence_mm = 0\n")
    assert main(["plan", T_CLIP, "--cell", cell, "-o", "p.json"]) == 0
    out = words(capsys.readouterr().out)
    line = out[out.index("cycle time:") : out.index("wrote the plan")]
    assert "1.85e+299 parts/min" in line and len(line) < 120, line


def test_a_lookalike_s_com_has_no_negative_zero(here, capsys):
    assert main(["lookalike", str(CATALOG / "octagon.json"), "--keep", "push-diameter",
                 "-o", "f8.json"]) == 0  # fmt: skip
    assert "(-0, -0)" not in capsys.readouterr().out
    assert "-0.0" not in (here / "f8.json").read_text()
