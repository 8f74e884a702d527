"""Plan parts over their landings: each landing is one member of a mix (section 8.5).

The paper's multi-part planner orients a product mix and tells its parts apart; the
landings of a part (``up``/``down``, mesh poses) are such members. Each member carries its
prior share (the part's share times the landing's probability, normalised over the landings
planned) and whether the next station takes it: the planners weight the expected length by
the shares and end every set of rejected landings' states in a reject leaf
(:func:`feederkit.plans.make.make_plan`). The plan file (version 2) names part and landing
in every result; :class:`LandingPlan` reads them back as :class:`LandingResult`. Landings
that no plan can tell apart (section 8.4) are reported as the mix's indistinguishable pairs,
and a result leaf then lists several landings. :func:`load_landings` finds the landings of
the sources a command names. docs/landings.md has the details.
"""

from __future__ import annotations

import os
import re
import time
from collections.abc import Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from feederkit.catalog import Revision, default_catalog_path, get_revision, landings_for
from feederkit.errors import InputError
from feederkit.importers import ImportOptions
from feederkit.importers.budget import Budget
from feederkit.importers.reader import MESH_SUFFIXES, import_parts
from feederkit.landing.model import (
    Landing,
    check_landing_name,
    landings_of_outline,
    select_landings,
)
from feederkit.loading import LoadedParts, load_parts
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.mix.changeover import accepted_lumps, checked_landings, plan_landing_members
from feederkit.mix.changeover import landing_members as landing_members  # re-exported
from feederkit.mix.pairs import PairWitness
from feederkit.part import Part
from feederkit.planning.options import PlanningOptions
from feederkit.plans.fileformat import result_nodes
from feederkit.plans.make import MadePlan
from feederkit.plans.model import member_fragile_warnings
from feederkit.sensors import Sensor
from feederkit.uncertainty import Uncertainty

_POSE_INDEX_RE = re.compile(r"0|[1-9][0-9]*")
"""The short form ``K`` of ``pose-K`` (design.md's landing names: no leading zeros)."""


@dataclass(frozen=True)
class LandingResult:
    """One answer of a plan over landings: ``part`` lying in ``landing``, resting in ``state``
    (a stable state of that landing's outline) at ``pose_deg``."""

    part: str
    landing: str
    state: int
    pose_deg: float

    def to_dict(self) -> dict[str, object]:
        """The plan file version 2 result entry (design.md)."""
        return {
            "part": self.part,
            "landing": self.landing,
            "state": self.state,
            "pose_deg": self.pose_deg,
        }


@dataclass(frozen=True)
class LandingLeaf:
    """A result leaf of a plan over landings: its entries, and whether it is a reject leaf
    (every entry a landing the next station cannot take). Iterating gives the entries."""

    results: tuple[LandingResult, ...]
    reject: bool = False

    def __iter__(self) -> Iterator[LandingResult]:
        return iter(self.results)


@dataclass(frozen=True)
class LandingPair:
    """Two landings no plan can tell apart, and the witness of the mix analysis."""

    a: Landing
    b: Landing
    witness: PairWitness


