"""Plans over landings in the plan file (design.md, "Landings" and plan file version 2): parts
with ``landing`` and ``share``, results naming the landing, ``"reject": true`` results; what
the reader refuses, what verification (ideal and strong) checks, what ``run`` prints.

The plans are made here from the planner and :func:`plan_from_result` with
:class:`PlanMember` values (one right triangle lying face up and face down, the down side
rejected), so the file side is tested without the landing planners.
"""

from __future__ import annotations

import copy
import json
import math

import pytest
from shared import made_as_drawn, one_line_error

from feederkit.cli.app import main
from feederkit.errors import CheckFailed, InputError
from feederkit.machine.build import build_machine
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan as plan_machine
from feederkit.plans import execute, plan_from_dict, plan_json, plan_to_dict, read_plan
from feederkit.plans.fileformat import plan_from_result
from feederkit.plans.model import PlanMember
from feederkit.plans.strong import ideal_view, verify_strong
from feederkit.plans.verify import verify_declared, verify_plan
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

UP = [(0.0, 0.0), (4.0, 0.0), (0.0, 3.0)]
DOWN = [(-x, y) for x, y in UP]  # mirrored about the part frame's y axis
SENSOR = ToleranceSensor(0.1)
MEMBERS = (PlanMember("tri", "up", 0.5), PlanMember("tri", "down", 0.5, accept=False))


def _pfs():
    return [
        push_function(make_part(make_outline(f"tri/{side}", pts)))
        for side, pts in (("up", UP), ("down", DOWN))
    ]


@pytest.fixture(scope="module")
def landing_plan() -> dict:
    """The ideal plan over both landings of the triangle, the down side rejected."""
    pfs = _pfs()
    result = plan_machine(build_machine(pfs, SENSOR, IDEAL))
    return plan_to_dict(plan_from_result(result, pfs, members=MEMBERS, uncertainty=IDEAL))


@pytest.fixture(scope="module")
def strong_landing_plan() -> dict:
    """The same at design.md's default uncertainty (a strong plan, over the ideal states)."""
    pfs = _pfs()
    unc = Uncertainty()
    result = plan_machine(build_machine(pfs, SENSOR, unc))
    ideal = ideal_view(result, build_machine(pfs, SENSOR, IDEAL))
    return plan_to_dict(plan_from_result(ideal, pfs, members=MEMBERS, uncertainty=unc))


def _leaves(d: dict) -> list[dict]:
    out, stack = [], [d["root"]]
    while stack:
        node = stack.pop()
        node = d.get("nodes", {}).get(node.get("ref"), node)
        if "result" in node:
            out.append(node)
        else:
            stack.extend(b["next"] for b in node["branches"])
    return out


def test_the_file_names_landings_shares_and_rejects(landing_plan):
    parts = landing_plan["parts"]
    assert [(p["name"], p["landing"], p["share"]) for p in parts] == [
        ("tri", "up", 0.5),
        ("tri", "down", 0.5),
    ]
    assert list(parts[0])[:3] == ["name", "landing", "share"]
    leaves = _leaves(landing_plan)
    for leaf in leaves:
        landings = {e["landing"] for e in leaf["result"]}
        assert list(leaf["result"][0]) == ["part", "landing", "state", "pose_deg"]
        # a leaf of down states only is a reject leaf, and only those are
        assert leaf.get("reject", False) == (landings == {"down"})
        assert "reject" not in leaf or leaf["reject"] is True
    assert any(leaf.get("reject") for leaf in leaves)
    text = plan_json(landing_plan)
    assert '{"part": "tri", "landing": "up", "state": ' in text  # an entry stays on one line
    assert plan_json(plan_from_dict(json.loads(text))) == text  # the round trip


def test_the_model_reads_landings_rejects_and_identifies_members(landing_plan):
    plan = plan_from_dict(landing_plan)
    assert [p.key for p in plan.parts] == [("tri", "up"), ("tri", "down")]
    assert plan.part("tri", "down") is plan.parts[1]
    with pytest.raises(InputError, match="several landings"):
        plan.part("tri")
    rejects = [leaf for leaf in plan.leaves() if leaf.reject]
    assert rejects and all(e.landing == "down" for leaf in rejects for e in leaf.results)
    entry = rejects[0].results[0]
    assert rejects[0].accepts("tri", entry.state, "down")
    assert not rejects[0].accepts("tri", entry.state, "up")
    assert not rejects[0].accepts("tri", entry.state)


