"""Members' prior shares and rejected members on a built machine (design.md, "Landings").

A machine built from push functions (:mod:`feederkit.machine.build`) gives every member the
same share: a state's weight is its resting range over 360, divided by the number of members.
A part that lands face up or face down, or a mesh in its resting poses, is a mix whose
members (its landings) come with prior probabilities, and some of them the next station
cannot take. :func:`weigh_members` rescales each member's state weights to its share (the
expected number of operations is then weighted by the landing probabilities) and marks the
states of rejected members (``MachineState.reject``: a set of only such states is a reject
leaf, :attr:`feederkit.machine.space.SearchSpace.inseparable`). Nothing else changes: the
action maps and readings are the member's own.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import replace

from feederkit.errors import InputError
from feederkit.machine.model import PushAlignMachine

SHARE_SUM_TOL = 1e-9
"""Shares summing to 1 within this are taken as given; others are normalised."""


def normalised_shares(shares: Sequence[float], members: int) -> tuple[float, ...]:
    """``shares`` (one per member, each positive and finite) scaled to sum to 1.

    Raises InputError for a wrong count or a share that is not a positive finite number.
    """
    values = list(shares)
    if len(values) != members:
        raise InputError(f"{len(values)} shares for {members} members: give one per member")
    for s in values:
        if (
            isinstance(s, bool)
            or not isinstance(s, int | float)
            or not (math.isfinite(s) and s > 0.0)
        ):
            raise InputError(f"a member's share must be a finite positive number, got {s!r}")
    total = math.fsum(float(s) for s in values)
    if abs(total - 1.0) <= SHARE_SUM_TOL:
        return tuple(float(s) for s in values)
    return tuple(float(s) / total for s in values)


def weigh_members(
    machine: PushAlignMachine,
    shares: Sequence[float] | None = None,
    rejected: Collection[int] = (),
) -> PushAlignMachine:
    """The machine with member ``p``'s states weighing ``shares[p]`` in all, and the states
    of the members in ``rejected`` (indices into ``machine.part_names``) marked ``reject``.

    Within a member the weights keep their proportions (the resting ranges, section 3.1);
    ``shares`` are normalised to sum to 1 (None: leave the equal shares as built). The
    machine is returned unchanged when there is nothing to change. Raises InputError for an
    unknown member index or a bad share.
    """
    n_members = len(machine.part_names)
    bad = sorted(k for k in rejected if not 0 <= k < n_members)
    if bad:
        raise InputError(f"no member {bad[0]} to reject: the machine has {n_members} members")
    if shares is None and not rejected:
        return machine
    scale = [1.0] * n_members
    if shares is not None:
        wanted = normalised_shares(shares, n_members)
        totals = [0.0] * n_members
        for s in machine.states:
            totals[s.part] += s.weight
        for p in range(n_members):
            if totals[p] <= 0.0:
                raise InputError(f"member {machine.part_names[p]!r} has no weight to rescale")
            scale[p] = wanted[p] / totals[p]
    marked = frozenset(rejected)
    states = tuple(
        replace(
            s,
            weight=s.weight if shares is None else s.weight * scale[s.part],
            reject=s.part in marked,
        )
        for s in machine.states
    )
    return replace(machine, states=states)
