"""Physical states no result may hold: a part at rest there wanders between unlike poses.

Under uncertainty a physical resting state can hold ideal stable states whose poses do not
look alike and span a quarter turn or more (``MachineState.unlike_members``, the merge rule of
docs/uncertainty.md): a part resting there is not oriented, so a plan may pass through the
state but not end in it. The goal relation is pairwise (a set is oriented when every pair of
its states is inseparable, section 6.1), and a state alone is always oriented. So each such
state gets a twin: a copy with the same action map, readings and half the weight, which no
leaf may list with it (neither looks like the other). Every outcome set holds both or
neither, and no reading tells them apart, so no oriented set holds either: a plan must push
the part on until it rests elsewhere, and every planner searches that goal unchanged. Where
no plan can (every action may leave the part there), the planner proves that no strong plan
exists.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from feederkit.machine import OutcomeRange, PushAlignMachine, members, search_space
from feederkit.machine.inseparable import inseparable_masks


def split_wandering(machine: PushAlignMachine) -> tuple[PushAlignMachine, list[int]]:
    """``machine`` with a twin appended for each state with ``unlike_members``, and
    ``old[index]``: the original state of each state (itself, or the state a twin copies).

    The machine itself (and the identity) when no state wanders, or when its actions are
    the ideal model's single targets (where none does).

    >>> from feederkit.machine import MachineState
    >>> from feederkit.sensors import NoSensor
    >>> s = (MachineState(0, 0, 1.0, 0.5, members=(0, 1), look_alike=(), unlike_members=True),
    ...      MachineState(0, 2, 2.0, 0.5, members=(2,), look_alike=()))
    >>> maps = ((OutcomeRange(0.0, 360.0, 0b11),), (OutcomeRange(0.0, 360.0, 0b10),))
    >>> m = PushAlignMachine(("toy",), s, maps, NoSensor(), None)
    >>> split, old = split_wandering(m)
    >>> old, [st.weight for st in split.states], split.action_maps[0][0].targets
    ([0, 1, 0], [0.25, 0.5, 0.25], 7)
    """
    wandering = [i for i, s in enumerate(machine.states) if s.unlike_members]
    outcomes = all(isinstance(r, OutcomeRange) for rs in machine.action_maps for r in rs)
    if not wandering or not outcomes:
        return machine, list(range(machine.n))
    n = machine.n
    twin = {w: n + k for k, w in enumerate(wandering)}
    of_part: dict[int, list[int]] = {}
    for s in machine.states:
        of_part.setdefault(s.part, []).append(s.state)
    states = list(machine.states)
    for w in wandering:
        s = states[w]
        # Alike to what it was alike to, never to itself (so not to its twin either); a
        # state that recorded nothing (alike to all) is alike to its part's other states.
        alike = s.look_alike if s.look_alike is not None else tuple(of_part[s.part])
        states[w] = replace(
            s, weight=s.weight / 2.0, look_alike=tuple(a for a in alike if a != s.state)
        )
    states += [states[w] for w in wandering]

    def doubled(r: OutcomeRange) -> OutcomeRange:
        extra = 0
        for t in members(r.targets):
            if t in twin:
                extra |= 1 << twin[t]
        return OutcomeRange(r.lo, r.hi, r.targets | extra) if extra else r

    maps = [tuple(doubled(r) for r in rs) for rs in machine.action_maps]
    maps += [maps[w] for w in wandering]
    split = PushAlignMachine(
        machine.part_names, tuple(states), tuple(maps), machine.sensor, machine.uncertainty
    )
    return split, list(range(n)) + wandering


def twin_masks(masks: tuple[int, ...], old: list[int], apart: bool = False) -> tuple[int, ...]:
    """Per-state masks of the machine (its bisimilar states, say) over the machine from
    :func:`split_wandering` (``old[index]``: each state's original): each state's original's
    mask, every original bit standing for the state and its twin; ``apart``: a state's mask
    never holds its own twin (a goal relation, where they must stay apart).

    >>> twin_masks((0b01, 0b11), [0, 1, 0]), twin_masks((0b01, 0b11), [0, 1, 0], apart=True)
    ((5, 7, 5), (1, 7, 4))
    """
    copies: dict[int, int] = {}
    for k, o in enumerate(old):
        copies[o] = copies.get(o, 0) | 1 << k
    out = []
    for k, o in enumerate(old):
        mask = 0
        for j in members(masks[o]):
            mask |= copies[j]
        if apart:
            mask &= ~(copies[o] & ~(1 << k))
        out.append(mask)
    return tuple(out)


def twinned(
    machine: PushAlignMachine, check: Callable[[], None] | None = None
) -> tuple[PushAlignMachine, list[int]]:
    """:func:`split_wandering` with the machine's own goal relation: the split machine's
    bisimilar states are the machine's (:func:`twin_masks`), computed once (``check`` polls
    a deadline), not its own, where a twin would be an outcome nature keeps apart from its
    state (two states pushed into one wandering state are merged there)."""
    split, old = split_wandering(machine)
    if split is not machine:
        space = search_space(machine)
        if "bisimilar" not in vars(space):
            vars(space)["bisimilar"] = inseparable_masks(machine, check)
        vars(search_space(split))["bisimilar"] = twin_masks(space.bisimilar, old)
    return split, old


def is_twin_pair(machine: PushAlignMachine, i: int, j: int) -> bool:
    """Whether states ``i`` and ``j`` of a machine from :func:`split_wandering` are a wandering
    state and its twin (equal records: a pair no plan resolves because a part resting there
    wanders between unlike poses)."""
    return i != j and machine.states[i] == machine.states[j] and machine.states[i].unlike_members


def wandering_words(
    machine: PushAlignMachine, pairs: list[tuple[int, int]], unresolved: bool = True
) -> str:
    """The clause of a "no strong plan" message for twin pairs (:func:`is_twin_pair`): no
    strong plan resolves them (the part may rest in those states, unoriented, whatever the
    plan), or, ``unresolved`` False, only that no result may hold them (not looked at)."""
    named = []
    for i, _j in pairs:
        s = machine.states[i]
        poses = ", ".join(str(m) for m in s.ideal_states)
        named.append(f"{machine.part_names[s.part]} states {poses}")
    u = machine.uncertainty
    toleranced = u is not None and (u.shape_tolerance_mm > 0.0 or u.com_tolerance_mm > 0.0)
    barriers = (
        "twice the shape and COM tolerances plus a breath of vibration"
        if toleranced
        else "a breath of vibration"
    )
    lead = (
        "every plan may leave the part resting where it wanders between unlike poses"
        if unresolved
        else "no result may hold a state where the part at rest wanders between unlike poses"
    )
    words = (
        f"{lead} ({'; '.join(named)}: their barriers lie below {barriers}, "
        "docs/uncertainty.md); a plan that ends there, leaving the part unoriented, is given "
        "with lumping 'any'"
    )
    if toleranced:
        words += "; a smaller --shape-tolerance or --com-tolerance may keep them apart"
    return words


__all__ = ["is_twin_pair", "split_wandering", "twin_masks", "twinned", "wandering_words"]
