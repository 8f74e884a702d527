"""Changeovers: one verified plan for a product mix, stored in the catalog against the parts'
exact revisions (section 8.5; docs/changeovers.md). The command line and the demo call this.

A changeover's plan orients every part of the mix; it recognizes every part except the pairs
that no plan can tell apart (section 8.4, Corollary 7), whose results list each candidate.
The plan is made for the revisions it names: a part revised later does not change it, and
:func:`stale_revisions` says when a newer revision exists.

Plans cover every landing of every part unless told otherwise (design.md, "Landings"): each
landing is one member of the mix. :func:`plan_landing_members` is the one place that plans
landings and decides which pairs of them are reported (shared with ``feederkit plan``
through :func:`feederkit.landing.plan.plan_landings`; docs/landings.md).
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable, Collection, Iterable, Mapping, Sequence
from contextlib import closing
from dataclasses import dataclass
from typing import Any

from feederkit.catalog import (
    DEFAULT_WAIT,
    ChangeoverInfo,
    Revision,
    get_changeover,
    get_revision,
    list_changeovers,
    name_key,
    open_catalog,
    revision_stamps,
    save_changeover,
)
from feederkit.errors import InputError
from feederkit.importers.orientable import orientability
from feederkit.jsonio import OutputFile, StagedFiles
from feederkit.landing.model import Landing, landings_of_outline, select_landings
from feederkit.loading import LoadedParts, load_parts
from feederkit.machine import PushAlignMachine, members, search_space
from feederkit.machine.weights import normalised_shares
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.mix.pairs import PairWitness, unrecognizable_pairs
from feederkit.planning.options import PlanningOptions
from feederkit.plans.make import MadePlan, make_plan
from feederkit.plans.model import Plan, PlanMember, member_fragile_warnings
from feederkit.plans.model import member_name as member_name  # its home: plans.model
from feederkit.plans.readplan import as_plan, parse_plan_text, validate_plan
from feederkit.plans.writeplan import read_back
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
    rejected: frozenset[str] = frozenset()
    """The landings (``PART/LANDING``) the next station does not take: reject results."""
    view: Plan | None = None
    """The plan as stored, checked by the loader's validator (:func:`read_back`) before it
    was stored: what the command shows, without checking it again."""

    @property
    def plan(self) -> dict[str, Any]:
        """The plan file's object."""
        return self.made.plan

    @property
    def lumped(self) -> list[tuple[str, str]]:
        """Pairs of members that some accepting result of the plan lists together
        (:func:`accepted_lumps`)."""
        return accepted_lumps(self.made.plan if self.view is None else self.view)


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

    @property
    def rejected(self) -> frozenset[str]:
        """The landings (``PART/LANDING``) its plan rejects (:func:`rejected_members`)."""
        return rejected_members(self.plan)

    def witnesses(self) -> list[PairWitness]:
        """The pairs of its parts (or landings) the stored plan cannot tell apart, as
        ``changeover compile`` reported them (:func:`stored_witnesses`): what ``show``,
        ``list`` and ``report`` say."""
        if len(self.parts) < 2:
            return []
        return stored_witnesses(self.plan, list(self.parts), self.sensor)


def stored_witnesses(
    plan: Mapping[str, Any], parts: Sequence[PushFunction], sensor: Sensor
) -> list[PairWitness]:
    """The pairs of members a stored plan cannot tell apart, with their witnesses.

    On the ideal model (no uncertainty declared, or all zero) they are decided again exactly
    (section 8.4, :func:`reported_pairs`), as compile decided them. Under a declared
    uncertainty compile's pairs are those of the strong machine's search, which a stored plan
    does not keep; they are the pairs its accepting results list together
    (:func:`accepted_lumps`), each with the ideal witness where there is one (it explains the
    pair better), else the states the results list together and compile's reason
    (:func:`uncertainty_reason`)."""
    ideal = reported_pairs(unrecognizable_pairs(list(parts), sensor), rejected_members(plan))
    declared = plan.get("uncertainty")
    unc = Uncertainty.from_dict(declared) if declared else None
    if unc is None or unc.is_ideal:
        return ideal
    known = {(w.part_a, w.part_b): w for w in ideal}
    lumped = accepted_lumps(plan)
    index = {pf.part.name: k for k, pf in enumerate(parts)}
    out = [known.get(ab) or _lumped_witness(plan, ab, unc, index) for ab in lumped]
    return out + [w for w in ideal if (w.part_a, w.part_b) not in set(lumped)]


