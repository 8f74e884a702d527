"""A plan's parts simulated on their own outlines (``feederkit simulate PLAN --part SOURCE``).

A plan file carries each part's contact hull as import simplified it (chords across arcs,
``--hull-tolerance``), and ``simulate`` by default simulates that hull: it cannot catch a plan
that is right for the model and wrong for the real part. Here a member's physics uses the part
a SOURCE holds (an outline or CAD file, or a catalog name, loaded as every command loads one:
:mod:`feederkit.sources`, :mod:`feederkit.landing.plan`): the exact convex hull of its outline
(no simplification, arcs of a drawing flattened finely) and its own COM, while the plan runs as
before. Where such a part rests is judged by angle (:class:`feederkit.sim.trial.PoseRule`).

A SOURCE must be the plan's part: its exact hull within the plan's shape tolerance, plus the
hull tolerance of the plan's import, plus :data:`MATCH_SLACK_MM`, of the plan's hull (their
Hausdorff distance: for convex regions the largest difference of their radius functions, what
the fence feels), and its COM within the COM tolerance plus the slack; anything else is bad
input naming the distance (docs/simulation.md, "A part's own outline"). The hull tolerance is
``--hull-tolerance`` when given, else the one stored with the catalog revision the plan's
member was made from (:func:`plan_drawing`: the plan's revision, or a catalog SOURCE's, whose
stored hull is the plan's), else a CAD import's default. A hull beyond the declared shape
tolerance plus the slack, though within the allowance, is simulated with a warning that says
how much of the distance is the import's simplification of the hull: the plan is guaranteed
only within its declared tolerance.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from feederkit.catalog import could_be_part_name, default_catalog_path, get_revision
from feederkit.catalog import part_from_revision as revision_part
from feederkit.errors import InputError
from feederkit.hull import hull_distance
from feederkit.importers import ImportOptions
from feederkit.importers.model import CAD_SUFFIXES, DEFAULT_FLATTEN_TOLERANCE
from feederkit.importers.reader import effective_hull_tolerance
from feederkit.landing import DOWN, UP, landings_of_outline, mirror_part
from feederkit.mechanics.analysis import FRAGILE_BARRIER_REL
from feederkit.mechanics.uncertain import uncertain_mechanics
from feederkit.part import Part, make_part
from feederkit.plans.model import Plan, PlanPart
from feederkit.sim.likeness import refusal_words
from feederkit.sim.pushalign import SettleRule
from feederkit.sources import load_part
from feederkit.uncertainty import IDEAL

Point = tuple[float, float]

MATCH_SLACK_MM = DEFAULT_FLATTEN_TOLERANCE
"""Slack (mm) of the match check beyond the plan's tolerances: the largest distance between a
drawing's arc and the chords the import flattens it into (a plan made from the drawing and a
SOURCE of the true outline differ by that much where nothing else differs)."""

MATCH_REL_SLACK = 1e-6
"""Slack of the match check as a fraction of the part's size (rounding in the plan file)."""

FINE_FLATTEN_REL = 1e-5
"""A drawing SOURCE's curves are flattened to this fraction of the plan part's size (0.3 um on
a 30 mm part): chords 0.01 mm deep (the import's default) are wells MuJoCo holds a part in where
the drawn arc rolls it on."""

REAL_SETTLE_RULE = SettleRule(window_sizes=1.0, drift_tol_deg=0.5, max_travel_sizes=60.0)
"""When a part on its own outline has settled (:class:`~feederkit.sim.pushalign.PushAligner`'s
``rests``): still (its mean orientation drifting less than 0.5 degree over a part size of belt
travel: on a gentle arc it jitters by a degree or two) within 1 degree of where it lies lowest,
or anywhere in a resting range after 60 part sizes of belt travel (it creeps down a gentle arc
for tens of part sizes); read where it rests, the window's second half (``SettleRule.reading``:
the window may begin with the end of its turn onto the rest). Measured in docs/simulation.md."""


