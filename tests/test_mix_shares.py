"""Mix shares (``--mix A:0.7,B:0.2,C:0.1``): parsed and checked in one line, stored with the
changeover, and weighting every expected figure and the expected objectives.

The weighted figures are checked by an evaluator written here: a plan tree's expected
operations per part, from the machine's action maps and the sensor's reading model.
"""

from __future__ import annotations

import json
import math
import re
import shutil
from pathlib import Path

import pytest
from shared import one_line_error

from feederkit.cli.app import main
from feederkit.cli.changeover import parse_mix, parse_mix_shares
from feederkit.errors import InputError
from feederkit.machine import members
from feederkit.mechanics import push_function
from feederkit.planning.options import PlanningOptions
from feederkit.planning.tree import Leaf
from feederkit.plans.make import make_plan
from feederkit.plans.model import PlanMember
from feederkit.sensors import ToleranceSensor
from feederkit.sources import load_part
from feederkit.uncertainty import IDEAL, Uncertainty

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
MIX = ("quadrilateral", "rectangle-2x1", "l-bracket")
SHARES = (0.7, 0.2, 0.1)


def test_shares_are_normalised_and_default_to_equal():
    assert parse_mix_shares("a,b@2,c") == (["a", "b@2", "c"], None)
    names, shares = parse_mix_shares("a:7, b:2 ,c:1")
    assert names == ["a", "b", "c"]
    assert shares == pytest.approx((0.7, 0.2, 0.1), abs=1e-15)
    # Parts without a share split what the given ones leave.
    assert parse_mix_shares("a:0.5,b,c")[1] == pytest.approx((0.5, 0.25, 0.25))
    assert parse_mix("a:0.5,b") == ["a", "b"]


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("a:-0.2,b", "share of a must be a finite positive number, got '-0.2'"),
        ("a:0,b:0", "share of a must be a finite positive number, got '0' (leave a part out"),
        ("a:nan,b", "share of a must be a finite positive number, got 'nan'"),
        ("a:inf,b", "share of a must be a finite positive number, got 'inf'"),
        ("a:lots,b", "share of a must be a number, got 'lots'"),
        ("a:0.5,a:0.5", "a is listed twice"),
        (":0.5,b", "names no part"),
        ("a:0.7,b:0.6,c", "add up to 1.3, leaving nothing for c"),
        ("a,,b", "comma-separated list"),
    ],
)
def test_bad_shares_are_one_line(text, needle):
    with pytest.raises(InputError, match=re.escape(needle)):
        parse_mix_shares(text)


def pfs(*names: str):
    return [push_function(load_part(str(CATALOG / f"{n}.json"))) for n in names]


def part_expectations(machine, root) -> list[float]:
    """Per part: the expected operations of a part of that kind (its states weighted by
    their resting ranges)."""

    def walk(node, state: int) -> float:
        if isinstance(node, Leaf):
            return 0.0
        rot = None if node.action is None else node.action.representative
        outs = [state] if rot is None else members(machine.outcomes(state, rot))
        total = 1.0
        for t in outs:
            for b, sub in node.branches:
                if b.mask >> t & 1:
                    p = machine.sensor.reading_probability(machine.states[t].sensed, b.lo, b.hi)
                    total += p * walk(sub, t) / len(outs)
        return total

    out = []
    for p in range(len(machine.part_names)):
        states = [(i, s) for i, s in enumerate(machine.states) if s.part == p]
        mass = sum(s.weight for _, s in states)
        out.append(sum(s.weight * walk(root, i) for i, s in states) / mass)
    return out


@pytest.mark.parametrize("uncertainty", [IDEAL, Uncertainty()], ids=["ideal", "strong"])
def test_every_expected_figure_is_weighted_by_the_shares(uncertainty):
    parts = pfs(*MIX)
    named = [PlanMember(n, share=s) for n, s in zip(MIX, SHARES, strict=True)]
    sensor = ToleranceSensor(0.2)
    made = make_plan(parts, sensor, uncertainty=uncertainty, members=named, certify=False)
    per_part = part_expectations(made.result.machine, made.result.root)
    weighted = sum(s * e for s, e in zip(SHARES, per_part, strict=True))
    assert made.result.expected_length == pytest.approx(weighted, rel=1e-12)
    assert made.plan["stats"]["expected_length"] == pytest.approx(weighted, rel=1e-12)
    assert [p.get("share") for p in made.plan["parts"]] == pytest.approx(list(SHARES))
    # The expected objective minimises the weighted figure: never worse under these shares
    # than the plan made for equal shares.
    opts = PlanningOptions(objective="expected")
    best = make_plan(parts, sensor, opts, uncertainty=uncertainty, members=named, certify=False)
    equal = make_plan(parts, sensor, opts, uncertainty=uncertainty, certify=False)
    under = part_expectations(best.result.machine, best.result.root)
    equal_under = part_expectations(equal.result.machine, equal.result.root)
    mine = sum(s * e for s, e in zip(SHARES, under, strict=True))
    theirs = sum(s * e for s, e in zip(SHARES, equal_under, strict=True))
    assert mine <= theirs + 1e-9
    assert math.isclose(best.result.expected_length, mine, rel_tol=1e-12)


