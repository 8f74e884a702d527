"""Changeovers: one verified plan for a product mix, stored in the catalog against the parts'
exact revisions (section 8.5; docs/changeovers.md). The command line and the demo call this.

A changeover's plan orients every part of the mix; it recognizes every part except the pairs
that no plan can tell apart (section 8.4, Corollary 7), whose results list each candidate.
The plan is made for the revisions it names: a part revised later does not change it, and
:func:`stale_revisions` says when a newer revision exists.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Sequence
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
from feederkit.loading import load_parts
from feederkit.machine import PushAlignMachine, members, search_space
from feederkit.mechanics.push import PushFunction
from feederkit.mix.pairs import PairWitness, unrecognizable_pairs
from feederkit.planning.options import PlanningOptions
from feederkit.plans.fileformat import plan_json, validate_plan
from feederkit.plans.make import MadePlan, make_plan
from feederkit.plans.match import leaf_part_pairs
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
) -> tuple[MadePlan, list[PairWitness]]:
    """A verified plan for one part or a mix (section 8.5), and the pairs of parts no plan
    can tell apart (section 8.4), each with its witness.

    ``uncertainty`` defaults to design.md's ``Uncertainty()``. On the ideal model the pairs
    are the exact analysis of :mod:`feederkit.mix.pairs`; under uncertainty they are the
    cross pairs of the strong machine's inseparable (bisimilar) states, the relation the
    planner's results use.
    """
    made = make_plan(parts, sensor, options, uncertainty=uncertainty)
    if len(parts) < 2:
        return made, []
    ideal = unrecognizable_pairs(parts, sensor)
    if made.result.machine.uncertainty.is_ideal:
        return made, ideal
    # The ideal witness explains a pair better (Lemma 8, symmetry) where there is one.
    known = {(w.part_a, w.part_b): w for w in ideal}
    strong = strong_witnesses(made.result.machine)
    return made, [known.get((w.part_a, w.part_b), w) for w in strong]


def strong_witnesses(machine: PushAlignMachine) -> list[PairWitness]:
    """Pairs of parts with bisimilar physical states (no strong plan tells them apart),
    each with the ideal member states of those pairs; sorted by part index."""
    insep = search_space(machine).inseparable
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
        f"their resting states stay alike for every outcome under rotation error "
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
) -> CompiledChangeover:
    """Plan, verify and store the changeover ``name`` for ``members`` (catalog parts).

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
    made, witnesses = plan_mix(pfs, sensor, options, uncertainty=uncertainty)
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


def load_changeover(catalog: str | os.PathLike[str], name: str) -> StoredChangeover:
    """The stored changeover ``name``: its plan (checked), its parts' exact revisions, and a
    warning per part revised since. InputError when there is none or it is damaged."""
    co = get_changeover(catalog, name)
    plan = validate_plan(parse_json(co.plan_json, f"changeover {name!r}"), f"changeover {name!r}")
    loaded = load_parts([f"{n}@{r}" for n, r in co.info.parts], catalog=catalog)
    warnings = stale_revisions(catalog, co.info.parts)
    return StoredChangeover(co.info, plan, loaded.push_functions, tuple(warnings))