@dataclass(frozen=True)
class PlanDrawing:
    """The catalog revision a plan member was made from (:func:`plan_drawing`): ``where``
    names it (``NAME@REV in DB``), ``hull_tolerance_mm`` is the hull tolerance stored with it
    (0: an exact hull), and ``part`` its drawing: the exact hull of its outline and its COM,
    as the member lies (its landing)."""

    where: str
    hull_tolerance_mm: float
    part: Part


@dataclass(frozen=True)
class HullAllowance:
    """The hull tolerance the match check allows for the plan's import, and whence:
    ``--hull-tolerance``, a catalog revision (``drawing``), or a CAD import's default."""

    mm: float
    drawing: PlanDrawing | None = None
    given: bool = False

    def words(self) -> str:
        """Whence the hull tolerance, in a few words."""
        if self.given:
            return "given with --hull-tolerance"
        if self.drawing is not None:
            return f"stored with {self.drawing.where}"
        return (
            "the default a CAD import takes for the part's size: the plan does not say how "
            "its hull was made"
        )


@dataclass(frozen=True)
class RealPart:
    """A plan member simulated on the part a SOURCE holds.

    ``member`` is its index in the plan's parts, ``label`` its name in words (``NAME`` or
    ``NAME (LANDING)``); ``part`` the part with the exact hull of its outline and its own COM;
    ``rests`` where its outline rests (:func:`resting_ranges`: where it settles);
    ``hull_distance_mm`` the Hausdorff distance between its hull and the plan's, ``allowed_mm``
    the most the match check allows; likewise the COM. ``shape_tolerance_mm`` is the plan's
    declared shape tolerance and ``slack_mm`` the match check's slack: a distance beyond
    both is accepted but warned of (:meth:`tolerance_warning`), naming ``certified_mm``, the
    shape tolerance the plan's certificate holds (None: no certificate). ``hull`` is the
    hull tolerance allowed for the plan's import; with its catalog revision known,
    ``simplified_mm`` is how far the plan's hull lies from that revision's drawing (the
    import's simplification) and ``drawing_distance_mm`` how far the part's hull does.
    """

    member: int
    label: str
    source: str
    part: Part
    rests: tuple[tuple[float, float, float], ...]
    hull_distance_mm: float
    allowed_mm: float
    com_distance_mm: float
    allowed_com_mm: float
    shape_tolerance_mm: float = 0.0
    slack_mm: float = 0.0
    certified_mm: float | None = None
    hull: HullAllowance = HullAllowance(0.0)
    simplified_mm: float | None = None
    drawing_distance_mm: float | None = None

    @property
    def beyond_tolerance(self) -> bool:
        """Whether its hull lies farther from the plan's than the plan's declared shape
        tolerance, more than the slack of a drawing's flattening."""
        return self.hull_distance_mm > self.shape_tolerance_mm + self.slack_mm

    def tolerance_warning(self) -> str | None:
        """One line when the part lies beyond the plan's declared shape tolerance
        (:attr:`beyond_tolerance`); None otherwise."""
        if not self.beyond_tolerance:
            return None
        held = (
            ""
            if self.certified_mm is None
            else f" (its certificate's largest shape tolerance: {self.certified_mm:.4g} mm)"
        )
        return (
            f"{self.label}: {self.source}'s hull lies {self.hull_distance_mm:.4g} mm from the "
            f"plan's hull, beyond the plan's declared shape tolerance of "
            f"{self.shape_tolerance_mm:g} mm: the plan is guaranteed only within its declared "
            f"tolerance{held}; simulated anyway, as up to {self.allowed_mm:.4g} mm is accepted "
            f"for a plan whose hull may simplify a drawing: {self.simplification_words()}"
        )

    def simplification_words(self) -> str:
        """How much of the allowed distance is the hull simplification of the plan's import:
        measured against its catalog revision's drawing when known, else the most it may be."""
        h = self.hull
        if self.simplified_mm is None or h.drawing is None:
            # A default is a guess: the plan file does not record the hull tolerance its
            # import used (an import lowers it where arcs need it), so "up to".
            amount = f"{h.mm:g} mm of it is" if h.given else f"up to {h.mm:g} mm of it may be"
            return (
                f"{amount} the hull tolerance of the plan's import ({h.words()}), "
                f"not a tolerance the plan declares, so the part may lie up to "
                f"{self.allowed_mm - self.slack_mm:.4g} mm from its drawing unnoticed"
            )
        whence = "given with --hull-tolerance" if h.given else "stored with it"
        return (
            f"the plan's hull simplifies the drawing of {h.drawing.where} by "
            f"{self.simplified_mm:.4g} mm (hull tolerance {h.mm:g} mm, {whence}), and "
            f"{self.source}'s hull lies {self.drawing_distance_mm:.4g} mm from that drawing"
        )

    def words(self) -> str:
        """The geometry simulated, in one line."""
        cx, cy = (round(c, 4) + 0.0 for c in self.part.com)  # no -0 nor 1e-16
        return (
            f"{self.label}: its own outline from {self.source} (exact hull, "
            f"{len(self.part.hull)} vertices, COM ({cx:g}, {cy:g})); "
            f"{self.hull_distance_mm:.4g} mm from the plan's hull ({self.allowed_mm:.4g} allowed)"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON-ready form (``--json``'s ``geometry`` entries)."""
        return {
            "part": self.label,
            "simulated": "outline",
            "source": self.source,
            "hull_vertices": len(self.part.hull),
            "com": [round(c, 6) + 0.0 for c in self.part.com],
            "hull_distance_mm": round(self.hull_distance_mm, 6),
            "allowed_mm": round(self.allowed_mm, 6),
            "com_distance_mm": round(self.com_distance_mm, 6),
            "allowed_com_mm": round(self.allowed_com_mm, 6),
            "shape_tolerance_mm": round(self.shape_tolerance_mm, 6),
            "hull_tolerance_mm": round(self.hull.mm, 6),
            "hull_tolerance_from": self.hull.words(),
            "simplified_mm": _rounded(self.simplified_mm),
            "drawing_distance_mm": _rounded(self.drawing_distance_mm),
            "warning": self.tolerance_warning(),
        }


def _rounded(value: float | None) -> float | None:
    return None if value is None else round(value, 6)


def exact_part(part: Part, name: str | None = None) -> Part:
    """``part`` with the exact convex hull of its outline (nothing simplified) and its COM."""
    return make_part(
        part.outline, part.com, hull_tolerance=0.0, revision=part.revision, name=name or part.name
    )


def resting_ranges(part: Part) -> tuple[tuple[float, float, float], ...]:
    """Where the part rests: ``(lo, hi, lowest)`` (deg) per physical state with a breath of
    vibration and nothing else uncertain (as import judges a hull's resting states,
    ``mechanics.modelerror``): the range of its merged stable edges' normals and the normal of
    the one nearest the COM, where the part lies lowest (an arc drawn as many short edges: the
    arc's lowest point, not the edge of the band of facets its COM's foot falls on)."""
    mech = uncertain_mechanics(part, IDEAL, vibration_mm=FRAGILE_BARRIER_REL * part.size)
    hull = np.asarray(part.hull, dtype=float) - np.asarray(part.com, dtype=float)
    ideal = mech.push.states

    def radius(normal_deg: float) -> float:
        a = math.radians(normal_deg)
        return float(np.max(hull @ np.array([math.cos(a), math.sin(a)])))

    out = []
    for s in mech.states:
        lowest = min((ideal[m].normal_deg for m in s.members), key=radius)
        out.append((float(s.rest_deg[0]), float(s.rest_deg[1]), float(lowest)))
    return tuple(out)


def plan_hull_tolerance(size_mm: float, hull_tolerance: float | None = None) -> float:
    """The hull tolerance (mm) the plan's part may have been imported with: ``hull_tolerance``
    when given, else a CAD import's default for a part of ``size_mm`` (the plan may come from a
    drawing even when the SOURCE is an outline file)."""
    if hull_tolerance is not None:
        if not (math.isfinite(hull_tolerance) and hull_tolerance >= 0.0):
            raise InputError(f"--hull-tolerance must be >= 0 mm, got {hull_tolerance:g}")
        return float(hull_tolerance)
    tol = effective_hull_tolerance("cad", ImportOptions(), size_mm)
    return 0.0 if tol is None else float(tol)


def hull_allowance(
    size_mm: float, hull_tolerance: float | None = None, drawing: PlanDrawing | None = None
) -> HullAllowance:
    """The hull tolerance the match check allows: ``--hull-tolerance`` when given, else the
    one stored with the plan member's catalog revision (``drawing``), else a CAD import's
    default (:func:`plan_hull_tolerance`)."""
    if hull_tolerance is not None:
        return HullAllowance(plan_hull_tolerance(size_mm, hull_tolerance), drawing, given=True)
    if drawing is not None:
        return HullAllowance(drawing.hull_tolerance_mm, drawing)
    return HullAllowance(plan_hull_tolerance(size_mm))


def plan_drawing(
    plan: Plan, member: int, catalog: str | None, source: str | None = None
) -> PlanDrawing | None:
    """The catalog revision the plan's member ``member`` was made from, if the catalog in use
    (``catalog``, else ``$FEEDERKIT_CATALOG`` or ``./feederkit.db``) holds it: the revision
    the plan names, or the one a catalog SOURCE names, whose stored hull (in the member's
    landing) is the plan's. None when there is no such revision (a plan from a file, another
    catalog, a revision since re-imported): then nothing is known of the plan's import."""
    pp = plan.parts[member]
    db = Path(catalog) if catalog is not None else default_catalog_path()
    if not db.is_file():
        return None
    wanted: list[tuple[str, object]] = [(pp.name, pp.revision)]
    if source is not None and not Path(source).exists() and could_be_part_name(source):
        name, at, rev = source.rpartition("@")
        wanted.append((name, rev) if at else (source, None))
    for name, rev in wanted:
        found = _stored_drawing(db, pp, name, rev)
        if found is not None:
            return found
    return None


def _stored_drawing(db: Path, pp: PlanPart, name: str, rev: object) -> PlanDrawing | None:
    """The revision ``name@rev`` (latest when ``rev`` is None) of catalog ``db`` as
    :func:`plan_drawing` takes it: when its stored hull, in ``pp``'s landing, is ``pp``'s."""
    try:
        revision = get_revision(db, name, None if rev is None else int(str(rev)))
    except (InputError, ValueError):
        return None
    part = _landing_part(revision, pp.landing)
    if part is None or hull_distance(pp.hull, part.hull) > MATCH_REL_SLACK * pp.size:
        return None  # another import of the part: its hull tolerance is not the plan's
    return PlanDrawing(
        f"{revision.name}@{revision.revision} in {db}",
        float(revision.hull_tolerance or 0.0),
        exact_part(part, pp.name),
    )


def _landing_part(revision, landing: str | None) -> Part | None:
    """A stored revision's part as it lies in ``landing`` (None: as imported; ``up`` of a
    revision stored without landings: as drawn)."""
    if landing is None:
        return revision_part(revision)
    found = next((x.part for x in revision.landings if x.name == landing), None)
    return revision_part(revision) if found is None and landing == UP else found


def check_match(
    plan: Plan,
    member: int,
    part: Part,
    source: str,
    hull_tolerance: float | None = None,
    drawing: PlanDrawing | None = None,
) -> RealPart:
    """The plan member ``member`` simulated on ``part`` (its exact hull is taken here), after
    the match check: InputError, one line naming the distance, when the part's hull differs
    from the plan's by more than the plan's shape tolerance plus the hull tolerance of its
    import (:func:`hull_allowance`; ``drawing``: the catalog revision the member was made
    from, :func:`plan_drawing`) plus the slack, or its COM by more than the COM tolerance
    plus the slack. A hull within that allowance but beyond the shape tolerance plus the
    slack is accepted with a warning (:meth:`RealPart.tolerance_warning`)."""
    pp = plan.parts[member]
    exact = exact_part(part, pp.name)
    unc = plan.uncertainty
    slack = MATCH_SLACK_MM + MATCH_REL_SLACK * pp.size
    h = hull_allowance(pp.size, hull_tolerance, drawing)
    allowed = unc.shape_tolerance_mm + h.mm + slack
    d = hull_distance(pp.hull, exact.hull)
    if not d <= allowed:
        raise InputError(
            f"{source}: not the part the plan was made for: its outline's hull lies {d:.4g} mm "
            f"from the plan's hull of {pp.label} (allowed {allowed:.4g} mm: shape tolerance "
            f"{unc.shape_tolerance_mm:g} + hull tolerance {h.mm:g} ({h.words()}) + slack "
            f"{slack:.3g}; same part frame){_refusal_hint(h, exact, pp, source, allowed)}"
        )
    allowed_com = unc.com_tolerance_mm + slack
    dc = math.dist(pp.com, exact.com)
    if not dc <= allowed_com:
        raise InputError(
            f"{source}: not the part the plan was made for: its COM lies {dc:.4g} mm from the "
            f"plan's COM of {pp.label} (allowed {allowed_com:.4g} mm: COM tolerance "
            f"{unc.com_tolerance_mm:g} + slack {slack:.3g})"
        )
    known = h.drawing
    return RealPart(
        member=member,
        label=pp.label,
        source=source,
        part=exact,
        rests=resting_ranges(exact),
        hull_distance_mm=d,
        allowed_mm=allowed,
        com_distance_mm=dc,
        allowed_com_mm=allowed_com,
        shape_tolerance_mm=unc.shape_tolerance_mm,
        slack_mm=slack,
        certified_mm=_certified_shape_tolerance(plan),
        hull=h,
        simplified_mm=None if known is None else hull_distance(pp.hull, known.part.hull),
        drawing_distance_mm=None if known is None else hull_distance(known.part.hull, exact.hull),
    )


def _refusal_hint(h: HullAllowance, exact: Part, pp: PlanPart, source: str, allowed: float) -> str:
    """What a refused SOURCE may still need: its units or its part frame, when its hull is
    the plan's scaled or moved (:func:`feederkit.sim.likeness.refusal_words`); else the hull
    tolerance the plan's part was imported with, when it is not known (no catalog revision,
    no --hull-tolerance); else how far the part lies from the revision's drawing."""
    other = refusal_words(
        pp.hull,
        pp.com,
        exact.hull,
        exact.com,
        allowed,
        source=source,
        name=pp.name,
        is_file=Path(source).exists(),
    )
    if other is not None:
        return other
    if h.drawing is not None:
        far = hull_distance(h.drawing.part.hull, exact.hull)
        return f"; it lies {far:.4g} mm from the drawing of {h.drawing.where}"
    if h.given:
        return ""
    return (
        ": if the plan's part was imported with a coarser hull tolerance, give "
        "--hull-tolerance MM with the value it was imported with (catalog show names a "
        "revision's; --catalog DB, the plan's catalog, reads it)"
    )


def _certified_shape_tolerance(plan: Plan) -> float | None:
    """The largest shape tolerance the plan's certificate holds; None without one."""
    cert = plan.stats.certificate
    return None if cert is None else cert.max_shape_tolerance_mm


def _import_options(source: str, pp: PlanPart) -> ImportOptions | None:
    """Fine flattening for a drawing SOURCE (:data:`FINE_FLATTEN_REL`); None otherwise."""
    if Path(source).suffix.lower() not in CAD_SUFFIXES:
        return None
    return ImportOptions(flatten_tolerance=max(FINE_FLATTEN_REL * pp.size, 1e-6))


def split_spec(plan: Plan, spec: str) -> tuple[str, str]:
    """``(NAME, SOURCE)`` of one ``--part`` value: ``NAME=SOURCE`` names a part of the plan;
    a plain ``SOURCE`` (or one that is an existing file) is enough when the plan has one part.
    InputError for a name not in the plan, or a plain SOURCE for a plan of several parts."""
    names = list(dict.fromkeys(p.name for p in plan.parts))
    if "=" in spec and not Path(spec).exists():
        name, source = spec.split("=", 1)
        if name not in names:
            raise InputError(
                f"--part {spec}: {name!r} is not one of the plan's parts ({', '.join(names)})"
            )
        if not source:
            raise InputError(f"--part {spec}: no SOURCE after {name}=")
        return name, source
    if len(names) > 1:
        raise InputError(
            f"--part {spec}: the plan has {len(names)} parts ({', '.join(names)}): "
            "name the one it is with --part NAME=SOURCE"
        )
    return names[0], spec


LandingLoader = Callable[[str, tuple[str, ...], str | None, ImportOptions | None], dict[str, Part]]
"""``(source, landings, catalog, options) -> {landing: part}``: a SOURCE's part in each of the
landings named (the command line passes :func:`feederkit.landing.plan.load_landings`'s)."""


def outline_landings(
    source: str, held: tuple[str, ...], catalog: str | None, options: ImportOptions | None
) -> dict[str, Part]:
    """A flat part's landings (``up`` as drawn, ``down`` mirrored: design.md, "Landings"), for
    :func:`real_parts` without a loader of its own; a mesh's poses need one."""
    part = load_part(source, catalog=catalog, options=options)
    found = {x.name: x.part for x in landings_of_outline(part)}
    if DOWN in held and DOWN not in found:  # congruent sides: down is up turned over
        found[DOWN] = mirror_part(part)
    missing = [x for x in held if x not in found]
    if missing:
        raise InputError(
            f"{source}: has no landing {missing[0]} here (a mesh's poses: use the command line)"
        )
    return found


def real_parts(
    plan: Plan,
    specs: Sequence[str],
    *,
    catalog: str | None = None,
    hull_tolerance: float | None = None,
    landings: LandingLoader | None = None,
) -> tuple[RealPart, ...]:
    """The members ``--part`` values name (``SOURCE`` or ``NAME=SOURCE``, see
    :func:`split_spec`), each loaded (:func:`feederkit.sources.load_part`; a drawing's curves
    flattened finely) and checked (:func:`check_match`, against the catalog revision the
    member was made from when ``catalog`` holds it: :func:`plan_drawing`), in the plan's
    order.

    In a plan over landings a SOURCE stands for every landing of its part the plan holds, as
    ``landings`` loads them (default :func:`outline_landings`: up as drawn, down mirrored).
    InputError (one line) for an unreadable SOURCE or unknown catalog name, a name not in the
    plan, a part named twice, or a part that does not match.
    """
    out: dict[int, RealPart] = {}
    seen: set[str] = set()
    for spec in specs:
        name, source = split_spec(plan, spec)
        if name in seen:
            raise InputError(f"--part: the plan's part {name!r} is given twice")
        seen.add(name)
        first = next(p for p in plan.parts if p.name == name)
        options = _import_options(source, first)
        held = tuple(dict.fromkeys(p.landing for p in plan.parts if p.name == name))
        others = tuple(x for x in held if x not in (None, UP))
        for landing in (None, UP):  # the part as loaded (as drawn): checked first
            if landing in held:
                k = plan.part_index(name, landing)
                part = load_part(source, catalog=catalog, options=options)
                drawing = plan_drawing(plan, k, catalog, source)
                out[k] = check_match(plan, k, part, source, hull_tolerance, drawing)
        if others:  # a plan over landings: down mirrored, a mesh's poses
            found = (landings or outline_landings)(source, others, catalog, options)
            for landing in others:
                k = plan.part_index(name, landing)
                drawing = plan_drawing(plan, k, catalog, source)
                out[k] = check_match(plan, k, found[landing], source, hull_tolerance, drawing)
    return tuple(out[k] for k in sorted(out))


__all__ = [
    "FINE_FLATTEN_REL",
    "MATCH_SLACK_MM",
    "REAL_SETTLE_RULE",
    "HullAllowance",
    "PlanDrawing",
    "RealPart",
    "check_match",
    "exact_part",
    "hull_allowance",
    "hull_distance",
    "outline_landings",
    "plan_drawing",
    "plan_hull_tolerance",
    "real_parts",
    "resting_ranges",
    "split_spec",
]
