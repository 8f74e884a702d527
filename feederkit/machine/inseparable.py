"""The goal of a plan: inseparable states, a greatest fixpoint over pairs (sections 3.3, 8.4).

Two states are *inseparable* when no plan can ever either merge them into one state or tell
them apart by a reading: the greatest fixpoint of "their readings can agree, and every
action sends them to two different states that are again inseparable". The relation holds
between symmetric poses of one part (definitions 3, 8) and between states of parts with the
same push-diameter function (Lemma 8). A set of states is oriented (a goal) when every pair
in it is inseparable; a plan then reports all of them as correct answers. The same
fixpoint, over the cross pairs of two parts, decides whether two parts are distinguishable
(definition 11, :mod:`feederkit.mix.pairs`).

Under uncertainty an action sends a state to a *set* of states (nature picks). Two states are
then inseparable when they are *bisimilar*: their readings can agree, and for every action
every outcome of the one is matched by a *different* outcome of the other that is again
inseparable from it, and vice versa (the greatest such relation). Nature can then mirror any
run of the one by a run of the other, reading alike at every step and never merging, so no
strong plan can tell them apart or merge them: the relation is sound. With single outcomes it
is exactly the fixpoint above; symmetric poses of one part (whose outcome sets are rotated
copies) and Lemma 8 twins stay inseparable. docs/planning.md ("Strong plans") says more.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Hashable, Iterable, Sequence
from typing import TypeVar

from feederkit.angles import merge_boundaries
from feederkit.machine.model import PushAlignMachine, target_at

P = TypeVar("P", bound=Hashable)


def prune_pairs(alive: set[P], dead: list[P], preds: dict[P, list[P]]) -> None:
    """The worklist step of a greatest fixpoint over state pairs, in place.

    Removes the ``dead`` pairs from ``alive`` and, transitively, every alive pair that some
    action sends to a removed one (``preds[q]``: the pairs that lead to ``q``).
    """
    while dead:
        p = dead.pop()
        if p not in alive:
            continue
        alive.discard(p)
        dead.extend(q for q in preds.get(p, ()) if q in alive)


def greatest_fixpoint(alive: set[P], successors: Callable[[P], Iterable[P] | None]) -> set[P]:
    """The largest subset of ``alive`` closed under ``successors``, in place.

    ``successors(p)`` lists where the actions send pair ``p``, or is None when some action
    merges it (it is then separable). A pair is dropped when a successor is not alive.
    """
    preds: dict[P, list[P]] = defaultdict(list)
    dead: list[P] = []
    for p in alive:
        nxt = successors(p)
        if nxt is None:
            dead.append(p)
            continue
        for q in nxt:
            if q not in alive:
                dead.append(p)
                break
            preds[q].append(p)
    prune_pairs(alive, dead, preds)
    return alive


def pair_successors(
    starts_a: Sequence[float],
    targets_a: Sequence[int],
    starts_b: Sequence[float],
    targets_b: Sequence[int],
) -> list[tuple[int, int]]:
    """Where the actions send a pair of states with these action maps: one pair per overlap
    range of the two (section 3.2.2), in rotation order."""
    bounds = merge_boundaries([starts_a, starts_b])
    m = len(bounds)
    out = []
    for k in range(m):
        hi = bounds[k + 1] if k + 1 < m else bounds[0] + 360.0
        mid = (bounds[k] + hi) / 2.0
        out.append((target_at(starts_a, targets_a, mid), target_at(starts_b, targets_b, mid)))
    return out


def inseparable_masks(machine: PushAlignMachine) -> tuple[int, ...]:
    """For each state, the mask of states it is inseparable from (see the module docstring).

    Starts from the pairs whose readings can agree; drops a pair when some action merges it
    or sends it to a dropped pair, until nothing changes.
    """
    n = machine.n
    sensor = machine.sensor
    d = [s.sensed for s in machine.states]
    starts, targets = machine.starts, machine.targets
    alive = {(i, j) for i in range(n) for j in range(i + 1, n) if sensor.can_read_alike(d[i], d[j])}
    if not machine.deterministic:
        return _masks(_bisimilar(machine, alive), n)

    def successors(p: tuple[int, int]) -> list[tuple[int, int]] | None:
        i, j = p
        out = []
        for a, b in pair_successors(starts[i], targets[i], starts[j], targets[j]):
            if a == b:
                return None
            out.append((a, b) if a < b else (b, a))
        return out

    greatest_fixpoint(alive, successors)
    return _masks(alive, n)


def _masks(pairs: set[tuple[int, int]], n: int) -> tuple[int, ...]:
    masks = [0] * n
    for i, j in pairs:
        masks[i] |= 1 << j
        masks[j] |= 1 << i
    return tuple(masks)


def pair_outcomes(machine: PushAlignMachine, i: int, j: int) -> list[tuple[int, int]]:
    """The outcome sets ``(of i, of j)`` (masks) on each overlap range of the two states'
    action maps (section 3.2.2), in rotation order."""
    starts, outs = machine.starts, machine.outcomes_of
    bounds = merge_boundaries([starts[i], starts[j]])
    m = len(bounds)
    out = []
    for k in range(m):
        hi = bounds[k + 1] if k + 1 < m else bounds[0] + 360.0
        mid = (bounds[k] + hi) / 2.0
        out.append((target_at(starts[i], outs[i], mid), target_at(starts[j], outs[j], mid)))
    return out


def _bits(mask: int) -> list[int]:
    out = []
    while mask:
        low = mask & -mask
        out.append(low.bit_length() - 1)
        mask ^= low
    return out


def _bisimilar(machine: PushAlignMachine, alive: set[tuple[int, int]]) -> set[tuple[int, int]]:
    """The greatest bisimulation inside ``alive`` (pairs ``i < j``), in place: a pair stays
    while, on every overlap range, each outcome of either state has a different outcome of
    the other that is still paired with it."""
    cases = {p: sorted(set(pair_outcomes(machine, *p))) for p in alive}

    def linked(x: int, y: int) -> bool:
        return x != y and ((x, y) if x < y else (y, x)) in alive

    def matched(a: int, b: int) -> bool:
        xs, ys = _bits(a), _bits(b)
        return all(any(linked(x, y) for y in ys) for x in xs) and all(
            any(linked(x, y) for x in xs) for y in ys
        )

    changed = True
    while changed:
        changed = False
        for p in sorted(alive):
            if not all(matched(a, b) for a, b in cases[p]):
                alive.discard(p)
                changed = True
    return alive
