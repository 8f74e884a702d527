"""Shared subplans (design.md, plan file: ``"nodes"`` and ``{"ref": ID}``): the writer stores
each repeated subtree once, the reader makes it one shared object again and refuses broken
tables in one line, and every walk (depth, execution, verification, drawing) costs the
distinct nodes, not the paths.

The plans are made from the golden rectangle (states alternately 1 and 2 mm wide): a layered
DAG whose every step branches on the reading to two steps of the next layer, so ``LAYERS``
layers give 2**LAYERS paths through about ten distinct steps per layer.
"""

from __future__ import annotations

import copy
import dataclasses
import io
import json
import re
import time
from pathlib import Path

import pytest
from rich.console import Console

from feederkit.cli.plan_render import plan_tree
from feederkit.errors import InputError
from feederkit.plans import (
    Branch,
    Leaf,
    Plan,
    PlanStats,
    ResultEntry,
    Step,
    execute,
    plan_from_dict,
    plan_json,
    plan_to_dict,
    read_plan,
    verify_plan,
)
from feederkit.plans.fileformat import file_nodes
from feederkit.plans.verify import verify_declared
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import Uncertainty

GOLDEN = Path(__file__).resolve().parent / "golden"
BASE = "rectangle-2x1.tolerance.json"  # diameters 1, 2, 1, 2; read at 0.02 mm below
MARGIN = 10.0  # every multiple of 90 degrees keeps the rectangle's states within ±10


def layered(layers: int, width: int = 10, uncertainty: Uncertainty | None = None) -> Plan:
    """A plan of ``layers`` layers of ``width`` distinct steps (rotations by multiples of 90
    degrees), each branching on the reading to two steps of the next layer; every path takes
    every layer and ends in one of two leaves, the states of each diameter (right, if
    useless: paths end there in each state it lists)."""
    base = read_plan(GOLDEN / BASE)
    part = base.parts[0]
    leaves = [
        Leaf(tuple(ResultEntry(part.name, s.id, s.pose_deg) for s in part.states if k == s.id % 2))
        for k in range(2)
    ]  # diameters 1, 2, 1, 2: the short states, the long ones
    short, long = (0.98, 1.02), (1.98, 2.02)
    below: list[Step | Leaf] = [leaves[j % 2] for j in range(width)]
    for _ in range(layers):
        below = [
            Step(
                (90.0 * j) % 360.0,
                MARGIN,
                (Branch(short, below[2 * j % width]), Branch(long, below[(2 * j + 1) % width])),
            )
            for j in range(width)
        ]
    root = Step(None, None, (Branch(short, below[0]), Branch(long, below[1])))
    n = layers + 1
    stats = PlanStats(n, float(n), MARGIN, False, 1)
    unc = base.uncertainty if uncertainty is None else uncertainty
    sensor = ToleranceSensor(0.02)  # the branches' reading intervals are 1 and 2 mm +- 0.02
    return dataclasses.replace(base, root=root, stats=stats, uncertainty=unc, sensor=sensor)


def _table_refs(node: dict) -> list[str]:
    """The references inside one NODE object written in place (not through other refs)."""
    out, stack = [], [node]
    while stack:
        n = stack.pop()
        if "ref" in n:
            out.append(n["ref"])
        elif "branches" in n:
            stack.extend(b["next"] for b in n["branches"])
    return out


@pytest.fixture(scope="module")
def small() -> dict:
    return plan_to_dict(layered(5, width=4))


def test_repeated_subtrees_are_written_once_and_read_back_shared(small):
    assert list(small)[-3:] == ["root", "nodes", "stats"]
    assert set(small["nodes"]) == {f"n{k}" for k in range(1, len(small["nodes"]) + 1)}
    text = plan_json(small)
    assert '"next": {"ref": "n1"}' in text  # a reference stays on one line
    plan = plan_from_dict(json.loads(text))
    assert plan_json(plan) == text  # write -> read -> write: the same bytes
    uses: dict[int, int] = {}
    for node, _number in plan.walk():  # each distinct node once
        for b in node.branches if isinstance(node, Step) else ():
            uses[id(b.next)] = uses.get(id(b.next), 0) + 1
    # every shared subplan is one object that several branches lead to
    assert sum(1 for n in uses.values() if n > 1) == len(small["nodes"])
    assert plan.depth() == 6 and len(plan.leaves()) == 2 * 4  # the last layer's places


