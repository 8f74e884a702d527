"""``feederkit run``: execution on the kinematic model, bad input, corrupted plans."""

from __future__ import annotations

import json
import re

import pytest
from shared import one_line_error

from feederkit.cli.app import main

TRI = [[0, 0], [1, 0], [0, 1]]


@pytest.fixture()
def tri(tmp_path, capsys):
    src = tmp_path / "tri.json"
    src.write_text(json.dumps({"name": "tri", "vertices": TRI}))
    plan = tmp_path / "tri.plan.json"
    assert main(["plan", str(src), "--tolerance", "0.01", "-o", str(plan)]) == 0
    capsys.readouterr()
    return str(src), plan


def test_single_run_prints_steps_and_pose(tri, capsys):
    src, plan = tri
    assert main(["run", str(plan), src, "--start-deg", "200"]) == 0
    out = capsys.readouterr().out
    assert "align" in out and "oriented in 2 operations" in out
    # the pose is the one of the state the plan's result names (which one: the planner's choice)
    assert re.search(r"state (\d) \(edge \1\), pose (0|90|225) deg", out)


def test_single_run_json(tri, capsys):
    src, plan = tri
    assert main(["run", str(plan), src, "--start-deg", "45", "--json"]) == 0
    (trace,) = json.loads(capsys.readouterr().out)["runs"]
    assert trace["success"] and trace["operations"] == 1
    assert trace["steps"][0]["action_deg"] is None and trace["final_pose_deg"] == 225.0


