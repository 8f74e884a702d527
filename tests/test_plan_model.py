"""The one Plan model: made from files and dicts, written back byte for byte, read by all.

Fixtures are the golden plan files (``tests/golden/``), so these tests need no planner.
"""

from __future__ import annotations

import dataclasses
import json
import random
from pathlib import Path

import pytest

from feederkit.errors import InputError
from feederkit.mechanics.push import StableState
from feederkit.plans import (
    Branch,
    Leaf,
    Plan,
    Step,
    execute,
    leaf_part_pairs,
    plan_from_dict,
    plan_json,
    plan_to_dict,
    push_function_of,
    read_plan,
    verify_plan,
    write_plan,
)
from feederkit.plans.model import ResultEntry
from feederkit.uncertainty import IDEAL

GOLDEN = Path(__file__).resolve().parent / "golden"


def golden(name: str) -> dict:
    return json.loads((GOLDEN / name).read_text(encoding="utf-8"))


def deep_plan(operations: int, name: str = "rectangle-2x1.sensorless.json") -> dict:
    """A sensorless plan ``operations`` deep: the first alignment, then rotations by 0 whose
    leaf lists every state (so it is right, if useless)."""
    d = golden(name)
    part = d["parts"][0]
    leaf = {
        "result": [
            {"part": part["name"], "state": s["id"], "pose_deg": s["pose_deg"]}
            for s in part["stable_states"]
        ]
    }
    node: dict = leaf
    for _ in range(operations - 1):
        node = {"action_deg": 0.0, "margin_deg": 0.0, "branches": [{"reading": None, "next": node}]}
    d["root"] = {
        "action_deg": None,
        "margin_deg": None,
        "branches": [{"reading": None, "next": node}],
    }
    d["stats"].update(length=operations, expected_length=float(operations), lower_bound=1)
    d["stats"]["min_margin_deg"] = 0.0 if operations > 1 else None
    return d


@pytest.mark.parametrize("name", sorted(p.name for p in GOLDEN.glob("*.json")))
def test_golden_files_round_trip_through_the_model(name, tmp_path):
    text = (GOLDEN / name).read_text(encoding="utf-8")
    plan = read_plan(GOLDEN / name)
    assert isinstance(plan, Plan)
    if json.loads(text)["version"] == 1 and "uncertainty" not in json.loads(text):
        # a version-1 file reads as the ideal model; written back it is version 2
        assert not plan.uncertainty_declared and plan.uncertainty.is_ideal
        text = plan_json(upgraded(json.loads(text)))
    if repeats_a_step(json.loads(text)["root"]):
        # written before shared subplans: the writer now stores a repeated step once
        shared = json.loads(plan_json(plan))
        assert shared["nodes"] and expanded(shared) == json.loads(text)
        text = plan_json(shared)
    assert plan_json(plan) == text
    out = tmp_path / name
    write_plan(plan, out)
    assert out.read_text(encoding="utf-8") == text
    assert plan_json(read_plan(out)) == text


def repeats_a_step(root: dict) -> bool:
    """Whether a tree written without references holds two equal operation subtrees."""
    seen, stack = set(), [root]
    while stack:
        node = stack.pop()
        if "branches" in node:
            key = json.dumps(node, sort_keys=True)
            if key in seen:
                return True
            seen.add(key)
            stack.extend(b["next"] for b in node["branches"])
    return False


def expanded(d: dict) -> dict:
    """A plan file's object with every reference replaced by its node (no "nodes")."""
    table = d.get("nodes", {})

    def out(node: dict) -> dict:
        if "ref" in node:
            return out(table[node["ref"]])
        if "branches" not in node:
            return node
        branches = [{"reading": b["reading"], "next": out(b["next"])} for b in node["branches"]]
        return {**node, "branches": branches}

    return {k: out(v) if k == "root" else v for k, v in d.items() if k != "nodes"}


def upgraded(d: dict) -> dict:
    """A version-1 plan file's object as version 2 writes it: the ideal model declared, and
    every result entry naming its landing (``up``: the file's parts name none)."""
    out: dict = {}
    for key, value in d.items():
        out[key] = (
            2 if key == "version" else _as_drawn(value) if key in ("root", "nodes") else value
        )
        if key == "sensor":
            out["uncertainty"] = IDEAL.to_dict()
    return out


