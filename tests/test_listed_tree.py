"""``plans.make.listed_tree``: the planner's tree with each leaf cut to what the plan file's
pruned result at that place lists, shared as the file shares it."""

from __future__ import annotations

from types import SimpleNamespace

from shared import small_mix

from feederkit.machine import ReadingBranch, build_machine
from feederkit.planning.tree import Leaf, Step, leaf_masks
from feederkit.plans.make import listed_tree
from feederkit.sensors import NoSensor
from feederkit.uncertainty import IDEAL


def _machine():
    return build_machine(small_mix(2, 100), NoSensor(), IDEAL)


def _entry(machine, i: int) -> dict:
    s = machine.states[i]
    return {"part": machine.part_names[s.part], "state": s.ideal_states[0]}


def _data(machine, results, nodes=None) -> dict:
    root = {"branches": [{"next": r} for r in results]}
    data = {"parts": [{"name": n} for n in machine.part_names], "root": root}
    if nodes:
        data["nodes"] = nodes
    return data


def test_a_leaf_shared_by_places_pruned_apart_becomes_one_leaf_per_place():
    m = _machine()
    a, b = 0, m.n - 1  # a state of each part
    leaf = Leaf(1 << a | 1 << b)
    root = Step(None, ((ReadingBranch(None, None, leaf.mask), leaf),) * 2)
    data = _data(m, [{"result": [_entry(m, a)]}, {"result": [_entry(m, b)]}])
    out = listed_tree(SimpleNamespace(machine=m, root=root), data)
    assert [sub.mask for _b, sub in out.branches] == [1 << a, 1 << b]
    assert sorted(leaf_masks(out)) == sorted([1 << a, 1 << b])


def test_a_subplan_the_file_shares_stays_one_object_and_an_unpruned_tree_is_kept():
    m = _machine()
    a, b = 0, m.n - 1
    leaf = Leaf(1 << a | 1 << b)
    inner = Step(None, ((ReadingBranch(None, None, leaf.mask), leaf),))
    root = Step(None, ((ReadingBranch(None, None, leaf.mask), inner),) * 2)
    shared = {"n1": {"branches": [{"next": {"result": [_entry(m, a)]}}]}}
    data = _data(m, [{"ref": "n1"}, {"ref": "n1"}], shared)
    out = listed_tree(SimpleNamespace(machine=m, root=root), data)
    first, second = (sub for _b, sub in out.branches)
    assert first is second and first.branches[0][1].mask == 1 << a
    both = {"n1": {"branches": [{"next": {"result": [_entry(m, a), _entry(m, b)]}}]}}
    same = listed_tree(SimpleNamespace(machine=m, root=root), _data(m, [{"ref": "n1"}] * 2, both))
    assert same is root  # nothing pruned: the planner's own tree
