"""A plan's file holds each distinct node once: repeated subplans go to ``"nodes"``, and only
a plan with more distinct nodes than the limit is refused, in one line."""

from __future__ import annotations

import time

import pytest

import feederkit.plans.fileformat as fileformat
from feederkit.errors import PlanningError
from feederkit.machine import ReadingBranch, build_machine, overlap_ranges
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.tree import Leaf, PlanResult, Step
from feederkit.plans.fileformat import file_nodes, plan_from_result, plan_to_dict
from feederkit.plans.readplan import plan_from_dict
from feederkit.plans.verify import verify_plan
from feederkit.sensors import ToleranceSensor


def _shared_chain(depth: int) -> tuple[PlanResult, object]:
    pf = push_function(make_part(make_outline("rect", [(0, 0), (2, 0), (2, 1), (0, 1)])))
    m = build_machine([pf], ToleranceSensor(0.01))
    action = overlap_ranges(m, m.all_states)[0]
    narrow = sum(1 << i for i, s in enumerate(m.states) if s.diameter < 1.5)
    short = ReadingBranch(0.99, 1.01, narrow)
    long = ReadingBranch(1.99, 2.01, m.all_states ^ narrow)
    # The last step's reading tells the sides apart; the symmetric poses of a side listed
    # together (paths may end in only one of them).
    node: Step | Leaf = Step(action, ((short, Leaf(short.mask)), (long, Leaf(long.mask))))
    for _ in range(depth - 1):  # two branches to one shared child: 2**depth leaves expanded
        node = Step(action, ((short, node), (long, node)))
    root = Step(None, ((short, node), (long, node)))
    result = PlanResult(m, root, depth + 1, float(depth + 1), action.margin, False, 2)
    return result, pf


def test_file_nodes_counts_each_distinct_step_once_and_leaves_per_place() -> None:
    result, pf = _shared_chain(10)
    plan = plan_from_result(result, [pf])
    # the root and ten distinct steps; the last step's two branches each hold the leaf
    assert file_nodes(plan.root) == 1 + 10 + 2


def test_an_enormous_tree_of_shared_subplans_is_written_once_per_node() -> None:
    result, pf = _shared_chain(40)  # 2**40 paths
    start = time.perf_counter()
    data = plan_to_dict(result, [pf])
    assert len(data["nodes"]) == 40  # every step below the root is used by two branches
    plan = plan_from_dict(data)
    assert plan.depth() == 41
    assert verify_plan(plan).ok
    assert time.perf_counter() - start < 2.0


def test_more_distinct_nodes_than_the_limit_is_refused_in_one_line(monkeypatch) -> None:
    result, pf = _shared_chain(40)
    monkeypatch.setattr(fileformat, "MAX_FILE_NODES", 30)
    with pytest.raises(PlanningError) as err:
        plan_to_dict(result, [pf])
    message = str(err.value)
    assert "\n" not in message and "more time" in message and "at least 2" in message
    assert "43 nodes" in message
    assert "--" not in message  # library words; the command line names its flags