def _lumped_witness(
    plan: Mapping[str, Any], pair: tuple[str, str], unc: Uncertainty, index: Mapping[str, int]
) -> PairWitness:
    """The witness of two members an accepting result of ``plan`` lists together: each pair
    of their states some such result lists, with compile's reason under ``unc``."""
    a, b = pair
    found: set[tuple[int, int]] = set()
    for leaf in as_plan(plan).leaves():
        if leaf.reject:
            continue
        named = [(member_name(e.part, e.landing), e.state) for e in leaf.results]
        for m, i in named:
            for n, j in named:
                if m == a and n == b:
                    found.add((i, j))
    states_a = tuple(i for i, _ in sorted(found))
    states_b = tuple(j for _, j in sorted(found))
    return PairWitness(
        a, b, states_a, states_b, uncertainty_reason(unc), "uncertainty", index[a], index[b]
    )


def uncertainty_reason(unc: Uncertainty) -> str:
    """Why no strong plan tells two members apart under ``unc``, in compile's words."""
    return (
        f"no strong plan tells their resting states apart under rotation error "
        f"{unc.rotation_error_deg:g} deg (shape {unc.shape_tolerance_mm:g} mm, COM "
        f"{unc.com_tolerance_mm:g} mm)"
    )


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
    started: float | None = None,
) -> tuple[MadePlan, list[PairWitness]]:
    """A verified plan for one part or a mix (section 8.5), and the pairs of parts no plan
    can tell apart (section 8.4), each with its witness.

    ``uncertainty`` defaults to design.md's ``Uncertainty()``. ``members`` name the parts in
    the plan file with their landings, prior shares and accept/reject
    (:class:`~feederkit.plans.model.PlanMember`; None: as the parts are, equal shares);
    ``weights`` give the parts' prior shares alone (a product mix's, normalised);
    ``started`` the instant the time limit counts from (:func:`~feederkit.plans.make.make_plan`,
    None: now). On the ideal model the pairs are the exact analysis of
    :mod:`feederkit.mix.pairs`; under uncertainty they are the cross pairs of the strong
    machine's bisimilar states, the relation the planner's results use. Pairs name the parts
    as ``parts`` do.
    """
    made = make_plan(
        parts,
        sensor,
        options,
        uncertainty=uncertainty,
        members=members,
        weights=weights,
        started=started,
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


def reported_pairs(
    pairs: Iterable[PairWitness], rejected: Collection[str] = ()
) -> list[PairWitness]:
    """The pairs of members no plan can tell apart that a plan must report (exit 1).

    The one rule for plans over landings (design.md, "Landings"; docs/landings.md), used by
    ``plan``, ``changeover compile`` and the changeover commands alike; members are named
    :func:`member_name`-wise, ``rejected`` names the landings the next station does not take:

    * two **rejected** landings need not be told apart: both end in a reject result and the
      controller recirculates the part either way, so the pair is left out;
    * an **accepted and a rejected** landing that no plan tells apart leave no plan at all
      (:func:`feederkit.plans.make.make_plan` raises PlanningError before planning);
    * two **accepted** landings are reported like two parts of a mix (section 8.4), also
      when they are the two sides of one part: the result then lists both landings, each
      with its state and pose, so the controller knows the part but neither its side nor
      the pose it lies in; the plan is still a correct plan, but the next station cannot
      take the part as it is, which is a result the user must act on (a finer sensor, or
      re-dropping the part).
    """
    return [w for w in pairs if not {w.part_a, w.part_b} <= set(rejected)]


def accepted_lumps(plan: Plan | Mapping[str, Any]) -> list[tuple[str, str]]:
    """Pairs of members (:func:`member_name`) that an accepting result of ``plan`` lists
    together, each pair once in the plan's part order. A reject result may list several
    rejected landings: that lumps nothing (:func:`reported_pairs`). Given the file's object,
    it is read first (2 s for a 20-part mix's 16 MB plan)."""
    checked = as_plan(plan)
    order = {member_name(p.name, p.landing): k for k, p in enumerate(checked.parts)}
    pairs: set[tuple[str, str]] = set()
    for leaf in checked.leaves():
        if leaf.reject:
            continue
        names = sorted(
            {member_name(e.part, e.landing) for e in leaf.results}, key=order.__getitem__
        )
        pairs.update((a, b) for i, a in enumerate(names) for b in names[i + 1 :])
    return sorted(pairs, key=lambda ab: (order[ab[0]], order[ab[1]]))


def rejected_members(plan: Plan | Mapping[str, Any]) -> frozenset[str]:
    """The landings (``PART/LANDING``) a plan file rejects: those its reject results name.

    The plan file keeps no accept flag per member; a rejected landing's states end in reject
    results only, and an accepted landing's never do (:func:`reported_pairs`)."""
    return frozenset(
        member_name(e.part, e.landing)
        for leaf in as_plan(plan).leaves()
        if leaf.reject
        for e in leaf.results
    )


def landing_rows(plan: Mapping[str, Any], rejected: Collection[str]) -> list[dict[str, Any]]:
    """The landings a plan over landings covers, in plan order (none for a plan of parts):
    ``part``, ``landing``, ``share`` (the plan file's) and ``accept`` (``rejected`` names
    the landings the next station does not take, ``PART/LANDING``)."""
    return [
        {
            "part": p["name"],
            "landing": p["landing"],
            "share": p.get("share"),
            "accept": member_name(p["name"], p["landing"]) not in rejected,
        }
        for p in plan.get("parts", [])
        if p.get("landing") is not None
    ]


def plans_over_landings(
    per_part: Sequence[Sequence[Landing]], landings_given: bool, accept_given: bool
) -> bool:
    """Whether a plan for parts with the landings ``per_part`` is made over landings.

    design.md: "plans cover every landing unless told otherwise". When every part has one
    landing (mirror-symmetric outlines) and neither the landings nor the accepted ones are
    given, the plan over landings would be the plan of the parts themselves, so it is made
    and written exactly so (no landing keys, as before landings existed); otherwise it is
    made over landings, its parts and results naming them."""
    return landings_given or accept_given or any(len(lands) > 1 for lands in per_part)


def checked_landings(source: str, landings: Sequence[Landing]) -> tuple[Landing, ...]:
    """``landings`` when pushing can orient each one. InputError for a mesh pose on a round
    face, pointing to ``--landings``."""
    for x in landings:
        if not x.name.startswith("pose-"):
            continue
        verdict = orientability(x.part, None)
        if not verdict.orientable:
            raise InputError(
                f"{source}: landing {x.name} is not orientable by pushing: "
                f"{verdict.reason}; choose the landings to plan with --landings"
            )
    return tuple(landings)


@dataclass(frozen=True)
class LandingMix:
    """A verified plan over landings: the landings' push functions and plan members (in plan
    part order), the plan, and the pairs of landings it reports (:func:`reported_pairs`)."""

    parts: tuple[PushFunction, ...]
    members: tuple[PlanMember, ...]
    made: MadePlan
    witnesses: tuple[PairWitness, ...]

    @property
    def rejected(self) -> frozenset[str]:
        """The landings (``PART/LANDING``) the plan rejects."""
        return frozenset(
            pf.part.name for pf, m in zip(self.parts, self.members, strict=True) if not m.accept
        )


def plan_landing_members(
    landings: Sequence[Landing],
    sensor: Sensor,
    options: PlanningOptions | None = None,
    *,
    uncertainty: Uncertainty | None = None,
    accept: Collection[str] | None = None,
    part_shares: Sequence[float] | None = None,
    started: float | None = None,
) -> LandingMix:
    """Plan over ``landings`` (of one part or of several) as the members of one mix
    (section 8.5): their shares and accept/reject from :func:`landing_members`, the plan
    from :func:`plan_mix` (verified), the pairs no plan tells apart as
    :func:`reported_pairs` reports them. The one path of ``plan`` and ``changeover
    compile`` over landings. Raises as :func:`landing_members` and :func:`plan_mix` do."""
    named = landing_members(landings, accept, part_shares)
    pfs = tuple(push_function(x.part) for x in landings)
    made, pairs = plan_mix(
        list(pfs), sensor, options, uncertainty=uncertainty, members=named, started=started
    )
    rejected = {x.label for x, m in zip(landings, named, strict=True) if not m.accept}
    return LandingMix(pfs, named, made, tuple(reported_pairs(pairs, rejected)))


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
    reason = uncertainty_reason(machine.uncertainty)
    names = machine.part_names
    return [
        PairWitness(names[i], names[j], tuple(sa), tuple(sb), reason, "uncertainty")
        for (i, j), (sa, sb) in sorted(found.items())
    ]


def changeover_exists(catalog: str | os.PathLike[str], name: str) -> bool:
    """Whether the catalog stores a changeover called ``name`` (as typed or in NFC)."""
    names = {name, name_key(name)}
    return any(c.name in names for c in list_changeovers(catalog))


def stale_revisions(
    catalog: str | os.PathLike[str], revisions: Iterable[tuple[str, int]]
) -> list[str]:
    """One line per part whose pinned revision is older than the catalog's latest, or whose
    latest revision the catalog cannot read (the catalog's own words: a damaged row must not
    hide the other changeovers of a listing)."""
    out = []
    for name, rev in revisions:
        try:
            newest = get_revision(catalog, name, None)
            latest = newest.revision
            if latest > rev and _same_contents(newest, get_revision(catalog, name, rev)):
                continue  # the same file again (a revision put back): the plan is its plan
        except InputError as exc:
            out.append(f"{name}: {exc}")
            continue
        if latest > rev:
            out.append(
                f"{name}: the changeover is made for revision {rev}, the catalog's latest is "
                f"{latest}; compile it again to plan for the latest"
            )
    return out


def _same_contents(a: Revision, b: Revision) -> bool:
    """Whether two revisions of a part store the same part: the same file's bytes, import
    options and tolerances (the outline, hull, COM and landings follow from them)."""
    return (
        a.source_sha256 == b.source_sha256
        and dict(a.options) == dict(b.options)
        and a.shape_tolerance_mm == b.shape_tolerance_mm
        and a.com_tolerance_mm == b.com_tolerance_mm
    )


def mix_landings(
    catalog: str | os.PathLike[str],
    loaded: LoadedParts,
    landings: str | Sequence[str] | None = None,
) -> list[tuple[Landing, ...]]:
    """The landings planned for each of the ``loaded`` catalog parts: their revisions' stored
    landings, those named in ``landings`` (None: all). InputError for a part given as a file,
    a landing a part does not have, or a mesh pose that pushing cannot orient."""
    return [
        checked_landings(
            f"{n}@{r}", select_landings(_stored_landings(catalog, n, r, pf), landings or "all")
        )
        for (n, r), pf in zip(loaded.revisions, loaded.push_functions, strict=True)
    ]


def left_out_landings(
    catalog: str | os.PathLike[str],
    loaded: LoadedParts,
    landings: str | Sequence[str] | None = None,
) -> list[tuple[Landing, ...]]:
    """Per loaded catalog part, its stored landings that ``landings`` (None: all) does not
    name: the ways it lands that a changeover of those landings leaves out."""
    if landings in (None, "all"):
        return []
    out = []
    for (n, r), pf in zip(loaded.revisions, loaded.push_functions, strict=True):
        every = _stored_landings(catalog, n, r, pf)
        chosen = {x.name for x in select_landings(every, landings)}
        out.append(tuple(x for x in every if x.name not in chosen))
    return out


def compile_changeover(
    catalog: str | os.PathLike[str],
    name: str,
    members: Sequence[Member],
    sensor: Sensor,
    options: PlanningOptions | None = None,
    *,
    replace: bool = False,
    outputs: Callable[[CompiledChangeover, str], Iterable[OutputFile]] | None = None,
    prepare: Callable[[MadePlan], object] | None = None,
    uncertainty: Uncertainty | None = None,
    shares: Sequence[float] | None = None,
    landings: str | Sequence[str] | None = None,
    accept: Collection[str] | None = None,
    loaded: LoadedParts | None = None,
    started: float | None = None,
    on_stored: Callable[[], None] | None = None,
    wait: float = DEFAULT_WAIT,
) -> CompiledChangeover:
    """Plan, verify and store the changeover ``name`` for ``members`` (catalog parts).

    Every landing of every part is planned for (design.md, "Landings"; docs/landings.md):
    the revisions' stored landings, each one member of the mix, named ``PART/LANDING`` in
    the changeover's ``parts`` and pairs. ``landings`` (``"all"`` or landing names, e.g.
    ``("up",)``) picks them for every part; ``accept`` names the landings the next station
    takes, the others ending in reject results. With neither, a mix whose parts have one
    landing each (mirror-symmetric outlines) is planned as its parts, exactly as before
    landings (:func:`plans_over_landings`). ``shares`` are the parts' shares of the mix
    (normalised; None: equal), split among a part's landings by their probabilities.

    ``prepare`` is called on the made plan before its file is made (e.g. to put the cycle
    time in it: :func:`~feederkit.cell.annotate_cycle_time`); the file's text is then made
    and read back once (:func:`read_back`: 2 s for a 20-part mix's 16 MB plan). ``outputs``
    gives, from the changeover (its ``view`` set) and that text, the files to write with it
    (its plan file, its report): they are written in full before the changeover is stored
    and put in place inside the store's transaction, so either the changeover is stored and
    its files written, or neither. ``uncertainty`` is the declared one (default
    ``Uncertainty()``); ``loaded`` the members as the caller loaded them
    (:func:`load_parts`), e.g. to declare the tolerances their revisions store
    (:func:`feederkit.catalog.declared_tolerances`); ``started`` the instant the time limit
    counts from (:func:`~feederkit.plans.make.make_plan`);
    ``on_stored`` is called once the changeover and its files are in place, also when an
    interrupt comes after that (it then goes on up: the caller can say what was done);
    ``wait`` the seconds the store waits while another process writes the catalog.
    Raises InputError for an existing name (unless ``replace``), bad parts, a landing a part does
    not have or an accepted name no landing has, PlanningError when no plan meets the
    request (an accepted and a rejected landing no plan tells apart), CheckFailed when the
    plan fails verification.
    """
    if loaded is None:
        loaded = load_parts([_source(m) for m in members], catalog=catalog)
    pfs = list(loaded.push_functions)
    revisions = loaded.revisions  # InputError for a part given as a file
    stamps = revision_stamps(catalog, revisions)  # what the plan is made from
    per_part = mix_landings(catalog, loaded, landings)
    if not replace and changeover_exists(catalog, name):  # after every input is checked
        raise InputError(f"a changeover named {name!r} already exists")
    rejected: frozenset[str] = frozenset()
    if plans_over_landings(per_part, landings is not None, accept is not None):
        mix = plan_landing_members(
            [x for lands in per_part for x in lands],
            sensor,
            options,
            uncertainty=uncertainty,
            accept=accept,
            part_shares=shares,
            started=started,
        )
        pfs, made, witnesses, rejected = list(mix.parts), mix.made, mix.witnesses, mix.rejected
        # Fragile states named per landing, with the landing's own numbers (as plan says).
        landed = [(m.name, m.landing, pf) for m, pf in zip(mix.members, mix.parts, strict=True)]
        warnings = [*loaded.import_warnings, *member_fragile_warnings(landed)]
    else:
        made, pairs = plan_mix(
            pfs, sensor, options, uncertainty=uncertainty, weights=shares, started=started
        )
        witnesses = tuple(pairs)
        warnings = list(loaded.warnings)
    warnings += [*made.warnings, *stale_revisions(catalog, revisions)]
    compiled = CompiledChangeover(
        name, tuple(revisions), tuple(pfs), made, tuple(witnesses), tuple(warnings), rejected
    )
    if prepare is not None:
        prepare(made)
    text, view = read_back(made.plan)
    compiled = dataclasses.replace(compiled, view=view)
    files = [] if outputs is None else list(outputs(compiled, text))
    with StagedFiles(files) as staged, closing(open_catalog(catalog, wait=wait)) as conn:
        try:
            save_changeover(
                conn,
                name,
                revisions,
                sensor.to_dict(),
                text,
                replace=replace,
                before_commit=staged.commit,
                stamps=stamps,
            )
        except BaseException:
            # An interrupt after the COMMIT (leaving the catalog's context) must not take the
            # files of a stored changeover away: the catalog says whether it holds this plan.
            if not (staged.committed and _stored_as(catalog, name, text)):
                staged.undo()
            elif on_stored is not None:
                on_stored()
            raise
    if on_stored is not None:
        on_stored()
    return compiled


def _stored_as(catalog: str | os.PathLike[str], name: str, text: str) -> bool:
    """Whether the catalog holds the changeover ``name`` with the plan JSON ``text``."""
    try:
        return get_changeover(catalog, name).plan_json == text
    except InputError:
        return False


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
    where = f"changeover {name!r}"
    plan = validate_plan(parse_plan_text(co.plan_json, where), where)
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