@dataclass(frozen=True)
class LandingPlan:
    """A verified plan over landings, its landings in plan-part order, the pairs of landings
    no plan can tell apart, and the labels (``PART/LANDING``) of the landings it rejects."""

    landings: tuple[Landing, ...]
    made: MadePlan
    indistinguishable: tuple[LandingPair, ...]
    rejected: frozenset[str] = frozenset()

    @property
    def lumped(self) -> list[tuple[str, str]]:
        """Pairs of landings (``PART/LANDING``) an accepting result lists together
        (:func:`feederkit.mix.changeover.accepted_lumps`)."""
        return accepted_lumps(self.made.plan)

    @cached_property
    def _by_name(self) -> dict[tuple[str, str | None], int]:
        """The index of the first landing of each (part, landing) (made once: a large
        plan's results name tens of thousands of entries)."""
        out: dict[tuple[str, str | None], int] = {}
        for k, x in enumerate(self.landings):
            out.setdefault((x.part_name, x.name), k)
        return out

    @cached_property
    def _by_label(self) -> dict[str, int]:
        """The index of the first landing of each label (``PART/LANDING``)."""
        out: dict[str, int] = {}
        for k, x in enumerate(self.landings):
            out.setdefault(x.label, k)
        return out

    def landing_of(self, part: str, landing: str | None = None) -> Landing:
        """The landing ``landing`` of ``part`` (or, with one argument, the one labelled
        ``PART/LANDING``); InputError when the plan has none."""
        # The first landing either way, as a scan of the landings in order would find.
        by_label = self._by_label.get(part) if landing is None else None
        hits = [k for k in (self._by_name.get((part, landing)), by_label) if k is not None]
        if hits:
            return self.landings[min(hits)]
        shown = part if landing is None else f"{part}/{landing}"
        raise InputError(f"the plan has no landing {shown!r}")

    def resolve(self, entry: Mapping[str, object]) -> LandingResult:
        """A plan file result entry (``{"part", "landing", "state", "pose_deg"}``) as the
        part, its landing and its state."""
        landing = entry.get("landing")
        x = self.landing_of(str(entry["part"]), None if landing is None else str(landing))
        return LandingResult(x.part_name, x.name, int(entry["state"]), float(entry["pose_deg"]))

    def leaves(self) -> tuple[LandingLeaf, ...]:
        """Every distinct result leaf of the plan (pre-order) with its entries resolved,
        read off the verified plan file's object (:func:`result_nodes`)."""
        return tuple(
            LandingLeaf(tuple(self.resolve(e) for e in node["result"]), node.get("reject") is True)
            for node in result_nodes(self.made.plan)
        )


def plan_landings(
    landings: Sequence[Landing],
    sensor: Sensor,
    options: PlanningOptions | None = None,
    *,
    uncertainty: Uncertainty | None = None,
    accept: Collection[str] | None = None,
    part_shares: Sequence[float] | None = None,
    started: float | None = None,
) -> LandingPlan:
    """Plan over ``landings`` (of one part, or of several) as the members of one mix.

    :func:`feederkit.mix.changeover.plan_landing_members` makes every landing's part a
    push function for :func:`~feederkit.mix.changeover.plan_mix` (which goes through
    :func:`feederkit.plans.make.make_plan` and verifies the plan), with the shares and
    accept/reject of :func:`~feederkit.mix.changeover.landing_members` (``part_shares``: the
    parts' shares of a mix, None: equal); ``uncertainty`` defaults to design.md's. The
    pairs reported are :func:`~feederkit.mix.changeover.reported_pairs`' (two rejected
    landings need not be told apart; two accepted ones, sides of one part too, are
    reported), the rule ``changeover compile`` follows too. Raises InputError for no
    landings, two with the same label, an accepted name that is no landing, or every landing
    rejected, PlanningError when an accepted and a rejected landing cannot be told apart.
    """
    members = tuple(landings)
    if not members:
        raise InputError("no landings to plan for")
    labels = [x.label for x in members]
    dup = sorted({n for n in labels if labels.count(n) > 1})
    if dup:
        raise InputError(f"landing {dup[0]} is given twice")
    mix = plan_landing_members(
        members,
        sensor,
        options,
        uncertainty=uncertainty,
        accept=accept,
        part_shares=part_shares,
        started=started,
    )
    by_label = {x.label: x for x in members}
    found = tuple(LandingPair(by_label[w.part_a], by_label[w.part_b], w) for w in mix.witnesses)
    return LandingPlan(members, mix.made, found, mix.rejected)


@dataclass(frozen=True)
class LoadedLandings:
    """The parts to plan for (:class:`LoadedParts`) and, per part in the same order, the
    landings selected (design.md, "Landings")."""

    parts: LoadedParts
    landings: tuple[tuple[Landing, ...], ...]
    left_out: tuple[tuple[Landing, ...], ...] = ()
    """Per part, its landings that ``which`` did not select (a part may still land so)."""

    def left_out_words(self, what: str) -> list[str]:
        """:func:`left_out_words` of the landings ``which`` did not select."""
        return left_out_words(self.left_out, what)

    @property
    def all(self) -> tuple[Landing, ...]:
        """Every selected landing of every part, part by part."""
        return tuple(x for lands in self.landings for x in lands)

    @property
    def several(self) -> bool:
        """Whether some part has more than one landing selected."""
        return any(len(lands) > 1 for lands in self.landings)

    def warnings(self, over_landings: bool) -> list[str]:
        """The loading's warnings as a plan names its members: over landings the imports',
        then each landing's fragile states with its own numbers
        (:func:`member_fragile_warnings`: a flat part's face-down side numbers its states
        otherwise), else as loaded."""
        if not over_landings:
            return list(self.parts.warnings)
        members = [(x.part_name, x.name, push_function(x.part)) for x in self.all]
        return [*self.parts.import_warnings, *member_fragile_warnings(members)]