def test_equal_subtrees_are_shared_even_when_written_out_in_full(small):
    plan = plan_from_dict(small)
    # a file with the shared subtrees written in place is the same plan: written, it shares
    flat = json.loads(plan_json(small))
    table = flat.pop("nodes")

    def inline(node: dict) -> dict:
        if "ref" in node:
            return inline(table[node["ref"]])
        if "branches" in node:
            return {
                **node,
                "branches": [{**b, "next": inline(b["next"])} for b in node["branches"]],
            }
        return node

    flat["root"] = inline(flat["root"])
    assert "nodes" not in flat
    assert plan_json(plan_from_dict(flat)) == plan_json(plan)


def test_a_plan_without_repeated_subtrees_is_written_as_before():
    text = (GOLDEN / "isosceles-right-triangle.sensorless.json").read_text(encoding="utf-8")
    plan = read_plan(GOLDEN / "isosceles-right-triangle.sensorless.json")
    assert '"nodes"' not in plan_json(plan) and plan_json(plan) == text


def test_a_dag_of_two_to_the_thirty_paths_loads_runs_and_verifies_fast(tmp_path):
    start = time.perf_counter()
    plan = layered(30)
    path = tmp_path / "dag.plan.json"
    path.write_text(plan_json(plan), encoding="utf-8")
    assert path.stat().st_size < 1_000_000
    data = json.loads(path.read_text(encoding="utf-8"))
    assert 250 <= len(data["nodes"]) <= 310
    read = read_plan(path)
    assert read.depth() == 31 and file_nodes(read.root) < 400
    assert plan_json(read) == path.read_text(encoding="utf-8")
    for k, s in enumerate(read.parts[0].states):
        t = execute(read, 0, s.normal_deg + 3.0 * k)
        assert t.success and len(t.steps) == 31, t.message
    assert len(list(read.walk())) == file_nodes(read.root)  # each distinct node once
    report = verify_plan(read)
    assert report.ok, report.first_problem()
    assert time.perf_counter() - start < 2.0


def test_a_dag_is_drawn_once_per_distinct_node():
    plan = layered(30, width=4)  # 2**31 root-to-leaf paths through 121 distinct steps
    console = Console(file=io.StringIO(), width=100)
    console.print(plan_tree(plan))
    drawing = console.file.getvalue()
    assert "shared subplan S1" in drawing and "the shared subplan S1 (drawn above)" in drawing
    assert drawing.count("\n") < 10 * file_nodes(plan.root)


def test_a_drawing_past_its_line_limit_stops_and_says_what_it_left_out():
    plan = layered(30, width=4)
    console = Console(file=io.StringIO(), width=200)
    console.print(plan_tree(plan, max_lines=60))
    drawing = console.file.getvalue()
    before, note = drawing.split("the drawing stops after", 1)
    assert len(before.splitlines()) < 100  # 60 labels (a few results wrap), not ~500
    left = re.search(r"(\d+) more operations", " ".join(note.split()))
    assert left is not None and 0 < int(left.group(1)) < 121  # 121 distinct steps in all
    assert "not drawn here (in the plan file)" in before  # a cut branch says so
    whole = Console(file=io.StringIO(), width=200)
    whole.print(plan_tree(plan))
    assert "the drawing stops" not in whole.file.getvalue()


def test_a_strong_dag_verifies_at_its_declared_uncertainty():
    start = time.perf_counter()
    plan = layered(30, uncertainty=Uncertainty(1.0, 0.0, 0.0))
    data = plan_to_dict(plan)
    report = verify_declared(plan_from_dict(data))
    assert report.ok, report.first_problem()
    assert time.perf_counter() - start < 2.0


def _first_shared(d: dict) -> str:
    return next(iter(d["nodes"]))


def _refusal(d: dict, edit) -> str:
    bad = copy.deepcopy(d)
    edit(bad)
    with pytest.raises(InputError) as exc:
        plan_from_dict(bad, "p.json")
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("p.json: ")
    return msg


def _self_cycle(d: dict) -> None:
    key = _first_shared(d)
    d["nodes"][key]["branches"][0]["next"] = {"ref": key}


def _two_cycle(d: dict) -> None:
    a = next(k for k, n in d["nodes"].items() if _table_refs(n))
    b = _table_refs(d["nodes"][a])[0]
    d["nodes"][b]["branches"][0]["next"] = {"ref": a}


