"""What a new user setting up a changeover is told: a damaged catalog part, `plan --json`
as the plan file, a folder or extreme timing given as the cell profile, overflowing mix
shares, and the short form of a landing name."""

from __future__ import annotations

import re
import sqlite3
from pathlib import Path

import pytest
from shared import one_line_error

from feederkit.cell import (
    BeltSection,
    CellProfile,
    CellProfileError,
    RobotSection,
    action_costs,
    parse_cell,
    read_cell,
    resolve_settings,
)
from feederkit.cli.app import main
from feederkit.cli.changeover import parse_mix_shares
from feederkit.errors import InputError
from feederkit.landing.plan import landing_names
from feederkit.sources import load_part

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


# --- a damaged catalog row is the catalog's own line, not "no such part" -------------------


@pytest.fixture
def db(tmp_path: Path) -> Path:
    path = tmp_path / "c.db"
    assert main(["catalog", "add", str(CATALOG / "l-bracket.json"), "--catalog", str(path)]) == 0
    return path


def _edit(db: Path, sql: str) -> None:
    conn = sqlite3.connect(db)
    conn.execute("PRAGMA ignore_check_constraints = ON")
    conn.execute(sql)
    conn.commit()
    conn.close()


@pytest.mark.parametrize(
    "sql",
    [
        "UPDATE revisions SET hull_json = '[[0, 0], [10, 0]]'",
        "UPDATE revisions SET com_x = 'abc'",
        "PRAGMA user_version = 99",
    ],
)
def test_a_damaged_part_or_catalog_says_what_catalog_show_says(db, capsys, sql) -> None:
    capsys.readouterr()
    _edit(db, sql)
    shown = one_line_error(capsys, ["catalog", "show", "l-bracket", "--catalog", str(db)])
    planned = one_line_error(
        capsys, ["plan", "l-bracket", "--tolerance", "0.2", "--catalog", str(db)]
    )
    assert planned == shown
    assert "no such" not in planned
    with pytest.raises(InputError) as exc:  # a changeover's parts are loaded as NAME@REV
        load_part("l-bracket@1", catalog=str(db))
    assert "no such" not in str(exc.value)


def test_an_unknown_name_or_revision_is_still_no_such_part(db, capsys) -> None:
    capsys.readouterr()
    _edit(db, "UPDATE revisions SET hull_json = '[[0, 0], [10, 0]]'")
    err = one_line_error(capsys, ["plan", "l-brackt", "--tolerance", "0.2", "--catalog", str(db)])
    assert err.startswith("error: l-brackt: no such file or catalog part (no part named")
    assert "did you mean 'l-bracket'" in err
    with pytest.raises(InputError, match=r"^l-bracket@7: no such file or catalog part \(part"):
        load_part("l-bracket@7", catalog=str(db))


# --- plan --json prints the plan file as -o writes it --------------------------------------


@pytest.mark.parametrize(
    ("args", "code"),
    [
        ([str(CATALOG / "t-clip.json"), "--tolerance", "0.2"], 0),
        # a mix no plan tells apart: exit 1, the plan is still the one answer on stdout
        ([str(CATALOG / "t-clip.json"), str(CATALOG / "octagon.json"), "--sensorless"], 1),
    ],
)
def test_plan_json_prints_the_bytes_of_the_plan_file(tmp_path, capsys, args, code) -> None:
    out = tmp_path / "plan.json"
    assert main(["plan", *args, "-o", str(out), "--json"]) == code
    printed = capsys.readouterr().out
    assert printed.encode("utf-8") == out.read_bytes()


# --- the cell profile: a folder, and times too long to compute with ------------------------


def test_a_folder_as_the_cell_profile_says_it_is_a_folder(tmp_path, capsys) -> None:
    err = one_line_error(capsys, ["plan", str(CATALOG / "t-clip.json"), "--cell", str(tmp_path)])
    assert err == f"error: {tmp_path}: a folder, not a cell profile file\n"
    with pytest.raises(InputError, match="no such cell profile"):
        read_cell(tmp_path / "missing.toml")


HUGE = """[belt]
speed_m_s = 1e-300
drop_to_fence_mm = 1e300
[robot]
pick_place_s = 1e300
rotation_speed_deg_s = 1e-300
"""


def test_times_beyond_a_number_name_the_profile_and_its_fields(tmp_path, capsys) -> None:
    cell = tmp_path / "huge.toml"
    cell.write_text(HUGE, encoding="utf-8")
    err = one_line_error(
        capsys, ["plan", str(CATALOG / "t-clip.json"), "--cell", str(cell), "--tolerance", "0.2"]
    )
    assert err.startswith(f"error: {cell}: ")
    for field in ("pick_place_s", "rotation_speed_deg_s", "drop_to_fence_mm", "speed_m_s"):
        assert field in err
    with pytest.raises(CellProfileError) as exc:
        parse_cell({"belt": {"speed_m_s": 1e-300, "drop_to_fence_mm": 1e300}}, "cell.toml")
    assert exc.value.problems == (
        "belt.drop_to_fence_mm / (1000 * belt.speed_m_s) (the drift to the fence) must be "
        "at most 1e+09 seconds, got inf",
    )