def left_out_words(left_out: Sequence[Sequence[Landing]], what: str) -> list[str]:
    """A line per part that lands in a way ``what`` (e.g. "the plan") leaves out (its
    ``left_out`` landings, per part), with the share of drops that land so: a part landing
    so is not oriented by it."""
    out = []
    for lands in left_out:
        named = [x for x in lands if x.probability > 0.0]
        if not named:
            continue
        ways = ", ".join(
            f"{'in ' if x.name.startswith('pose-') else ''}{x.name} in "
            f"{100.0 * x.probability:.3g} %"
            for x in named
        )
        out.append(
            f"{named[0].part_name} also lands {ways} of drops, which {what} leaves out "
            "(--landings): a part landing so is not oriented by it (to plan every landing "
            "and reject some, name the ones the next station takes with --accept)"
        )
    return out


def landing_names(text: str, what: str = "--landings") -> tuple[str, ...]:
    """Landing names from ``LANDING,...`` (``up``, ``down``, ``pose-K`` or ``K`` for
    ``pose-K``); InputError naming ``what`` for an empty list or a name that is no landing."""
    names = []
    for item in text.split(","):
        item = item.strip()
        if not item:
            raise InputError(f"{what}: an empty landing name in {text!r}")
        name = f"pose-{item}" if _POSE_INDEX_RE.fullmatch(item) else item
        try:
            check_landing_name(name)
        except InputError as exc:
            raise InputError(f"{what}: {exc}") from None
        if name not in names:
            names.append(name)
    return tuple(names)


def _landings_of(
    source: str,
    pf: PushFunction,
    catalog: str | None,
    options: ImportOptions | None,
) -> tuple[Landing, ...]:
    """The landings of the part loaded from ``source``: a catalog part's stored ones (computed
    from its outline for a revision stored before landings), ``up`` and ``down`` of an
    outline or DXF file (one when the sides are congruent), every resting pose of a mesh."""
    path = Path(source)
    if path.is_file():
        opts = options or ImportOptions()
        if path.suffix.lower() not in MESH_SUFFIXES:
            return landings_of_outline(pf.part, check=Budget(opts.limits, source).check_time)
        _, imported = import_parts(path, opts)
        same = [x for x in imported if x.part.name == pf.part.name]
        return landings_for((same or imported)[0], opts, path)
    db = Path(catalog) if catalog is not None else default_catalog_path()
    revision = None if pf.part.revision is None else int(pf.part.revision)
    return revision_landings(get_revision(db, pf.part.name, revision), pf.part)


def revision_landings(rev: Revision, part: Part) -> tuple[Landing, ...]:
    """A catalog revision's landings: the stored ones, or those of ``part`` (the revision's
    part) computed from its outline for a revision stored before landings."""
    return rev.landings or landings_of_outline(part)


def load_landings(
    sources: Sequence[str],
    *,
    catalog: str | os.PathLike[str] | None = None,
    options: ImportOptions | None = None,
    which: str | Sequence[str] = "all",
) -> LoadedLandings:
    """Load the parts of ``sources`` (:func:`load_parts`) with their landings, ``which``
    selecting them (``"all"`` or landing names, :func:`feederkit.landing.select_landings`).

    Raises InputError as :func:`load_parts` does, for a landing a part does not have, and
    for a selected landing that pushing cannot orient (a mesh pose on a round face).
    """
    started = time.monotonic()
    loaded = load_parts(sources, catalog=catalog, options=options)
    db = None if catalog is None else str(Path(catalog))
    opts = (options or ImportOptions()).counting_from(started)
    every = [
        _landings_of(source, pf, db, opts)
        for source, pf in zip(loaded.origins, loaded.push_functions, strict=True)
    ]
    per_part = [
        checked_landings(source, select_landings(lands, which))
        for source, lands in zip(loaded.origins, every, strict=True)
    ]
    left = [
        tuple(x for x in lands if x.name not in {c.name for c in chosen})
        for lands, chosen in zip(every, per_part, strict=True)
    ]
    return LoadedLandings(loaded, tuple(per_part), tuple(left))
