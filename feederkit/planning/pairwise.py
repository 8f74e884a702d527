"""A plan that always exists on the ideal model: the states told apart one pair at a time.

The proofs of Theorems 9 and 11 (sections 7 and 8) orient parts by driving one pair of
states at a time "out of phase" and telling them apart. This module builds that plan for a
whole machine, as the anytime search's first plan when no other is in hand, so that on the
ideal model a planner with a time limit answers whatever the size of the sets it meets.

At each set the plan tracks one pair of its states that are not inseparable and rotates by
a first action of a shortest plan of that pair alone (the AND/OR search on the pair,
section 6.1); among those rotations, the one whose reading sets still open need the fewest
operations by their parts' backchaining (Goldberg 1993), then the smallest. Each reading
set goes on as the maximal reading set of the image that holds it (its witness, whose plan
orients every subset), so the plan grows with the maximal reading sets only.

Why it ends: in every reading set after the rotation the pair's images either are no
longer a pair to tell apart (merged, inseparable, or split by the reading), or they are a
pair with a shorter plan, which stays tracked. An action never makes a separable pair of
its image out of an inseparable one (the inseparability relation is closed under actions),
so a set's separable pairs never grow in number, and they drop by one each time a tracked
pair is done. The plan is at most the sum of the pairs' lengths long.

It needs exact push functions (a pair's image is a pair), the exact reading branches
(under the components rule a pair inside a larger component need not read as it does
alone) and no margin floor (a pair's cells are wider than the set's).
"""

from __future__ import annotations

import bisect

from feederkit.machine import Grouping, OverlapRange, members
from feederkit.planning.andor import WorstCase
from feederkit.planning.budget import Deadline
from feederkit.planning.problem import Problem
from feederkit.planning.tree import Leaf, Step, build_dag, root_step

PAIR_CANDIDATES = 64
"""A set picks the pair it tracks among at most this many pairs of neighbouring states (by
diameter, the likeliest to read alike), the one with the shortest plan."""

SCORED = 4
"""Of the rotations that start a shortest plan of the tracked pair, this many with the
smallest images are weighed by what their reading sets still need."""


def applies(problem: Problem) -> bool:
    """Whether the pairwise plan exists and is built here: the ideal model, the exact
    reading branches and no margin floor."""
    return (
        problem.machine.deterministic
        and problem.grouping is Grouping.EXACT
        and problem.min_margin == 0.0
    )


def pairwise_plan(problem: Problem, root_branches, deadline: Deadline) -> Step | None:
    """The plan that tells the states apart one pair at a time (module docstring), built
    under ``deadline`` (Timeout), or None when it does not apply (:func:`applies`).

    ``root_branches`` are the reading branches of the first alignment.
    """
    if not applies(problem):
        return None
    pairs = WorstCase(problem, deadline, pair_bound=False)  # each pair's own search
    insep = problem.insep
    choices = problem.choices
    readings = problem.readings

    # A pair that is not inseparable has a plan (section 7); the cap guards against a goal
    # relation that is not closed under actions (a lumped one), where one may not.
    cap = 4 * problem.n + 4

    def pair_length(pair: int) -> int:
        try:
            return pairs.length(pair, cap)
        except ValueError:
            raise _Stuck from None

    def separable(i: int, j: int) -> bool:
        return i != j and not insep[i] >> j & 1

    def track(mask: int) -> int:
        """The pair of ``mask`` to tell apart next: the shortest among neighbours."""
        idx = members(mask)
        found = [(1 << a) | (1 << b) for a, b in zip(idx, idx[1:], strict=False) if separable(a, b)]
        if not found:
            found = [
                (1 << a) | (1 << b)
                for t, a in enumerate(idx)
                for b in idx[t + 1 :]
                if separable(a, b)
            ][:1]
        step = max(1, len(found) // PAIR_CANDIDATES)
        return min(found[::step][:PAIR_CANDIDATES], key=lambda p: (pair_length(p), p))

    made_ways: dict[int, tuple[list[float], list[float], list[tuple[int, int] | None]]] = {}

    def ways(pair: int, k: int) -> tuple[list[float], list[float], list[tuple[int, int] | None]]:
        """The pair's cells (starts, ends) and, per cell, the pair's image (two states)
        when the cell starts a shortest plan of the pair (``k`` operations), else None."""
        hit = made_ways.get(pair)
        if hit is None:
            starts, ends, works = [], [], []
            for lo, hi, img in choices.fixed_cells(pair):
                a, b = (
                    t.bit_length() - 1 for t in choices.targets(pair, OverlapRange(lo, hi, img))
                )
                image = (1 << a) | (1 << b)
                ok = not separable(a, b) or all(
                    pairs.within(c, k - 1) for c in readings.children(image)
                )
                starts.append(lo)
                ends.append(hi)
                works.append((a, b) if ok else None)
            hit = made_ways[pair] = (starts, ends, works)
        return hit

    def expand(key: tuple[int, int]):
        mask, pair = key
        if problem.is_goal(mask):
            return Leaf(mask)
        if pair == 0:
            pair = track(mask)
        k = pair_length(pair)
        starts, ends, works = ways(pair, k)
        going = []
        deadline.check()
        for lo, hi, img in choices.fixed_cells(mask):
            x = (lo + hi) / 2.0
            x = x - 360.0 if x >= 360.0 else x
            at = bisect.bisect_right(starts, x) - 1  # -1: the last cell, which wraps
            if not (x + 360.0 < ends[at] if at < 0 else x < ends[at]):
                continue  # between the pair's cells (one no wider than ANGLE_EPS)
            if works[at] is not None:
                going.append((img.bit_count(), lo - hi, OverlapRange(lo, hi, img), *works[at]))
        if not going:
            # The pair's first actions lie only in cells of the set no wider than ANGLE_EPS,
            # which no plan uses.
            raise _Stuck
        going.sort(key=lambda g: g[:2])
        best = None
        for size, width, sa, a, b in going[:SCORED]:
            # The plan goes on from the maximal reading sets (below): the fewest operations
            # any of them still needs by its parts' backchaining, then the largest one open.
            kids = [c for c in readings.children(sa.image) if not problem.is_goal(c)]
            chain = max((pairs.part_bound(c) for c in kids), default=0)
            open_ = max((c.bit_count() for c in kids), default=0)
            if best is None or (chain, open_, size, width) < best[0]:
                best = ((chain, open_, size, width), sa, a, b)
        assert best is not None
        _score, sa, a, b = best
        goes_on = (1 << a) | (1 << b) if separable(a, b) else 0
        widest = readings.children(sa.image)  # the maximal reading sets, largest first
        subs = []
        for branch in readings.image_branches(sa.image):
            if problem.is_goal(branch.mask):
                subs.append((branch, (branch.mask, 0)))
                continue
            # A reading set goes on as the maximal one holding it (its witness): that
            # set's plan orients every subset, and the plan grows with the maximal reading
            # sets, not with every reading set.
            witness = next(c for c in widest if branch.mask & c == branch.mask)
            subs.append((branch, (witness, goes_on if goes_on & witness == goes_on else 0)))
        return sa, subs

    top = [(b, (b.mask, 0)) for b in root_branches]
    try:
        made = build_dag([k for _b, k in top], expand, deadline)
    except _Stuck:
        return None
    return root_step(((b, made[k]) for b, k in top), deadline)


class _Stuck(Exception):
    """No usable cell of a set starts a shortest plan of its tracked pair."""
