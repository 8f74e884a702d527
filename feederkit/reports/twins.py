"""Poses of one part that a result lists together: alike, or the part is not oriented.

A leaf may list several stable states of one member: no push or reading tells them apart
(Akella & Mason 1999, section 8.4: indistinguishable poses). That is a correct answer only
when the poses look alike to the next station, symmetric or nearly so (within
``NEAR_SYMMETRIC_REL`` of the part's size, :func:`~feederkit.mechanics.symmetry.look_alike`).
Poses that do not look alike, a slotted link end for end (its contact hull a symmetric
stadium, the slot and the hole swapping ends) or the heptagon of Fig. 17, leave the part not
oriented between them: ``plan`` and ``changeover compile`` name them and exit 1, and the
report tells the two kinds apart here. The comparison uses the outline the caller gives
(holes and notches included); without one only the contact hull the plan file records.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from feederkit.angles import norm360
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.mechanics.symmetry import unlike_pairs
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.outline import Outline
from feederkit.plans.advice import resting_spread_words
from feederkit.plans.model import Leaf, Plan, PlanPart, push_function_of
from feederkit.reports.trace import Place


@dataclass(frozen=True)
class TwinLeaf:
    """An accepting leaf listing several states of one member (index ``member``): its
    ``states`` (ids, in result order), the pairs of them whose poses do not look alike
    (``unlike``; empty: alike, each a correct answer), and whether the comparison saw the
    outline with its holes (``outline``) or only the plan's contact hull."""

    node_id: int
    member: int
    states: tuple[int, ...]
    unlike: tuple[tuple[int, int], ...]
    outline: bool
    merged: tuple[tuple[int, ...], ...] = ()
    """Groups of the listed states that are one resting state of the declared uncertainty's
    model (a physical state: shallow wells a breath of vibration crosses) and do not all look
    alike: the part rests anywhere over their poses, oriented only that far. Their pairs are
    not in ``unlike``: no plan could tell them apart, the part itself does not stay apart."""

    @property
    def oriented(self) -> bool:
        """Whether every pose listed looks like every other (a correct answer either way)."""
        return not self.unlike


def compared_push_function(part: PlanPart, outline: Outline | None) -> PushFunction:
    """The member's push function as the plan records it (hull and COM), carrying the
    caller's outline (holes, notches) when given, so poses are compared as the next station
    sees them; the states and their numbers stay the plan's."""
    pf = push_function_of(part)
    if outline is None:
        return pf
    return push_function(replace(pf.part, outline=outline))


def twin_leaves(
    plan: Plan,
    numbered: Sequence[Place],
    outlines: Sequence[Outline | None],
) -> list[TwinLeaf]:
    """Every accepting leaf that lists several states of one member and nothing else, with
    the pairs of its states whose poses do not look alike (:func:`unlike_pairs`); each
    member's ``outlines[k]`` (None: the hull only)."""
    pfs: dict[int, PushFunction] = {}
    physical: dict[int, dict[int, int]] = {}
    found: dict[tuple[int, tuple[int, ...]], tuple[tuple[tuple[int, int], ...], Groups]] = {}
    out = []
    for place in numbered:
        leaf = place.node
        if not isinstance(leaf, Leaf) or leaf.reject or len(leaf.results) < 2:
            continue
        if len({r.key for r in leaf.results}) != 1:
            continue
        m = plan.part_index(*leaf.results[0].key)
        states = tuple(r.state for r in leaf.results)
        if (m, states) not in found:
            if m not in pfs:
                pfs[m] = compared_push_function(plan.parts[m], outlines[m])
                physical[m] = physical_states(plan, m)
            pairs = [
                (states[a], states[b]) for a, b in unlike_pairs(pfs[m], [(s,) for s in states])
            ]
            found[(m, states)] = _split_merged(pairs, physical[m])
        unlike, merged = found[(m, states)]
        out.append(TwinLeaf(place.node_id, m, states, unlike, outlines[m] is not None, merged))
    return out


Groups = tuple[tuple[int, ...], ...]


def physical_states(plan: Plan, member: int) -> dict[int, int]:
    """Each stable state of the member's as the declared uncertainty's model groups them
    (:func:`~feederkit.mechanics.uncertain.uncertain_mechanics`: the physical state holding
    it); empty on the ideal model, where every state is its own."""
    if plan.uncertainty.is_ideal:
        return {}
    mech = uncertain_mechanics(push_function_of(plan.parts[member]).part, plan.uncertainty)
    return {i: s.id for s in mech.states for i in s.members}


def _split_merged(
    pairs: Sequence[tuple[int, int]], physical: dict[int, int]
) -> tuple[tuple[tuple[int, int], ...], Groups]:
    """The unlike ``pairs`` of states in different physical states, and the groups of states
    joined by an unlike pair within one physical state (:attr:`TwinLeaf.merged`)."""
    apart: list[tuple[int, int]] = []
    within: dict[int, set[int]] = {}
    for a, b in pairs:
        if a in physical and physical.get(b) == physical[a]:
            within.setdefault(physical[a], set()).update((a, b))
        else:
            apart.append((a, b))
    return tuple(apart), tuple(tuple(sorted(g)) for _, g in sorted(within.items()))


def spread_words_of(plan: Plan, twins: Sequence[TwinLeaf]) -> str | None:
    """The warning ``plan`` gives of results that name a resting state made of several
    unlike stable states (:func:`~feederkit.plans.advice.resting_spread_words`), for the
    leaves of the plan file; None when there are none."""
    named: dict[tuple[int, tuple[int, ...]], None] = {}
    for t in twins:
        for g in t.merged:
            named[(t.member, g)] = None
    if not named:
        return None
    items = []
    for m, g in named:
        part = plan.parts[m]
        normals = [part.state(s).normal_deg for s in g]
        spread = max(norm360(b - a) for a in normals for b in normals if norm360(b - a) < 180.0)
        items.append(f"{part.label} states {', '.join(map(str, g))} over {spread:.3g} degrees")
    return resting_spread_words("; ".join(items))


def unoriented_words(plan: Plan, twins: Sequence[TwinLeaf]) -> str | None:
    """One line naming every pair of poses of one member that a result lists together and
    that do not look alike, in the words ``plan`` uses (``plans.advice.unlike_twins_words``);
    None when there are none."""
    named: dict[tuple[int, int, int], None] = {}
    for t in twins:
        for a, b in t.unlike:
            named[(t.member, a, b)] = None
    if not named:
        return None
    items = []
    for m, a, b in named:
        part = plan.parts[m]
        poses = [norm360(part.state(s).pose_deg) for s in (a, b)]
        items.append(
            f"{part.label} states {a} and {b} (poses {poses[0]:.4g} and {poses[1]:.4g} degrees)"
        )
    return (
        "no plan can tell apart poses that do not look alike: "
        + "; ".join(items)
        + ": a result lists them, so the part is not oriented between them: check its pose "
        "by other means, or take it either way"
    )