def test_a_plan_over_landings_verifies_and_runs_every_member(landing_plan):
    report = verify_plan(landing_plan)
    assert report.ok, report.first_problem()
    by_landing = {c.landing: c for c in report.parts}
    assert by_landing["up"].rejects == 0 and by_landing["down"].rejects == by_landing["down"].paths
    plan = plan_from_dict(landing_plan)
    for k, part in enumerate(plan.parts):
        for s in part.states:
            t = execute(plan, k, s.normal_deg)
            assert t.success, t.message
            assert t.landing == part.landing and t.reject == (part.landing == "down")
            assert ("reject" in t.message) == t.reject
            d = t.to_dict()
            assert d["landing"] == part.landing and d["reject"] == t.reject
            assert all(e["landing"] == part.landing for e in d["result"])


def test_a_strong_plan_over_landings_verifies_at_its_uncertainty(strong_landing_plan):
    report = verify_declared(strong_landing_plan)
    assert report.ok, report.first_problem()
    assert {c.landing for c in report.parts} == {"up", "down"}
    assert sum(c.rejects for c in report.parts if c.landing == "up") == 0
    assert all(c.rejects > 0 for c in report.parts if c.landing == "down")


def _flip_one_accept_leaf(d: dict) -> dict:
    """The plan with one accept leaf of the up side turned into a reject leaf: the accepted
    landing then reaches a reject leaf on one path and accept leaves on others."""
    bad = copy.deepcopy(d)
    leaf = next(n for n in _leaves(bad) if not n.get("reject"))
    leaf["reject"] = True
    return bad


def test_an_accepted_landing_in_a_reject_leaf_fails_verification(landing_plan):
    report = verify_plan(_flip_one_accept_leaf(landing_plan))
    assert not report.ok
    assert "tri (up) is listed in a reject result and in an accept result" in (
        report.first_problem() or ""
    )


def test_a_rejected_landing_in_an_accept_leaf_fails_verification(landing_plan):
    bad = copy.deepcopy(landing_plan)
    leaf = next(n for n in _leaves(bad) if n.get("reject"))
    del leaf["reject"]  # the down side now reaches an accept result
    problem = verify_plan(bad).first_problem() or ""
    assert "tri (down) is listed in a reject result and in an accept result" in problem


def test_the_strong_verifier_refuses_the_clash_too(strong_landing_plan):
    with pytest.raises(CheckFailed, match=r"tri \(up\) is listed in a reject result"):
        verify_strong(_flip_one_accept_leaf(strong_landing_plan))
    assert not verify_declared(_flip_one_accept_leaf(strong_landing_plan)).ok


def _operations_by_member(d: dict) -> list[float]:
    """Each member's expected operations from a uniform start, from single runs: every state
    of the triangle reads inside one branch, so a start's run is its only path."""
    plan = plan_from_dict(d)
    out = []
    for k, part in enumerate(plan.parts):
        total = 0.0
        for s in part.states:
            lo, hi = s.resting_range_deg
            total += (hi - lo) / 360.0 * len(execute(plan, k, s.normal_deg).steps)
        out.append(total)
    return out


def test_the_expected_length_is_weighted_by_the_shares(landing_plan):
    up, down = _operations_by_member(landing_plan)
    assert landing_plan["stats"]["expected_length"] == pytest.approx(0.5 * up + 0.5 * down)
    skewed = copy.deepcopy(landing_plan)
    skewed["parts"][0]["share"], skewed["parts"][1]["share"] = 0.8, 0.2
    if not math.isclose(up, down):
        assert "expected length" in (verify_plan(skewed).first_problem() or "")
    skewed["stats"]["expected_length"] = 0.8 * up + 0.2 * down
    assert verify_plan(skewed).ok, verify_plan(skewed).first_problem()


