"""Changeovers: one verified plan for a product mix, stored in the catalog against the parts'
exact revisions (section 8.5; docs/changeovers.md). The command line and the demo call this.

A changeover's plan orients every part of the mix; it recognizes every part except the pairs
that no plan can tell apart (section 8.4, Corollary 7), whose results list each candidate.
The plan is made for the revisions it names: a part revised later does not change it, and
:func:`stale_revisions` says when a newer revision exists.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Collection, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from feederkit.catalog import (
    ChangeoverInfo,
    get_changeover,
    get_revision,
    list_changeovers,
    save_changeover,
)
from feederkit.errors import InputError
from feederkit.jsonio import OutputFile, StagedFiles, parse_json
from feederkit.landing.model import Landing, landings_of_outline, select_landings
from feederkit.loading import load_parts
from feederkit.machine import PushAlignMachine, members, search_space
from feederkit.machine.weights import normalised_shares
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.mix.pairs import PairWitness, unrecognizable_pairs
from feederkit.planning.options import PlanningOptions
from feederkit.plans.fileformat import plan_json, validate_plan
from feederkit.plans.make import MadePlan, make_plan
from feederkit.plans.match import leaf_part_pairs
from feederkit.plans.model import PlanMember
from feederkit.sensors import Sensor, sensor_from_dict
from feederkit.uncertainty import Uncertainty

Member = str | tuple[str, int | None]
"""A catalog part of a mix: ``NAME`` or ``NAME@REV`` (or, transitionally, ``(name, rev)``)."""


@dataclass(frozen=True)
class CompiledChangeover:
    """A stored changeover: its verified plan, exact revisions, pairs no plan tells apart."""

    name: str
    revisions: tuple[tuple[str, int], ...]
    parts: tuple[PushFunction, ...]
    made: MadePlan
    witnesses: tuple[PairWitness, ...]
    warnings: tuple[str, ...] = ()

    @property
    def plan(self) -> dict[str, Any]:
        """The plan file's object."""
        return self.made.plan

    @property
    def lumped(self) -> list[tuple[str, str]]:
        """Pairs of parts that some result of the plan lists together."""
        return leaf_part_pairs(self.made.plan)


@dataclass(frozen=True)
class StoredChangeover:
    """A changeover read back from the catalog: its record, plan, and the parts it was made for.

    ``parts`` are the push functions of the exact revisions the plan names; ``warnings`` say
    which of them the catalog has revised since (:func:`stale_revisions`).
    """

    info: ChangeoverInfo
    plan: dict[str, Any]
    parts: tuple[PushFunction, ...]
    warnings: tuple[str, ...]

    @property
    def sensor(self) -> Sensor:
        """The sensor the plan was made for."""
        return sensor_from_dict(dict(self.info.sensor))

    def witnesses(self) -> list[PairWitness]:
        """The pairs of its parts no plan can tell apart (section 8.4), decided again exactly."""
        if len(self.parts) < 2:
            return []
        return unrecognizable_pairs(list(self.parts), self.sensor)


def _source(member: Member) -> str:
    """A member as a catalog SOURCE (``NAME`` or ``NAME@REV``)."""
    if isinstance(member, str):
        return member
    name, rev = member
    return name if rev is None else f"{name}@{rev}"


def plan_mix(
    parts: Sequence[PushFunction],
    sensor: Sensor,
    options: PlanningOptions | None = None,
    *,
    uncertainty: Uncertainty | None = None,
    members: Sequence[PlanMember] | None = None,
    weights: Sequence[float] | None = None,
) -> tuple[MadePlan, list[PairWitness]]:
    """A verified plan for one part or a mix (section 8.5), and the pairs of parts no plan
    can tell apart (section 8.4), each with its witness.

    ``uncertainty`` defaults to design.md's ``Uncertainty()``. ``members`` name the parts in
    the plan file with their landings, prior shares and accept/reject
    (:class:`~feederkit.plans.model.PlanMember`; None: as the parts are, equal shares);
    ``weights`` give the parts' prior shares alone (a product mix's, normalised). On
    the ideal model the pairs are the exact analysis of :mod:`feederkit.mix.pairs`; under
    uncertainty they are the cross pairs of the strong machine's bisimilar states, the
    relation the planner's results use. Pairs name the parts as ``parts`` do.
    """
    made = make_plan(
        parts, sensor, options, uncertainty=uncertainty, members=members, weights=weights
    )
    if len(parts) < 2:
        return made, []
    ideal = unrecognizable_pairs(parts, sensor)
    if made.result.machine.uncertainty.is_ideal:
        return made, ideal
    # The ideal witness explains a pair better (Lemma 8, symmetry) where there is one.
    known = {(w.part_a, w.part_b): w for w in ideal}
    strong = strong_witnesses(made.result.machine, made.result.lumped_pairs)
    return made, [known.get((w.part_a, w.part_b), w) for w in strong]