def _as_drawn(node):
    """A copy of ``node`` with each result entry naming the landing ``up`` right after its
    part (an explicit stack: the plans here are hundreds of operations deep)."""
    top: list = [None]
    stack: list = [(node, top, 0)]
    while stack:
        src, parent, key = stack.pop()
        if isinstance(src, list):
            parent[key] = dst = [None] * len(src)
            stack.extend((v, dst, i) for i, v in enumerate(src))
        elif isinstance(src, dict):
            if {"part", "state"} <= set(src) and "landing" not in src:
                rest = {k: v for k, v in src.items() if k != "part"}
                src = {"part": src["part"], "landing": "up"} | rest
            parent[key] = dst = dict.fromkeys(src)
            stack.extend((v, dst, k) for k, v in src.items())
        else:
            parent[key] = src
    return top[0]


def test_the_model_is_frozen_and_typed():
    plan = read_plan(GOLDEN / "quadrilateral.tolerance.json")
    with pytest.raises(dataclasses.FrozenInstanceError):
        plan.stats = None  # type: ignore[misc]
    assert plan.sensor.model == "tolerance" and plan.sensor.informative
    part = plan.parts[0]
    assert all(isinstance(s, StableState) for s in part.states)
    assert isinstance(part.hull, tuple) and isinstance(part.com, tuple)
    assert isinstance(plan.root, Step) and plan.root.overlap_range is None
    nxt = next(b.next for b in plan.root.branches if isinstance(b.next, Step))
    lo, hi = nxt.overlap_range
    assert hi - lo == pytest.approx(2 * nxt.margin_deg)
    assert plan.depth() == plan.stats.length
    assert plan.smallest_margin() == pytest.approx(plan.stats.min_margin_deg)


def test_push_functions_are_rebuilt_once_and_match_the_listed_states():
    plan = read_plan(GOLDEN / "l-bracket.tolerance.json")
    part = plan.parts[0]
    assert push_function_of(part) is push_function_of(part)  # the explicit cache
    pf = push_function_of(part)
    assert [s.id for s in pf.states] == [s.id for s in part.states]
    for built, listed in zip(pf.states, part.states, strict=True):
        assert built.diameter == pytest.approx(listed.diameter, rel=1e-12)
        assert built.normal_deg == pytest.approx(listed.normal_deg, abs=1e-9)
    assert "__dict__" not in dir(type(part)) or not part.__dict__.get("_pf")


def test_branches_hold_closed_intervals_without_slack():
    leaf = Leaf(())
    b = Branch((1.0, 2.0), leaf)
    assert b.holds(1.0) and b.holds(2.0) and b.holds(1.5)
    assert not b.holds(2.0 + 1e-12) and not b.holds(1.0 - 1e-12) and not b.holds(None)
    assert Branch(None, leaf).holds(None) and Branch(None, leaf).holds(3.0)
    step = Step(None, None, (Branch((0.0, 1.0), leaf), Branch((1.0, 2.0), leaf)))
    assert step.held_by(1.0) == (0, 1) and step.follow(1.0) == 0
    assert step.follow(2.5) is None


def test_a_plan_325_operations_deep_loads_writes_verifies_and_executes(tmp_path):
    data = deep_plan(325)
    path = tmp_path / "deep.json"
    path.write_text(plan_json(data), encoding="utf-8")
    plan = read_plan(path)
    assert plan.depth() == 325
    assert plan_json(plan) == plan_json(upgraded(data))
    write_plan(plan, tmp_path / "again.json")
    assert read_plan(tmp_path / "again.json").depth() == 325
    assert verify_plan(plan).ok
    assert execute(plan, 0, 10.0).success


def test_deeper_than_the_limit_is_one_line_naming_the_file(tmp_path):
    path = tmp_path / "deep.json"
    path.write_text(plan_json(deep_plan(40)), encoding="utf-8")
    with pytest.raises(InputError) as exc:
        read_plan(path, max_depth=30)
    msg = str(exc.value)
    assert msg.startswith(str(path)) and "30 operations" in msg and "\n" not in msg
    assert read_plan(path, max_depth=40).depth() == 40