def test_the_strong_expected_length_is_weighted_by_the_shares(strong_landing_plan):
    skewed = copy.deepcopy(strong_landing_plan)
    skewed["parts"][0]["share"], skewed["parts"][1]["share"] = 0.9, 0.1
    skewed["stats"]["expected_length"] += 0.01
    with pytest.raises(CheckFailed, match="expected length"):
        verify_strong(skewed)


def _edit(d: dict, path: str, value) -> dict:
    out = copy.deepcopy(d)
    leaf = _leaves(out)[0]
    if path == "entry.landing":
        leaf["result"][0]["landing"] = value
    elif path == "entry.no-landing":
        del leaf["result"][0]["landing"]
    elif path == "reject":
        leaf["reject"] = value
    elif path == "part.landing":
        out["parts"][0]["landing"] = value
    elif path == "part.share":
        out["parts"][0]["share"] = value
    elif path == "one share":
        del out["parts"][1]["share"]
    elif path == "same member":
        out["parts"][1]["landing"] = "up"
    return out


@pytest.mark.parametrize(
    ("path", "value", "words"),
    [
        ("entry.landing", "pose-3", "with landing 'pose-3', but the plan lists it with landing"),
        ("entry.landing", 7, "landing must be up, down or pose-K"),
        ("entry.no-landing", None, "with no landing"),
        ("reject", "yes", "'reject' must be true or false"),
        ("reject", 1, "'reject' must be true or false"),
        ("part.landing", "sideways", "landing must be up, down or pose-K"),
        ("part.landing", "pose-01", "landing must be up, down or pose-K"),
        ("part.share", "half", "share must be a finite number"),
        ("part.share", 1.5, "share 1.5 is not in (0, 1]"),
        ("part.share", 0.0, "is not in (0, 1]"),
        ("part.share", 0.9, "shares sum to 1.4"),
        ("one share", None, "either every part gives its 'share' or none"),
        ("same member", None, "two parts are both 'tri (up)'"),
    ],
)
def test_broken_landing_fields_are_one_line_input_errors(landing_plan, path, value, words):
    with pytest.raises(InputError) as exc:
        plan_from_dict(_edit(landing_plan, path, value), "p.json")
    msg = str(exc.value)
    assert words in msg and "\n" not in msg and msg.startswith("p.json: ")


def test_run_prints_landings_and_rejects(landing_plan, tmp_path, capsys):
    path = tmp_path / "landings.plan.json"
    path.write_text(plan_json(landing_plan), encoding="utf-8")
    assert main(["run", str(path), "--all"]) == 0
    out = capsys.readouterr().out
    assert "landing" in out and "down" in out and "rejects" in out
    assert "in a reject result" in out and "recirculate or re-drop" in out
    assert main(["run", str(path), "--all", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert {(p["landing"], p["rejects"] > 0) for p in report["parts"]} == {
        ("up", False),
        ("down", True),
    }
    assert main(["run", str(path), "--json"]) == 0
    runs = json.loads(capsys.readouterr().out)["runs"]
    assert [(r["landing"], r["reject"]) for r in runs] == [("up", False), ("down", True)]
    assert main(["run", str(path)]) == 0
    out = capsys.readouterr().out
    assert "tri (down) from theta 0 deg: reject (landing down)" in out
    assert "tri (up) from theta 0 deg: oriented" in out


def test_run_refuses_a_broken_landing_in_one_line(landing_plan, tmp_path, capsys):
    path = tmp_path / "bad.plan.json"
    path.write_text(plan_json(_edit(landing_plan, "reject", "yes")), encoding="utf-8")
    err = one_line_error(capsys, ["run", str(path), "--all"])
    assert "'reject' must be true or false" in err


def test_plans_without_landings_write_no_landing_keys():
    plan = read_plan_golden("isosceles-right-triangle.tolerance.json")
    text = plan_json(plan)
    assert made_as_drawn(text) and '"reject"' not in text
    assert all(p.landing is None and p.share is None for p in plan.parts)
    assert not any(leaf.reject for leaf in plan.leaves())


def read_plan_golden(name: str):
    from pathlib import Path

    return read_plan(Path(__file__).resolve().parent / "golden" / name)