def test_times_within_the_limit_are_kept(tmp_path) -> None:
    profile = parse_cell(
        {
            "robot": {"pick_place_s": 1e9, "rotation_speed_deg_s": 180e-9},
            "belt": {"speed_m_s": 1e-9, "drop_to_fence_mm": 1e3},
        },
        "cell.toml",
    )
    costs = action_costs(profile)
    assert costs.seconds(180.0) == pytest.approx(3e9)


def test_a_profile_made_in_code_is_checked_when_timed() -> None:
    profile = CellProfile(
        robot=RobotSection(pick_place_s=1.0, rotation_speed_deg_s=1e-300),
        belt=BeltSection(speed_m_s=0.1, drop_to_fence_mm=150.0),
        source="made.toml",
    )
    with pytest.raises(CellProfileError, match=r"^made\.toml: 180 / robot\.rotation_speed"):
        action_costs(profile)


def test_a_belt_beyond_any_speed_still_warns() -> None:
    profile = CellProfile(belt=BeltSection(speed_m_s=1e300), source="fast.toml")
    warning = resolve_settings(profile).belt_warning()
    assert warning is not None and "1e+300 m/s (fast.toml)" in warning


# --- --mix shares whose sum or ratio leaves a number ---------------------------------------


def test_shares_whose_sum_overflows_name_mix_and_the_shares() -> None:
    with pytest.raises(InputError) as exc:
        parse_mix_shares("l-bracket:1e308,t-clip:1e308")
    assert str(exc.value).startswith(
        "--mix: the shares l-bracket:1e+308, t-clip:1e+308 add up to more than a number"
    )
    with pytest.raises(InputError, match=r"^--mix: the shares l-bracket:1e\+308, t-clip"):
        parse_mix_shares("l-bracket:1e308,t-clip:1e308,octagon")


def test_a_share_lost_beside_the_others_is_named() -> None:
    with pytest.raises(InputError, match=r"^--mix: the share of t-clip \(1e-300\) is too small"):
        parse_mix_shares("l-bracket:1.7e308,t-clip:1e-300")
    assert parse_mix_shares("l-bracket:1e300,t-clip:1e300")[1] == (0.5, 0.5)


def test_an_overflowing_mix_is_one_line_naming_mix(tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    args = ["changeover", "compile", "s9", "--mix", "l-bracket:1e308,t-clip:1e308"]
    err = one_line_error(capsys, [*args, "--tolerance", "0.2"])
    assert err.startswith("error: --mix: the shares l-bracket:1e+308, t-clip:1e+308")


# --- --landings K: the K of pose-K --------------------------------------------------------


@pytest.mark.parametrize("text", ["00", "01", "１", "٣", "+1", "pose-00"])
def test_a_short_landing_with_a_leading_zero_or_a_wide_digit_is_refused(text) -> None:
    with pytest.raises(InputError, match=rf"^--landings: invalid landing '{re.escape(text)}'"):
        landing_names(text)


def test_a_short_landing_is_pose_k() -> None:
    assert landing_names("0, 1,12,up") == ("pose-0", "pose-1", "pose-12", "up")


def test_a_damaged_part_leaves_the_changeover_listing_whole(db, capsys) -> None:
    # One changeover's part damaged: the listing still shows every changeover and says which
    # part the catalog cannot read (it stopped at the first with that part's line).
    args = ["--tolerance", "0.2", "--catalog", str(db)]
    assert main(["changeover", "compile", "one", "--mix", "l-bracket", *args]) == 0
    _edit(db, "UPDATE revisions SET hull_json = '[[0, 0], [10, 0]]'")
    capsys.readouterr()
    assert main(["changeover", "list", "--catalog", str(db)]) == 0
    out = capsys.readouterr()
    assert "one" in out.out and "l-bracket: catalog part l-bracket@1" in out.err


def test_an_led_noise_of_a_thousand_pitches_in_a_profile_names_the_profile(tmp_path, capsys):
    # It was refused as "--noise ... (--led-pitch)", flags the user never gave; a message the
    # flags' words were added to also built a CellProfileError wrongly (exit 70).
    cell = tmp_path / "noisy.toml"
    cell.write_text('[sensor]\nmodel = "led"\npitch_mm = 0.05\nnoise_mm = 100\n', encoding="utf-8")
    err = one_line_error(capsys, ["plan", str(CATALOG / "t-clip.json"), "--cell", str(cell)])
    assert err.startswith(f"error: {cell}: sensor.noise_mm must be at most 1000 times")
    assert "--noise" not in err and "--led-pitch" not in err
