"""``feederkit plan``: verified plans written atomically, exit codes, and ``run --all`` on them."""

from __future__ import annotations

import json
import math
import random
from pathlib import Path

import pytest
from shared import one_line_error

from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
RECT = [[-1, -0.5], [1, -0.5], [1, 0.5], [-1, 0.5]]
TRI = [[0, 0], [1, 0], [0, 1]]


def outline(tmp_path, name, vertices, com=None):
    data = {"name": name, "units": "mm", "vertices": vertices}
    if com is not None:
        data["com"] = com
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(data))
    return str(path)


def random_convex(seed, n=9, radius=20.0):
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0, 2 * math.pi) for _ in range(n))
    return [
        [radius * rng.uniform(0.6, 1.0) * math.cos(a), radius * rng.uniform(0.6, 1.0) * math.sin(a)]
        for a in angles
    ]


def plan_file(tmp_path, capsys, args, name="plan.json", code=0):
    out = tmp_path / name
    rc = main(["plan", *args, "-o", str(out)])
    captured = capsys.readouterr()
    assert rc == code, captured.err
    return json.loads(out.read_text()), captured


def run_all(plan_path, sources, capsys):
    rc = main(["run", str(plan_path), *sources, "--all"])
    captured = capsys.readouterr()
    assert rc == 0, captured.err
    assert "paths end in their result" in captured.out


def test_centred_rectangle_sensorless(tmp_path, capsys):
    src = outline(tmp_path, "rect", RECT)
    plan, cap = plan_file(tmp_path, capsys, [src])
    assert "no sensor option given" in cap.out and "sensorless" in cap.out
    assert plan["sensor"] == {"model": "none"}
    assert plan["stats"]["length"] == 2 and plan["stats"]["optimal"]
    leaves = []
    stack = [plan["root"]]
    while stack:
        node = stack.pop()
        if "result" in node:
            leaves.append(node["result"])
        else:
            assert all(b["reading"] is None for b in node["branches"])
            stack.extend(b["next"] for b in node["branches"])
    (result,) = leaves
    poses = sorted(e["pose_deg"] for e in result)
    assert len(poses) == 2 and poses[1] - poses[0] == pytest.approx(180.0)
    run_all(tmp_path / "plan.json", [src], capsys)


def test_right_triangle_tolerance_and_sensorless(tmp_path, capsys):
    src = outline(tmp_path, "tri", TRI)
    plan, cap = plan_file(tmp_path, capsys, [src, "--tolerance", "0.01"])
    assert plan["stats"]["length"] == 2
    assert plan["stats"]["class"] == 2 and plan["stats"]["meets_bound"] is True
    assert "op 2: rotate" in cap.out and "statistics" in cap.out and "passed" in cap.out
    run_all(tmp_path / "plan.json", [src], capsys)
    plan, _ = plan_file(tmp_path, capsys, [src, "--sensorless"], name="sl.json")
    # 3 on the ideal model; 4 with the slender part's 8-degree push bands (docs/uncertainty.md)
    assert plan["stats"]["length"] == 4
    run_all(tmp_path / "sl.json", [src], capsys)


def test_random_convex_part_led(tmp_path, capsys):
    src = outline(tmp_path, "rnd", random_convex(7))
    # ``run --all`` executes the ideal model: plan on it (strong plans: tests/test_strong_*.py).
    args = [src, "--led-pitch", "1.0", "--noise", "0.2", "--rotation-error", "0"]
    # Exit 1: its fragile states merge on a feeder that vibrates, where the ideal plan holds
    # no rotation error (the plan is still written, and run --all checks the ideal model).
    plan, _ = plan_file(tmp_path, capsys, args, code=1)
    assert plan["sensor"] == {"model": "led", "pitch_mm": 1.0, "noise_mm": 0.2}
    # A chiral part: the plan covers both sides (docs/landings.md), a mix of two landings.
    assert [(p["name"], p["landing"]) for p in plan["parts"]] == [("rnd", "up"), ("rnd", "down")]
    assert plan["stats"]["class"] is None
    run_all(tmp_path / "plan.json", [src], capsys)
    plan, _ = plan_file(tmp_path, capsys, [*args, "--landings", "up"], name="up.json")
    assert plan["stats"]["meets_bound"] is True
    run_all(tmp_path / "up.json", [src], capsys)


def test_two_part_mix(tmp_path, capsys):
    octagon = [[math.cos(k * math.pi / 4), math.sin(k * math.pi / 4)] for k in range(8)]
    a = outline(tmp_path, "tri", TRI)
    b = outline(tmp_path, "octagon", octagon, com=[0.13, 0.05])
    # On the ideal model (at 1 deg no strong plan orients the octagon's two sides, whose COM
    # is only 0.14 of the radius off centre); its sides read alike in every state, so the
    # plan lists both and exits 1.
    args = [a, b, "--tolerance", "0.01", "--rotation-error", "0"]
    plan, cap = plan_file(tmp_path, capsys, args, code=1)
    assert "recognizes octagon but not which side is up: octagon/up & octagon/down" in cap.err
    # The right triangle is mirror-symmetric (one landing), the off-centre octagon is not.
    assert [(p["name"], p["landing"]) for p in plan["parts"]] == [
        ("tri", "up"),
        ("octagon", "up"),
        ("octagon", "down"),
    ]
    assert plan["stats"]["class"] is None
    run_all(tmp_path / "plan.json", [a, b], capsys)
    run_all(tmp_path / "plan.json", [b], capsys)