def test_a_file_over_the_size_limit_is_refused_before_parsing(tmp_path):
    path = tmp_path / "big.json"
    path.write_text("{" + " " * 2000 + "not even json", encoding="utf-8")
    with pytest.raises(InputError) as exc:
        read_plan(path, max_bytes=1000)
    assert "more than the limit" in str(exc.value) and str(path) in str(exc.value)
    with pytest.raises(InputError, match="not valid JSON"):
        read_plan(path, max_bytes=10_000)


def test_leaf_pairs_are_each_listed_once():
    plan = read_plan(GOLDEN / "changeover-fig27-triangle-octagon.json")
    pairs = leaf_part_pairs(plan)
    assert len(pairs) == len(set(pairs))
    assert leaf_part_pairs(plan_to_dict(plan)) == pairs  # a dict is read through the model


def test_low_margin_warning():
    assert read_plan(GOLDEN / "t-clip.sensorless.json").low_margin_warning() is not None
    assert read_plan(GOLDEN / "t-clip.tolerance.json").low_margin_warning() is None
    assert read_plan(GOLDEN / "octagon.sensorless.json").low_margin_warning() is None


def test_plan_from_dict_accepts_only_a_checked_plan():
    with pytest.raises(InputError, match="not a feederkit plan"):
        plan_from_dict([1, 2, 3])


def test_a_strong_plans_margin_is_slack_beyond_its_declared_rotation_error():
    from dataclasses import replace

    from feederkit.plans.model import low_margin_words
    from feederkit.uncertainty import Uncertainty

    plan = read_plan(GOLDEN / "t-clip.sensorless.json")
    m = plan.stats.min_margin_deg
    assert m < 0.5
    assert replace(plan, uncertainty=Uncertainty(1.0)).low_margin_warning() is None
    words = replace(plan, uncertainty=Uncertainty(0.2)).low_margin_warning()
    assert words is not None and "declared ±0.2°" in words
    assert low_margin_words(None, 0.0) is None and low_margin_words(float("inf")) is None
    assert low_margin_words(0.999) is not None and low_margin_words(0.5, 0.5) is None


@pytest.mark.parametrize("count", [3, 8, 40])
def test_held_by_is_every_branch_whose_closed_interval_holds_the_reading(count):
    # Overlapping closed intervals that share endpoints, with many branches (found by
    # arrays) and few (one at a time): the same indices, in order, as Branch.holds.
    rng = random.Random(count)
    ends = sorted(round(rng.uniform(0.0, 50.0), 1) for _ in range(count + 1))
    spans = [(ends[k], ends[min(k + rng.randint(1, 2), count)]) for k in range(count)]
    branches = tuple(
        Branch(span, Leaf((ResultEntry("p", k, 0.0),))) for k, span in enumerate(spans)
    )
    step = Step(10.0, 1.0, branches)
    readings = [*ends, *(rng.uniform(-5.0, 55.0) for _ in range(200)), None]
    for r in readings:
        assert step.held_by(r) == tuple(k for k, b in enumerate(branches) if b.holds(r))


@pytest.mark.parametrize("shuffled", [False, True])
@pytest.mark.parametrize("count", [3, 8, 40])
def test_meeting_is_every_branch_whose_interval_meets_the_readings(count, shuffled):
    # The branches a state whose readings lie in [lo, hi] may follow: by bisection for
    # many branches in reading order (the planner's), by arrays for many in any order (a
    # hand-written file), one at a time for few: the same indices as the closed-interval
    # test.
    rng = random.Random(100 + count)
    ends = sorted(round(rng.uniform(0.0, 50.0), 1) for _ in range(count + 1))
    spans = [(ends[k], ends[min(k + rng.randint(1, 2), count)]) for k in range(count)]
    if shuffled:
        rng.shuffle(spans)
    branches = tuple(
        Branch(span, Leaf((ResultEntry("p", k, 0.0),))) for k, span in enumerate(spans)
    )
    step = Step(10.0, 1.0, branches)
    for _ in range(200):
        a, b = sorted(rng.choice([*ends, rng.uniform(-5.0, 55.0)]) for _ in range(2))
        want = tuple(k for k, (x, y) in enumerate(spans) if x <= b and a <= y)
        assert step.meeting(a, b) == want
    if count >= 8:  # indexed: bisection exactly when the branches come in reading order
        assert (step._ends()[2] is None) == shuffled
