"""``feederkit design sensor`` through ``main``: JSON, the one-line answer, exit codes."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest
from shared import one_line_error

import feederkit.cli.app as app_module
from feederkit.cli import design as design_cli
from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
MIX = [str(CATALOG / f"{n}.json") for n in ("quadrilateral", "rectangle-2x1", "l-bracket")]


@pytest.fixture(autouse=True)
def design_registered(tmp_path, monkeypatch):
    """The command on the app (until the lead lists it in COMMAND_MODULES); no stray profile."""
    group = app_module._click_command()
    if "design" not in getattr(group, "commands", {}):
        design_cli.register(app_module.app)
        app_module._click_command.cache_clear()
    monkeypatch.chdir(tmp_path)


def run_json(capsys, args, code=0):
    rc = main(args)
    captured = capsys.readouterr()
    assert rc == code, captured.err
    return json.loads(captured.out), captured.err


def test_tolerance_design_json(capsys):
    data, _ = run_json(capsys, ["design", "sensor", *MIX, "--json"])
    x = data["critical_tolerance_mm"]
    assert data["sensor_model"] == "tolerance" and x > 0
    assert data["cell_profile"] == "built-in defaults"
    # Every landing is a member of the mix, as plan plans it (design.md, "Landings").
    members = [f"{Path(m).stem}/{side}" for m in MIX for side in ("up", "down")]
    assert [(p["a"], p["b"]) for p in data["pairs"]] == [
        (a, b) for i, a in enumerate(members) for b in members[i + 1 :]
    ]
    assert x == min(p["critical_tolerance_mm"] for p in data["pairs"])
    rows = data["lengths"]
    assert rows[0]["tolerance_mm"][0] == 0.0 and rows[-1]["tolerance_mm"][1] == x
    for a, b in zip(rows, rows[1:], strict=False):
        assert a["tolerance_mm"][1] == b["tolerance_mm"][0] and a["length"] < b["length"]
    assert all(r["recognizable"] and 1.0 <= r["expected"] <= r["length"] for r in rows)
    assert data["uncertainty"] == {
        "rotation_error_deg": 1.0,
        "shape_tolerance_mm": 0.0,
        "com_tolerance_mm": 0.0,
        "applied": True,
    }
    assert data["model"].startswith("strong plans at the declared uncertainty (rotation error 1")
    assert data["answer"].endswith("(strong plans, rotation error 1 deg, shape tolerance 0 mm, "
                                   "COM tolerance 0 mm)")  # fmt: skip
    assert data["answer"].startswith(f"this mix is recognizable with a tolerance up to {x:.6g} mm")


def test_terminal_output_names_the_answer_and_the_profile(capsys):
    assert main(["design", "sensor", *MIX, "--rotation-error", "0"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "this mix is recognizable with a tolerance up to" in out
    assert "the plan takes" in out and "cell profile: built-in defaults" in out
    assert "rotation error ±0°, shape tolerance 0 mm, COM tolerance 0 mm (the ideal model)" in out


@pytest.mark.parametrize("pitches", [None, "0.5,1"])
def test_the_plot_is_written(capsys, tmp_path, pitches):
    plot = tmp_path / "steps.svg"
    extra = [] if pitches is None else ["--pitches", pitches]
    assert main(["design", "sensor", *MIX[:2], "--plot", str(plot), *extra]) == 0
    assert f"wrote {plot}" in " ".join(capsys.readouterr().out.split())
    assert plot.read_text().lstrip().startswith("<?xml") and "<svg" in plot.read_text()


def test_led_pitches_one_by_one(capsys):
    data, _ = run_json(capsys, ["design", "sensor", *MIX, "--pitches", "5,0.2,1", "--json"])
    assert [r["pitch_mm"] for r in data["pitches"]] == [0.2, 1.0, 5.0]
    ok = [r["pitch_mm"] for r in data["pitches"] if r["recognizable"]]
    assert data["critical_pitch_mm"] == max(ok)
    for r in data["pitches"]:
        assert (r["length"] is not None) == r["recognizable"] == (not r["unrecognizable"])
    assert "LED pitch of" in data["answer"]


def test_the_profile_chooses_the_led_array(capsys, tmp_path):
    cell = tmp_path / "cell.toml"
    cell.write_text('[sensor]\nmodel = "led"\npitch_mm = 0.25\nnoise_mm = 0.01\n')
    data, _ = run_json(capsys, ["design", "sensor", *MIX, "--cell", str(cell), "--json"])
    assert data["cell_profile"] == str(cell) and data["noise_mm"] == 0.01
    assert [r["pitch_mm"] for r in data["pitches"]] == [0.25]


def test_a_lookalike_pair_exits_1_naming_lemma_8(capsys, tmp_path):
    twin = tmp_path / "twin.json"
    src = MIX[0]
    assert (
        main(["lookalike", src, "--keep", "push-diameter", "--name", "twin", "-o", str(twin)]) == 0
    )
    capsys.readouterr()
    data, err = run_json(capsys, ["design", "sensor", src, str(twin), "--json"], code=1)
    assert data["critical_tolerance_mm"] is None and data["lengths"] == []
    alike = {(p["a"], p["b"]) for p in data["pairs"] if "Lemma 8" in p.get("reason", "")}
    assert alike == {("quadrilateral/up", "twin/up"), ("quadrilateral/down", "twin/down")}
    assert len(err.strip().splitlines()) == 1 and "Lemma 8" in err


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--pitches", ""], "--pitches is empty"),
        (["--pitches", " , "], "--pitches is empty"),
        (["--pitches", "0.1,,0.2"], "an empty item"),
        (["--pitches", "0.2,-1"], "positive"),
        (["--pitches", "0.2,wide"], "not a number"),
        (["--pitches", "1:0.5:0.1"], "ends before"),
        (["--noise", "0.1"], "--noise goes with"),
        (["--plot", "steps.pdf"], ".png or .svg"),
        (["--max-tolerance", "0"], "--max-tolerance"),
        (["--rotation-error", "-1"], "--rotation-error"),
    ],
)
def test_bad_options_are_one_line_exit_2(capsys, args, needle):
    assert needle in one_line_error(capsys, ["design", "sensor", *MIX, *args])


def test_bad_mixes_and_profiles_are_one_line_exit_2(capsys, tmp_path):
    err = one_line_error(capsys, ["design", "sensor", MIX[0], "--landings", "up"])
    assert "at least two parts" in err
    err = one_line_error(capsys, ["design", "sensor", *MIX, "--landings", "x"])
    assert "invalid landing" in err
    assert "SOURCE" in one_line_error(capsys, ["design", "sensor"])
    assert "not both" in one_line_error(capsys, ["design", "sensor", MIX[0], "--mix", "a,b"])
    assert "part names only" in one_line_error(capsys, ["design", "sensor", "--mix", "a:0.7,b"])
    assert "commas" in one_line_error(capsys, ["design", "sensor", "--mix", "a,,b"])
    bad = tmp_path / "bad.toml"
    bad.write_text("[robot]\npick_place_s = -1\nspeed = 3\n")
    err = one_line_error(capsys, ["design", "sensor", *MIX, "--cell", str(bad)])
    assert "robot.pick_place_s" in err and "unknown key robot.speed" in err
    err = one_line_error(capsys, ["design", "sensor", *MIX, "--cell", str(tmp_path / "no.toml")])
    assert "no such cell profile" in err


def test_a_shorter_table_says_where_it_stops(capsys):
    data, _ = run_json(capsys, ["design", "sensor", *MIX, "--max-tolerance", "0.1", "--json"])
    top = data["lengths"][-1]["tolerance_mm"][1]
    assert 0.1 <= top < data["critical_tolerance_mm"]
    assert f"tabulated up to {top:.6g} mm only" in data["answer"]


def mirrored(src: str, out: Path) -> Path:
    """The outline of ``src`` mirrored in the y axis: its face-down landing, named anew."""
    data = json.loads(Path(src).read_text())
    data["name"] = out.stem
    data["vertices"] = [[-x, y] for x, y in data["vertices"]][::-1]
    data["holes"] = [[[-x, y] for x, y in h][::-1] for h in data.get("holes", [])]
    out.write_text(json.dumps(data))
    return out


def test_the_design_covers_every_landing_as_plan_does(capsys, tmp_path):
    """A part and its mirror image read alike face up against face down: no sensor tells
    them apart, as ``plan`` says; face up only (``--landings up``) one does."""
    bracket = str(CATALOG / "l-bracket.json")
    mirror = str(mirrored(bracket, tmp_path / "l-bracket-mirror.json"))
    data, err = run_json(capsys, ["design", "sensor", bracket, mirror, "--json"], code=1)
    alike = {(p["a"], p["b"]) for p in data["pairs"] if "Lemma 8" in p.get("reason", "")}
    assert alike == {
        ("l-bracket/up", "l-bracket-mirror/down"),
        ("l-bracket/down", "l-bracket-mirror/up"),
    }
    assert "no tolerance makes this mix recognizable" in err
    assert main(["plan", bracket, mirror, "--tolerance", "0.2", "--time-limit", "20"]) == 1
    capsys.readouterr()
    up, _ = run_json(capsys, ["design", "sensor", bracket, mirror, "--landings", "up", "--json"])
    assert up["critical_tolerance_mm"] > 0


def test_the_length_table_is_the_plans_length(capsys):
    """The design's length at a tolerance is the length ``plan`` finds there."""
    data, _ = run_json(capsys, ["design", "sensor", *MIX, "--json"])
    for row in data["lengths"]:
        lo, hi = row["tolerance_mm"]
        plan, _ = run_json(capsys, ["plan", *MIX, "--tolerance", f"{(lo + hi) / 2:.6g}", "--json"])
        assert plan["stats"]["length"] == row["length"], row