def test_unrecognizable_pair_writes_the_plan_and_exits_1(tmp_path, capsys):
    a = outline(tmp_path, "tri", TRI)
    b = outline(tmp_path, "tri-copy", TRI)
    plan, cap = plan_file(tmp_path, capsys, [a, b, "--tolerance", "0.01"], code=1)
    assert "tri & tri-copy" in cap.err and len(cap.err.strip().splitlines()) == 1
    assert any(len({e["part"] for e in leaf}) == 2 for leaf in _results(plan))
    run_all(tmp_path / "plan.json", [a, b], capsys)


def _results(plan):
    stack, out = [plan["root"]], []
    while stack:
        node = stack.pop()
        if "result" in node:
            out.append(node["result"])
        else:
            stack.extend(b["next"] for b in node["branches"])
    return out


def test_json_output_is_the_plan_file(tmp_path, capsys):
    src = outline(tmp_path, "tri", TRI)
    out = tmp_path / "p.json"
    assert main(["plan", src, "--tolerance", "0.01", "--json", "-o", str(out)]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == json.loads(out.read_text())
    assert printed["format"] == "feederkit-plan"


def test_report_is_written(tmp_path, capsys):
    src = outline(tmp_path, "tri", TRI)
    html = tmp_path / "r.html"
    assert main(["plan", src, "--tolerance", "0.01", "--report", str(html)]) == 0
    assert html.read_text().startswith("<!DOCTYPE html>")


@pytest.mark.parametrize("sensor", [["--tolerance", "0.3"], ["--led-pitch", "0.5"]])
def test_component_branching_takes_diameter_intervals(tmp_path, capsys, sensor):
    # The d-washer's arc states have diameter intervals (its model error): the paper's
    # component branching sorts them with the plain diameters (it raised TypeError).
    src = str(CATALOG / "d-washer.json")
    plan, _ = plan_file(tmp_path, capsys, [src, *sensor, "--grouping", "components"])
    assert plan["stats"]["grouping"] == "components"
    run_all(tmp_path / "plan.json", [src], capsys)


def test_options_reach_the_plan(tmp_path, capsys):
    src = outline(tmp_path, "tri", TRI)
    plan, _ = plan_file(
        tmp_path,
        capsys,
        [src, "--tolerance", "0.01", "--objective", "expected", "--grouping", "components"],
    )
    assert plan["stats"]["objective"] == "expected" and plan["stats"]["grouping"] == "components"
    plan, _ = plan_file(tmp_path, capsys, [src, "--sensorless", "--min-margin", "4"], name="m.json")
    assert plan["stats"]["min_margin_deg"] >= 4


@pytest.mark.parametrize(
    "extra",
    [
        ["--tolerance", "0"],
        ["--tolerance", "-1"],
        ["--noise", "0.1"],
        ["--led-pitch", "0"],
        ["--tolerance", "0.1", "--led-pitch", "1"],
        ["--objective", "best"],
        ["--grouping", "cliques"],
        ["--min-margin", "-1"],
        ["--time-limit", "0"],
    ],
)
def test_impossible_settings(tmp_path, capsys, extra):
    src = outline(tmp_path, "tri", TRI)
    one_line_error(capsys, ["plan", src, *extra, "-o", str(tmp_path / "p.json")])
    assert not (tmp_path / "p.json").exists()


def test_bad_sources(tmp_path, capsys):
    err = one_line_error(capsys, ["plan", str(tmp_path / "nope.json")])
    assert "nope.json" in err
    src = outline(tmp_path, "tri", TRI)
    one_line_error(capsys, ["plan", src, src])


def test_disk_is_refused(tmp_path, capsys):
    disk = [
        [10 * math.cos(k * math.pi / 180), 10 * math.sin(k * math.pi / 180)] for k in range(360)
    ]
    src = outline(tmp_path, "disk", disk)
    err = one_line_error(capsys, ["plan", src, "-o", str(tmp_path / "p.json")])
    assert "not orientable" in err
    assert not (tmp_path / "p.json").exists()


def test_unwritable_output(tmp_path, capsys):
    src = outline(tmp_path, "tri", TRI)
    one_line_error(capsys, ["plan", src, "-o", str(tmp_path / "no" / "such" / "dir.json")])


def test_catalog_names(tmp_path, capsys):
    db = str(tmp_path / "parts.db")
    src = outline(tmp_path, "tri", TRI)
    assert main(["catalog", "init", "--catalog", db]) == 0
    assert main(["catalog", "add", src, "--catalog", db]) == 0
    capsys.readouterr()
    plan, _ = plan_file(tmp_path, capsys, ["tri", "--catalog", db, "--tolerance", "0.01"])
    assert plan["parts"][0]["revision"] == "1"
    rc = main(["run", str(tmp_path / "plan.json"), "tri", "--catalog", db, "--all"])
    assert rc == 0, capsys.readouterr().err
    one_line_error(capsys, ["plan", "no-such-part", "--catalog", db])


def test_plan_and_report_are_written_both_or_neither(tmp_path, capsys, monkeypatch):
    import feederkit.cli.common

    # The report's content does not matter here (test_report_is_written draws a real one).
    monkeypatch.setattr(feederkit.cli.common, "report_html", lambda *a: "<!DOCTYPE html>")
    src = outline(tmp_path, "tri", TRI)
    plan_path = tmp_path / "p.json"
    bad_report = tmp_path / "missing" / "r.html"
    args = ["plan", src, "--tolerance", "0.01", "-o", str(plan_path), "--report", str(bad_report)]
    assert "r.html" in one_line_error(capsys, args)
    assert not plan_path.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["tri.json"]  # no temporaries either


@pytest.mark.parametrize(
    ("extra", "flag", "words"),
    [
        (["--min-margin", "180"], "--min-margin", "minimum margin"),
        (["--time-limit", "-3"], "--time-limit", "time limit"),
        (["--objective", "fastest"], "--objective", "objective"),
    ],
)
def test_options_are_checked_once_by_the_library_and_named_by_flag(
    tmp_path, capsys, extra, flag, words
):
    src = outline(tmp_path, "tri", TRI)
    err = one_line_error(capsys, ["plan", src, *extra])
    assert flag in err and words in err


def test_the_default_time_limit_reaches_the_planner(tmp_path, capsys, monkeypatch):
    import feederkit.cli.plan as cli_plan
    from feederkit.cli.common import DEFAULT_TIME_LIMIT_S

    seen = []
    real = cli_plan.plan_mix

    def spy(pfs, sensor, options, **kw):
        seen.append(options)
        return real(pfs, sensor, options, **kw)

    monkeypatch.setattr(cli_plan, "plan_mix", spy)
    src = outline(tmp_path, "tri", TRI)
    plan_file(tmp_path, capsys, [src, "--tolerance", "0.01"])
    plan_file(tmp_path, capsys, [src, "--tolerance", "0.01", "--time-limit", "7"], name="b.json")
    assert [o.time_limit_s for o in seen] == [DEFAULT_TIME_LIMIT_S, 7.0]
    assert 10.0 <= DEFAULT_TIME_LIMIT_S <= 600.0  # sensible: a minute or so


def test_a_margin_below_one_degree_is_warned_about(tmp_path, capsys):
    # On the ideal model the t-clip's shortest sensorless plan turns within ±0.044° of an
    # action range's end; at the default rotation error of 1° the strong plan needs no warning.
    ideal = [str(CATALOG / "t-clip.json"), "--sensorless", "--rotation-error", "0"]
    plan, cap = plan_file(tmp_path, capsys, ideal, code=1)  # holds nothing on the belt
    assert plan["stats"]["min_margin_deg"] < 1.0
    assert "no robot holds ±0.044°" in cap.err
    _, cap = plan_file(tmp_path, capsys, [str(CATALOG / "t-clip.json"), "--tolerance", "0.3"])
    assert "no robot holds" not in cap.err
    plan, cap = plan_file(tmp_path, capsys, [str(CATALOG / "t-clip.json"), "--sensorless"])
    assert plan["uncertainty"]["rotation_error_deg"] == 1.0
    assert "no robot holds" not in cap.err


def test_a_sensor_that_reads_every_state_alike_is_warned_about(tmp_path, capsys):
    src = outline(tmp_path, "tri", TRI)
    plan, cap = plan_file(tmp_path, capsys, [src, "--tolerance", "5"])
    assert "every state reads alike" in cap.err
    assert plan["stats"]["length"] == 4  # as long as the sensorless plan


def test_no_plan_within_the_time_limit_names_the_flag(tmp_path, capsys):
    def regular(n):
        pts = [[math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)] for k in range(n)]
        return outline(tmp_path, f"regular-{n}", pts, com=[0.13, 0.05])

    args = ["plan", regular(12), regular(11), "--sensorless", "--time-limit", "0.0001"]
    err = one_line_error(capsys, args, code=1)
    assert "time limit of 0.0001 s" in err and "--time-limit" in err
    # what it proved: a lower bound, or the stage it ran out in (the goal relation comes first)
    assert "at least" in err or "inseparable" in err


def test_the_time_limit_note_names_the_lower_bound():
    from feederkit.cli.common import time_limit_note

    stats = {"length": 5, "lower_bound": 3, "optimal": False}
    note = time_limit_note(stats, 60.0)
    assert "60 s" in note and "at least 3" in note and "--time-limit" in note
    assert time_limit_note({**stats, "optimal": True}, 60.0) is None