def landing_members(
    landings: Sequence[Landing],
    accept: Collection[str] | None = None,
    part_shares: Sequence[float] | None = None,
) -> tuple[PlanMember, ...]:
    """The plan members of ``landings`` (design.md, "Landings"; docs/landings.md).

    Each part (in order of first appearance) has its share of the mix (``part_shares``,
    normalised; None: equal), split among its landings by their probabilities (normalised
    over the landings given). ``accept`` holds the landing names (``up``, ``pose-2``) the next
    station takes (None: every landing); a name merged into a landing (``down`` of a
    mirror-symmetric part) accepts that landing. InputError for a share per part that does
    not fit, and for an accepted name that is no landing given.
    """
    parts = list(dict.fromkeys(x.part_name for x in landings))
    if part_shares is None:
        share = {p: 1.0 / len(parts) for p in parts}
    else:
        share = dict(zip(parts, normalised_shares(part_shares, len(parts)), strict=True))
    totals = {p: math.fsum(x.probability for x in landings if x.part_name == p) for p in parts}
    for p, total in totals.items():
        if not total > 0.0:
            raise InputError(f"{p}: its landings have no probability")
    if accept is not None:
        known = {x.name for x in landings} | {m for x in landings for m in x.merged}
        for name in accept:
            if name not in known:
                raise InputError(
                    f"no landing {name} to accept: the landings are {', '.join(sorted(known))}"
                )

    def taken(x: Landing) -> bool:
        return accept is None or x.name in accept or any(m in accept for m in x.merged)

    return tuple(
        PlanMember(
            x.part_name,
            x.name,
            share[x.part_name] * x.probability / totals[x.part_name],
            taken(x),
        )
        for x in landings
    )


def strong_witnesses(
    machine: PushAlignMachine, lumped: Sequence[tuple[int, int]] = ()
) -> list[PairWitness]:
    """Pairs of parts with bisimilar physical states, or states the plan lumps (``lumped``:
    the result's ``lumped_pairs``, near-symmetric states no strong plan resolves), each
    with the ideal member states of those pairs; sorted by part index. No strong plan tells
    them apart."""
    insep = list(search_space(machine).bisimilar)
    for i, j in lumped:
        insep[i] |= 1 << j
        insep[j] |= 1 << i
    found: dict[tuple[int, int], tuple[list[int], list[int]]] = {}
    for k, a in enumerate(machine.states):
        for l_ in members(insep[k]):
            b = machine.states[l_]
            if a.part < b.part:
                sa, sb = found.setdefault((a.part, b.part), ([], []))
                sa.append(a.state)
                sb.append(b.state)
    u = machine.uncertainty
    reason = (
        f"no strong plan tells their resting states apart under rotation error "
        f"{u.rotation_error_deg:g} deg (shape {u.shape_tolerance_mm:g} mm, COM "
        f"{u.com_tolerance_mm:g} mm)"
    )
    names = machine.part_names
    return [
        PairWitness(names[i], names[j], tuple(sa), tuple(sb), reason, "uncertainty")
        for (i, j), (sa, sb) in sorted(found.items())
    ]


def changeover_exists(catalog: str | os.PathLike[str], name: str) -> bool:
    """Whether the catalog stores a changeover called ``name``."""
    return any(c.name == name for c in list_changeovers(catalog))


def stale_revisions(
    catalog: str | os.PathLike[str], revisions: Iterable[tuple[str, int]]
) -> list[str]:
    """One line per part whose pinned revision is older than the catalog's latest."""
    out = []
    for name, rev in revisions:
        latest = get_revision(catalog, name, None).revision
        if latest > rev:
            out.append(
                f"{name}: the changeover is made for revision {rev}, the catalog's latest is "
                f"{latest}; compile it again to plan for the latest"
            )
    return out