def test_the_printed_critical_tolerance_is_one_the_plan_accepts(capsys) -> None:
    """The line's tolerance is rounded down, so copying it into ``plan --tolerance`` works
    (6.0274085 printed as 6.02741 was past the limit: the plan then could not tell two
    landings apart)."""
    parts = [str(CATALOG / f"{n}.json") for n in ("l-bracket", "t-clip", "d-washer")]
    assert main(["design", "sensor", "--mix", ",".join(parts), "--json"]) == 0
    exact = json.loads(capsys.readouterr().out)["critical_tolerance_mm"]
    assert main(["design", "sensor", "--mix", ",".join(parts)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    printed = out.split("recognizable with a tolerance up to ")[1].split(" mm")[0]
    assert float(printed) <= exact and float(printed) == pytest.approx(exact, rel=1e-5)
    assert main(["plan", *parts, "--tolerance", printed]) == 0


def test_the_length_table_prints_each_breakpoint_once(capsys) -> None:
    """A step's lower end is the step before's upper end, printed alike (both rounded
    down), so the rows do not seem to leave a gap."""
    parts = [str(CATALOG / f"{n}.json") for n in ("rectangle-2x1", "equilateral-triangle")]
    assert main(["design", "sensor", "--mix", ",".join(parts), "--landings", "up"]) == 0
    out = capsys.readouterr().out
    rows = [
        line.split("(")[1].split("]")[0]
        for line in out.splitlines()
        if "] " in line and "(" in line and "," in line.split("]")[0]
    ]
    ends = [tuple(part.strip() for part in row.split(",")) for row in rows]
    assert len(ends) >= 2
    for (_lo, hi), (lo, _hi) in zip(ends, ends[1:], strict=False):
        assert lo == hi


def test_a_name_the_font_cannot_draw_is_drawn_escaped_without_warnings(capsys, tmp_path):
    """A part named in CJK: matplotlib printed raw "Glyph ... missing" warnings on stderr and
    drew empty boxes in the title; the title holds the name escaped, as the part plots do."""
    from feederkit.outline import load_outline_json, save_outline_json

    named = tmp_path / "日本語.json"
    outline = load_outline_json(CATALOG / "quadrilateral.json")
    save_outline_json(outline.__class__(**{**outline.__dict__, "name": "日本語"}), named)
    plot = tmp_path / "steps.svg"
    args = ["design", "sensor", str(named), MIX[1], "--plot", str(plot), "--rotation-error", "0"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(args) == 0
    assert not [w for w in caught if "Glyph" in str(w.message)]
    assert "Glyph" not in capsys.readouterr().err