def _ref_of(d: dict) -> dict:
    """The first reference written in the root's tree (a dict to edit in place)."""
    stack = [d["root"]]
    while stack:
        n = stack.pop()
        for b in n.get("branches", []):
            if "ref" in b["next"]:
                return b["next"]
            stack.append(b["next"])
    raise AssertionError("no reference in the root's tree")


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda d: _ref_of(d).update(ref="n999"), "refers to the unknown shared node 'n999'"),
        (lambda d: _ref_of(d).update(ref=3), "refers to 3: a reference names a shared node"),
        (lambda d: _ref_of(d).update(extra=1), "a reference with other keys than 'ref'"),
        (_self_cycle, "the shared subplans form a cycle"),
        (_two_cycle, "the shared subplans form a cycle"),
        (
            lambda d: d["nodes"].update(n99=copy.deepcopy(d["nodes"]["n1"])),
            "'n99' of 'nodes' is never used",
        ),
        (lambda d: d.update(nodes=[]), "'nodes' must be a non-empty object"),
        (lambda d: d.update(nodes={}), "'nodes' must be a non-empty object"),
        (lambda d: d["nodes"].update(n1=[1, 2]), "shared node 'n1' must be a JSON object"),
        (lambda d: d["nodes"].update(n1={"ref": "n2"}), "shared node 'n1' is itself a reference"),
        (lambda d: d.update(root={"ref": "n1"}), "the root is written in place"),
    ],
)
def test_broken_shared_subplans_are_one_line_input_errors(small, edit, words):
    assert words in _refusal(small, edit)


def test_references_deeper_than_the_limit_are_refused(tmp_path):
    path = tmp_path / "deep.plan.json"
    path.write_text(plan_json(layered(40, width=2)), encoding="utf-8")
    text = path.read_text(encoding="utf-8")
    assert text.count("{") < 2000  # shallow JSON: only the references make it deep
    with pytest.raises(InputError) as exc:
        read_plan(path, max_depth=30)
    msg = str(exc.value)
    assert msg.startswith(str(path)) and "more than 30 operations deep" in msg
    assert read_plan(path, max_depth=41).depth() == 41


def _uneven(uncertainty: Uncertainty | None = None) -> Plan:
    """A shared subplan S met after one operation (a narrow reading) and after two (a wide
    reading, then a quarter turn that makes the part narrow): the same state reaches S at
    different depths."""
    base = read_plan(GOLDEN / BASE)
    part = base.parts[0]
    short, long = (0.98, 1.02), (1.98, 2.02)
    narrow, wide = (
        Leaf(tuple(ResultEntry(part.name, s.id, s.pose_deg) for s in part.states if k == s.id % 2))
        for k in range(2)
    )  # diameters 1, 2, 1, 2
    shared = Step(0.0, MARGIN, (Branch(short, narrow), Branch(long, wide)))
    turn = Step(90.0, MARGIN, (Branch(short, shared), Branch(long, shared)))
    root = Step(None, None, (Branch(short, shared), Branch(long, turn)))
    widths = {s.id: s.resting_range_deg[1] - s.resting_range_deg[0] for s in part.states}
    narrow = sum(w for sid, w in widths.items() if part.state(sid).diameter < 1.5) / 360.0
    stats = PlanStats(3, 2.0 * narrow + 3.0 * (1.0 - narrow), MARGIN, False, 1)
    unc = base.uncertainty if uncertainty is None else uncertainty
    sensor = ToleranceSensor(0.02)  # the branches' reading intervals are 1 and 2 mm +- 0.02
    return dataclasses.replace(base, root=root, stats=stats, uncertainty=unc, sensor=sensor)


@pytest.mark.parametrize("uncertainty", [None, Uncertainty(1.0, 0.0, 0.0)])
def test_a_subplan_shared_across_depths_is_checked_at_each(uncertainty):
    data = plan_to_dict(_uneven(uncertainty))
    assert len(data["nodes"]) == 1
    plan = plan_from_dict(data)
    assert plan.depth() == 3
    report = verify_declared(plan)
    assert report.ok, report.first_problem()
    assert max(c.worst_operations for c in report.parts) == 3
    wide = next(s for s in plan.parts[0].states if s.diameter > 1.5)
    assert len(execute(plan, 0, wide.normal_deg).steps) == 3
    # a failure below the shared subplan is reported with the operations of its own path
    bad = copy.deepcopy(data)
    bad["nodes"]["n1"]["branches"][0]["next"]["result"] = bad["nodes"]["n1"]["branches"][0]["next"][
        "result"
    ][:1]
    if uncertainty is None:
        failures = verify_plan(bad).failures
        assert failures
        for t in failures:
            assert [s.number for s in t.steps] == list(range(1, len(t.steps) + 1))
