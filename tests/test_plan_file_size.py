"""A plan whose written tree would be enormous is refused in one line, without being built."""

from __future__ import annotations

import pytest

from feederkit.errors import PlanningError
from feederkit.machine import ReadingBranch, build_machine, overlap_ranges
from feederkit.mechanics import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.tree import Leaf, PlanResult, Step
from feederkit.plans.fileformat import MAX_FILE_NODES, file_nodes, plan_to_dict
from feederkit.sensors import NoSensor


def _shared_chain(depth: int) -> tuple[PlanResult, object]:
    pf = push_function(make_part(make_outline("rect", [(0, 0), (2, 0), (2, 1), (0, 1)])))
    m = build_machine([pf], NoSensor())
    action = overlap_ranges(m, m.all_states)[0]
    branch = ReadingBranch(None, None, m.all_states)
    node: Step | Leaf = Leaf(1)
    for _ in range(depth):  # two branches to one shared child: 2**depth leaves when written
        node = Step(action, ((branch, node), (branch, node)))
    root = Step(None, ((branch, node),))
    result = PlanResult(m, root, depth + 1, float(depth + 1), 1.0, False, 2)
    return result, pf


def test_file_nodes_counts_shared_subtrees_in_full() -> None:
    result, _pf = _shared_chain(10)
    assert file_nodes(result.root) == 1 + (2**11 - 1)


def test_an_enormous_plan_is_refused_not_built() -> None:
    result, pf = _shared_chain(40)
    assert file_nodes(result.root) > MAX_FILE_NODES
    with pytest.raises(PlanningError) as err:
        plan_to_dict(result, [pf])
    message = str(err.value)
    assert "\n" not in message and "more time" in message and "at least 2" in message
    assert "--" not in message  # library words; the command line names its flags