@pytest.fixture()
def db(tmp_path, capsys) -> Path:
    folder = tmp_path / "parts"
    folder.mkdir()
    for name in MIX:
        shutil.copy(CATALOG / f"{name}.json", folder)
    path = tmp_path / "parts.db"
    assert main(["catalog", "init", "--catalog", str(path)]) == 0
    assert main(["catalog", "import", str(folder), "--catalog", str(path)]) == 0
    capsys.readouterr()
    return path


PROFILE = """
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


def test_the_changeover_stores_its_shares_and_cycle_time(db, tmp_path, capsys):
    cell = tmp_path / "cell.toml"
    cell.write_text(PROFILE, encoding="utf-8")
    mix = ",".join(f"{n}:{s}" for n, s in zip(MIX, SHARES, strict=True))
    args = ["changeover", "compile", "week", "--mix", mix, "--cell", str(cell), "--json"]
    assert main([*args, "--catalog", str(db)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [p["share"] for p in out["parts"]] == pytest.approx(list(SHARES))
    assert out["cell"]["profile"] == str(cell)
    assert out["cell"]["rotation_error_deg"] == 0.5
    cycle = out["cycle_time"]
    assert cycle["profile"] == str(cell)
    assert cycle["parts_per_minute"] == pytest.approx(60.0 / cycle["expected_s"])
    assert main(["changeover", "show", "week", "--json", "--catalog", str(db)]) == 0
    shown = json.loads(capsys.readouterr().out)
    assert [p["share"] for p in shown["parts"]] == pytest.approx(list(SHARES))
    assert shown["cycle_time"] == pytest.approx(cycle)
    assert main(["changeover", "show", "week", "--catalog", str(db)]) == 0
    text = capsys.readouterr().out
    assert "quadrilateral@1 (70 %)" in text and "parts/min" in text


@pytest.mark.parametrize(
    "mix",
    ["quadrilateral:-1,l-bracket", "quadrilateral:0,l-bracket:0", "quadrilateral:nan,l-bracket"],
)
def test_bad_shares_on_the_command_line(db, capsys, mix):
    err = one_line_error(capsys, ["changeover", "compile", "w", "--mix", mix, "--catalog", str(db)])
    assert "--mix: the share of quadrilateral" in err


def test_a_share_for_a_part_not_in_the_catalog(db, capsys):
    args = ["changeover", "compile", "w", "--mix", "quadrilateral:0.5,nosuch:0.5"]
    err = one_line_error(capsys, [*args, "--catalog", str(db)])
    assert "nosuch" in err


def test_timed_objectives_need_the_cells_timing(db, tmp_path, capsys):
    cell = tmp_path / "sensor-only.toml"
    cell.write_text('[sensor]\nmodel = "tolerance"\ntolerance_mm = 0.2\n', encoding="utf-8")
    args = ["changeover", "compile", "w", "--mix", "quadrilateral,l-bracket", "--cell", str(cell)]
    err = one_line_error(capsys, [*args, "--objective", "time", "--catalog", str(db)])
    assert "robot.pick_place_s" in err and str(cell) in err


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("[robot]\npick_place_s = 1\nspeed = 2\n", "unknown key robot.speed"),
        ("[belt]\nspeed_m_s = -0.1\n", "belt.speed_m_s must be a finite positive"),
        ("[robot]\nrotation_speed_deg_s = inf\n", "robot.rotation_speed_deg_s must be"),
    ],
)
def test_a_bad_profile_is_one_line_before_any_planning(db, tmp_path, capsys, text, needle):
    cell = tmp_path / "bad.toml"
    cell.write_text(text, encoding="utf-8")
    args = ["changeover", "compile", "w", "--mix", "quadrilateral,l-bracket", "--cell", str(cell)]
    err = one_line_error(capsys, [*args, "--catalog", str(db)])
    assert needle in err and str(cell) in err
    assert "bad.toml" in one_line_error(capsys, ["demo", "--cell", str(cell), "-o", str(tmp_path)])