def compile_changeover(
    catalog: str | os.PathLike[str],
    name: str,
    members: Sequence[Member],
    sensor: Sensor,
    options: PlanningOptions | None = None,
    *,
    replace: bool = False,
    outputs: Callable[[CompiledChangeover], Iterable[OutputFile]] | None = None,
    uncertainty: Uncertainty | None = None,
    shares: Sequence[float] | None = None,
    landings: str | Sequence[str] | None = None,
    accept: Collection[str] | None = None,
) -> CompiledChangeover:
    """Plan, verify and store the changeover ``name`` for ``members`` (catalog parts).

    ``shares`` are the parts' shares of the mix (normalised; None: equal). ``landings``
    (``"all"`` or landing names) plans every part over its stored landings (docs/landings.md)
    and ``accept`` names the landings the next station takes, the others ending in reject
    results; with neither, each part is planned as stored (its imported outline), as before.
    The changeover's ``parts`` and pairs are then the landings' (named ``PART/LANDING``).

    ``outputs`` gives the files to write with the changeover (its plan file, its report):
    they are written in full before the changeover is stored and put in place inside the
    store's transaction, so either the changeover is stored and its files written, or
    neither. ``uncertainty`` is the declared one (default ``Uncertainty()``). Raises
    InputError for an existing name (unless ``replace``) or bad parts,
    PlanningError when no plan meets the request, CheckFailed when the plan fails
    verification.
    """
    if not replace and changeover_exists(catalog, name):
        raise InputError(f"a changeover named {name!r} already exists")
    loaded = load_parts([_source(m) for m in members], catalog=catalog)
    pfs = list(loaded.push_functions)
    revisions = loaded.revisions  # InputError for a part given as a file
    if landings is None and accept is None:
        made, witnesses = plan_mix(pfs, sensor, options, uncertainty=uncertainty, weights=shares)
    else:
        lands = [
            x
            for (n, r), pf in zip(revisions, pfs, strict=True)
            for x in select_landings(_stored_landings(catalog, n, r, pf), landings or "all")
        ]
        named = landing_members(lands, accept, shares)
        pfs = [push_function(x.part) for x in lands]
        made, pairs = plan_mix(pfs, sensor, options, uncertainty=uncertainty, members=named)
        rejected = {x.label for x, m in zip(lands, named, strict=True) if not m.accept}
        witnesses = [w for w in pairs if not {w.part_a, w.part_b} <= rejected]
    warnings = [*loaded.warnings, *made.warnings, *stale_revisions(catalog, revisions)]
    compiled = CompiledChangeover(
        name, tuple(revisions), tuple(pfs), made, tuple(witnesses), tuple(warnings)
    )
    files = [] if outputs is None else list(outputs(compiled))
    with StagedFiles(files) as staged:
        try:
            save_changeover(
                catalog,
                name,
                revisions,
                sensor.to_dict(),
                plan_json(made.plan),
                replace=replace,
                before_commit=staged.commit,
            )
        except BaseException:
            staged.undo()
            raise
    return compiled


def _stored_landings(
    catalog: str | os.PathLike[str], name: str, revision: int, pf: PushFunction
) -> tuple[Landing, ...]:
    """The landings stored with a revision (computed from its outline when it has none)."""
    return get_revision(catalog, name, revision).landings or landings_of_outline(pf.part)


def load_changeover(catalog: str | os.PathLike[str], name: str) -> StoredChangeover:
    """The stored changeover ``name``: its plan (checked), its parts' exact revisions, and a
    warning per part revised since. InputError when there is none or it is damaged.

    A changeover planned over landings has one part per landing (``PART/LANDING``), rebuilt
    from the revisions' stored landings."""
    co = get_changeover(catalog, name)
    plan = validate_plan(parse_json(co.plan_json, f"changeover {name!r}"), f"changeover {name!r}")
    loaded = load_parts([f"{n}@{r}" for n, r in co.info.parts], catalog=catalog)
    warnings = stale_revisions(catalog, co.info.parts)
    pfs = loaded.push_functions
    if any(p.get("landing") is not None for p in plan["parts"]):
        revs = dict(co.info.parts)
        by_name = {pf.part.name: pf for pf in pfs}
        found = []
        for p in plan["parts"]:
            n, landing = p["name"], p.get("landing")
            if n not in revs or landing is None:
                raise InputError(
                    f"changeover {name!r}: its plan names part {n!r} without a landing"
                )
            lands = _stored_landings(catalog, n, revs[n], by_name[n])
            match = [x for x in lands if x.name == landing]
            if not match:
                raise InputError(
                    f"changeover {name!r}: {n}@{revs[n]} has no landing {landing} any more"
                )
            found.append(push_function(match[0].part))
        pfs = tuple(found)
    return StoredChangeover(co.info, plan, pfs, tuple(warnings))
