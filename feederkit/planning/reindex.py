"""Renumbering a machine's states by diameter, and plans back to the original numbering.

With states numbered in diameter order, the states a reading can come from are a run of
consecutive bits, so the planners find reading branches with a few mask operations.
Nothing else depends on the numbering.
"""

from __future__ import annotations

from collections.abc import Callable

from feederkit.machine import (
    ActionRange,
    OutcomeRange,
    OverlapRange,
    PushAlignMachine,
    ReadingBranch,
    members,
    search_space,
)
from feederkit.planning.tree import Leaf, PlanTree, Step, map_tree


def by_diameter(machine: PushAlignMachine) -> tuple[PushAlignMachine, list[int]]:
    """The machine with states sorted by diameter, and ``old[new_index]``."""
    old = sorted(range(machine.n), key=lambda i: (machine.states[i].diameter, i))
    if old == list(range(machine.n)):
        return machine, old
    new = [0] * machine.n
    for k, i in enumerate(old):
        new[i] = k

    def moved(r: ActionRange | OutcomeRange) -> ActionRange | OutcomeRange:
        if isinstance(r, OutcomeRange):
            out = 0
            for t in members(r.targets):
                out |= 1 << new[t]
            return OutcomeRange(r.lo, r.hi, out)
        return ActionRange(r.lo, r.hi, new[r.target])

    maps = tuple(tuple(moved(r) for r in machine.action_maps[i]) for i in old)
    states = tuple(machine.states[i] for i in old)
    sorted_machine = PushAlignMachine(
        machine.part_names, states, maps, machine.sensor, machine.uncertainty
    )
    return sorted_machine, old


def share_bisimilar(
    machine: PushAlignMachine, sorted_machine: PushAlignMachine, old: list[int]
) -> None:
    """Give each of the two numberings of one machine (``old[new_index]``, from
    :func:`by_diameter`) the other's bisimilar states when only one has them: the fixpoint
    (:attr:`~feederkit.machine.space.SearchSpace.bisimilar`) is the longest step before a
    search, and callers ask it of the machine they hold (a mix's pairs after its plan)."""
    if sorted_machine is machine:
        return
    a, b = vars(search_space(machine)), vars(search_space(sorted_machine))
    if "bisimilar" in a and "bisimilar" not in b:
        new = [0] * len(old)
        for k, i in enumerate(old):
            new[i] = k
        b["bisimilar"] = tuple(remap_mask(a["bisimilar"][i], new) for i in old)
    elif "bisimilar" in b and "bisimilar" not in a:
        out = [0] * len(old)
        for k, i in enumerate(old):
            out[i] = remap_mask(b["bisimilar"][k], old)
        a["bisimilar"] = tuple(out)


def remap_mask(mask: int, old: list[int]) -> int:
    """A mask over the renumbered states as a mask over the original ones."""
    out = 0
    for k in members(mask):
        out |= 1 << old[k]
    return out


def remap_tree(node: PlanTree, old: list[int]) -> PlanTree:
    """A plan over the renumbered machine as a plan over the original one.

    Shared subtrees stay shared (each node is converted once).
    """
    masks: dict[int, int] = {}

    def mask(m: int) -> int:
        out = masks.get(m)
        if out is None:
            out = masks[m] = remap_mask(m, old)
        return out

    return map_masks(node, mask)


def map_masks(node: PlanTree, mask: Callable[[int], int]) -> PlanTree:
    """The plan with every mask (leaves, action images, reading branches) replaced by
    ``mask`` of it (:func:`~feederkit.planning.tree.map_tree`: each distinct node once)."""

    def step(n: Step, subs: tuple) -> Step:
        action = n.action
        if action is not None:
            action = OverlapRange(action.lo, action.hi, mask(action.image))
        return Step(
            action, tuple((ReadingBranch(b.lo, b.hi, mask(b.mask)), sub) for b, sub in subs)
        )

    return map_tree(node, lambda x: Leaf(mask(x.mask)), step)