def test_all_json(tri, capsys):
    src, plan = tri
    assert main(["run", str(plan), src, "--all", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["ok"] and report["parts"][0]["starts"] == 3  # one per stable state
    assert report["warnings"] == []


def _corrupt(plan_path, edit):
    data = json.loads(plan_path.read_text())
    edit(data)
    plan_path.write_text(json.dumps(data))


def test_corrupted_action_fails_all(tri, capsys):
    src, plan = tri
    _corrupt(plan, lambda d: d["root"]["branches"][1]["next"].update(action_deg=0.0))
    err = one_line_error(capsys, ["run", str(plan), src, "--all"], code=1)
    assert "the plan failed" in err


def test_a_failed_strong_check_shows_no_table_of_zero_counts(tri, capsys):
    src, plan = tri  # a strong plan (rotation error 1 degree by default)
    _corrupt(plan, lambda d: d["root"]["branches"][1]["next"].update(action_deg=0.0))
    assert main(["run", str(plan), src, "--all"]) == 1
    out = capsys.readouterr().out
    assert "starts" not in out and "declared uncertainty" in out
    assert main(["run", str(plan), src, "--all", "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert not report["ok"] and report["parts"] == [] and report["problems"]


def test_corrupted_interval_stops_the_run(tri, capsys):
    src, plan = tri
    _corrupt(plan, lambda d: d["root"]["branches"][0].update(reading=[0.8, 0.9]))
    err = one_line_error(capsys, ["run", str(plan), src, "--start-deg", "45"], code=1)
    assert "no branch" in err


@pytest.mark.parametrize(
    "content, message",
    [
        ("{broken", "not valid JSON"),
        ('{"format": "something-else"}', "not a feederkit plan"),
        ('{"format": "feederkit-plan", "version": 1}', "conventions"),
        ("[1, 2]", "not a feederkit plan"),
    ],
)
def test_bad_plan_files(tmp_path, capsys, tri, content, message):
    src, _ = tri
    bad = tmp_path / "bad.json"
    bad.write_text(content)
    assert message in one_line_error(capsys, ["run", str(bad), src])


def test_missing_plan(tmp_path, capsys, tri):
    src, _ = tri
    assert "no such plan file" in one_line_error(capsys, ["run", str(tmp_path / "x.json"), src])


def test_unknown_part(tmp_path, capsys, tri):
    _, plan = tri
    other = tmp_path / "sq.json"
    other.write_text(json.dumps({"name": "square", "vertices": [[0, 0], [1, 0], [1, 1], [0, 1]]}))
    assert "not one of the plan's parts" in one_line_error(capsys, ["run", str(plan), str(other)])
    moved = tmp_path / "tri2.json"
    moved.write_text(json.dumps({"name": "tri", "vertices": TRI, "com": [0.3, 0.3]}))
    assert "differs from the plan's part" in one_line_error(capsys, ["run", str(plan), str(moved)])
    assert "no such file" in one_line_error(capsys, ["run", str(plan), str(tmp_path / "none.json")])


def test_start_and_all_exclusive(tri, capsys):
    src, plan = tri
    one_line_error(capsys, ["run", str(plan), src, "--all", "--start-deg", "3"])
    one_line_error(capsys, ["run", str(plan), src, "--start-deg", "nan"])


def test_run_without_source_runs_every_part_of_the_plan(tri, capsys):
    _, plan = tri
    assert main(["run", str(plan), "--start-deg", "200", "--json"]) == 0
    (trace,) = json.loads(capsys.readouterr().out)["runs"]
    assert trace["part"] == "tri" and trace["success"]
    assert main(["run", str(plan), "--all"]) == 0


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda d: d.update(version=1.0), "version"),
        (lambda d: d.update(version=True), "version"),
        (lambda d: d["stats"].update(length=d["stats"]["length"] + 1), "stats length"),
        (lambda d: d["root"]["branches"][1]["next"].pop("margin_deg"), "margin_deg"),
    ],
)
def test_structurally_wrong_plans_exit_2_even_for_one_part(tri, capsys, edit, words):
    src, plan = tri
    _corrupt(plan, edit)
    assert words in one_line_error(capsys, ["run", str(plan), src, "--all"])


def test_a_wrong_plan_fails_a_single_run_too(tri, capsys):
    src, plan = tri
    state = lambda d: d["parts"][0]["stable_states"][0]  # noqa: E731
    _corrupt(plan, lambda d: state(d).update(diameter=state(d)["diameter"] + 0.05))
    err = one_line_error(capsys, ["run", str(plan), "--start-deg", "200"], code=1)
    assert "failed verification" in err and "diameter" in err


def test_a_small_margin_is_warned_about(tri, capsys):
    src, plan = tri

    def shrink(d):
        # A strong plan holds its declared rotation error plus its margin: 0.2 + 0.5 < 1.
        d["uncertainty"]["rotation_error_deg"] = 0.2
        d["root"]["branches"][1]["next"]["margin_deg"] = 0.5
        d["stats"]["min_margin_deg"] = 0.5

    _corrupt(plan, shrink)
    assert main(["run", str(plan), "--start-deg", "200"]) == 0
    assert "below" in capsys.readouterr().err  # warnings on stderr (docs/cli.md)
    assert main(["run", str(plan), "--start-deg", "200", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["warnings"]


def test_run_repeats_the_fragile_states_plan_warned_about(tmp_path, capsys):
    """The l-bracket has a fragile state: ``run`` says it as ``plan`` did, one line for the
    part naming each landing's own state (its two landings are mirror images, as fragile,
    but number their states differently)."""
    from pathlib import Path

    src = Path(__file__).resolve().parents[1] / "catalog" / "l-bracket.json"
    plan = tmp_path / "lb.plan.json"
    assert main(["plan", str(src), "--tolerance", "0.1", "-o", str(plan)]) == 0
    planned = [ln for ln in capsys.readouterr().err.splitlines() if "fragile" in ln]
    assert len(planned) == 1 and planned[0].startswith(
        "warning: l-bracket (up): fragile states 1; l-bracket (down): fragile states 3 ("
    )
    assert main(["run", str(plan), "--all", "--json"]) == 0
    (warning,) = json.loads(capsys.readouterr().out)["warnings"]
    assert "warning: " + warning == planned[0]
    assert main(["run", str(plan), "--all"]) == 0
    assert "fragile states" in capsys.readouterr().err  # warnings on stderr (docs/cli.md)


def test_a_plan_file_over_the_size_limit_is_refused(tri, capsys):
    _, plan = tri
    err = one_line_error(capsys, ["run", str(plan), "--max-plan-mb", "0.0001"])
    assert "more than the limit" in err and "--max-plan-mb" in err


def test_a_source_names_every_landing_of_its_part(tmp_path, capsys):
    """``run PLAN SOURCE --all`` on a plan over both landings checks both, not only the
    landing whose outline the file draws (docs/plans.md: every member is run)."""
    from pathlib import Path

    src = str(Path(__file__).resolve().parents[1] / "catalog" / "l-bracket.json")
    plan = tmp_path / "lb.plan.json"
    assert main(["plan", src, "--tolerance", "0.2", "-o", str(plan)]) == 0
    capsys.readouterr()
    assert main(["run", str(plan), src, "--all", "--json"]) == 0
    parts = json.loads(capsys.readouterr().out)["parts"]
    assert sorted(p["landing"] for p in parts) == ["down", "up"]
    assert main(["run", str(plan), "--all", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["parts"] == parts
    copy = tmp_path / "bracket-copy.json"  # the same outline under another name
    copy.write_text(Path(src).read_text().replace('"l-bracket"', '"bracket-copy"'))
    assert main(["run", str(plan), str(copy), "--all", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["parts"] == parts


def test_a_clockwise_hull_in_a_plan_file_is_bad_input(tri, tmp_path, capsys):
    """design.md fixes the hull counter-clockwise; a hand-edited file reversed it and still
    passed ``run --all``."""
    _src, plan = tri
    data = json.loads(plan.read_text())
    data["parts"][0]["hull"] = data["parts"][0]["hull"][::-1]
    bad = tmp_path / "reversed.plan.json"
    bad.write_text(json.dumps(data))
    assert main(["run", str(bad), "--all"]) == 2
    err = capsys.readouterr().err
    assert "hull is not counter-clockwise" in err and len(err.strip().splitlines()) == 1


def test_a_plan_of_the_down_landing_runs_with_its_source(tmp_path, capsys):
    """The source's outline is the up landing; the plan holds only the down one (mirrored):
    it is still the plan's part."""
    from pathlib import Path

    src = str(Path(__file__).resolve().parents[1] / "catalog" / "l-bracket.json")
    plan = tmp_path / "down.plan.json"
    assert main(["plan", src, "--tolerance", "0.2", "--landings", "down", "-o", str(plan)]) == 0
    capsys.readouterr()
    assert main(["run", str(plan), src, "--all", "--json"]) == 0
    parts = json.loads(capsys.readouterr().out)["parts"]
    assert [p["landing"] for p in parts] == ["down"]
