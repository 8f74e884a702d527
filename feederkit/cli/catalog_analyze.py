"""``feederkit catalog analyze``: behaviour classes of the catalog's parts and every pair no plan
can tell apart under a sensor (section 8).

The lead registers :func:`analyze_command` as ``analyze`` in the ``catalog`` group.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.table import Table

from feederkit.catalog import (
    DeclaredTolerances,
    RevisionTolerances,
    declared_tolerances,
    get_revision,
    list_parts,
    open_catalog,
    part_from_revision,
    resolve_catalog_path,
)
from feederkit.catalog.schema import no_catalog
from feederkit.cli.common import (
    COMMAND_START,
    CatalogOpt,
    ComToleranceOpt,
    JsonOpt,
    LedPitchOpt,
    NoiseOpt,
    SensorlessOpt,
    ShapeToleranceOpt,
    ToleranceOpt,
    add_name_column,
    console,
    flag_tolerance,
    flag_words,
    limit_instant,
    plural,
    print_json,
    print_warnings,
    progress_bar,
    stored_tolerance_words,
    uncertainty_option,
    with_flags,
)
from feederkit.cli.plan_render import sensor_text
from feederkit.design.limit import check_limits
from feederkit.errors import CheckFailed, InputError
from feederkit.importers.orientable import orientability
from feederkit.landing.model import Landing
from feederkit.landing.plan import revision_landings
from feederkit.machine.build import build_machine
from feederkit.machine.widths import widen_widths
from feederkit.mechanics.modelerror import part_offsets
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.mix.analyze import MixAnalysis, analyze_mix
from feederkit.mix.changeover import plans_over_landings
from feederkit.mix.pairs import PairWitness
from feederkit.part import Part
from feederkit.sensors import NoSensor, Sensor, make_sensor
from feederkit.uncertainty import (
    DEFAULT_ROTATION_ERROR_DEG,
    IDEAL,
    Uncertainty,
    check_for_part,
)


def catalog_file(option: Path | None) -> Path:
    """The catalog file (:func:`feederkit.catalog.resolve_catalog_path`); it must exist."""
    path = resolve_catalog_path(option)
    try:
        if not path.is_file():
            raise no_catalog(path)
    except OSError as exc:
        raise InputError(f"{path}: cannot open the catalog ({exc.strerror})") from None
    return path


def load_catalog_parts(
    path: Path,
) -> tuple[list[PushFunction], list[str], tuple[str, ...] | None, list[RevisionTolerances]]:
    """Push functions of every landing of every orientable part's latest revision, a
    warning per part (or mesh pose) left out, when the members are the landings the part
    each belongs to (None: the members are the parts), and what the revisions read store
    (:func:`~feederkit.catalog.declared_tolerances`).

    design.md, "Landings": plans cover every landing unless told otherwise, so the analysis
    is of the mix ``plan`` would plan: when some part has several landings, each landing is
    a member named ``PART/LANDING`` (a part and its mirror image read alike face up against
    face down, and one part's sides must be told apart too); else the parts themselves.
    """
    conn = open_catalog(path)
    try:
        summaries = list_parts(conn)
        per_part: list[tuple[Part, tuple[Landing, ...]]] = []
        stored: list[RevisionTolerances] = []
        skipped = []
        with progress_bar() as progress:
            task = progress.add_task("reading parts", total=len(summaries))
            for s in summaries:
                progress.advance(task)
                if not s.orientable:
                    skipped.append(f"{s.name}: not orientable by pushing, left out")
                    continue
                # Rows are validated when read (COM strictly inside a convex hull), so every
                # stored orientable part has a push function.
                rev = get_revision(conn, s.name, s.revision)
                stored.append(rev.tolerances)
                part = part_from_revision(rev)
                per_part.append((part, revision_landings(rev, part)))
    finally:
        conn.close()
    if not plans_over_landings([lands for _, lands in per_part], False, False):
        return [push_function(part) for part, _ in per_part], skipped, None, stored
    pfs = []
    owners = []
    for part, lands in per_part:
        for x in lands:
            if x.name.startswith("pose-") and not orientability(x.part, None).orientable:
                skipped.append(f"{x.label}: not orientable by pushing, left out")
                continue
            pfs.append(push_function(x.part))
            owners.append(part.name)
    return pfs, skipped, tuple(owners), stored


def members_taking(
    pfs: list[PushFunction],
    owners: tuple[str, ...] | None,
    unc: Uncertainty,
    declared: DeclaredTolerances | None = None,
) -> tuple[list[PushFunction], tuple[str, ...] | None, list[str]]:
    """The members whose hull takes the declared shape and COM tolerances
    (:func:`~feederkit.uncertainty.check_for_part`), their owners, and a line per member
    left out: one part with a short hull edge must not stop the whole catalog's screen.
    InputError (the first member's, naming the flag) when no member takes them; a tolerance
    the catalog gave (``declared``) names the revision storing it."""
    if unc.is_ideal:
        return pfs, owners, []
    kept: list[int] = []
    left_out: list[str] = []
    first: InputError | None = None
    for k, pf in enumerate(pfs):
        try:
            with stored_tolerance_words(declared):
                check_for_part(unc, pf.part)
        except InputError as exc:
            first = first or exc
            left_out.append(with_flags(f"{exc}, left out"))
            continue
        kept.append(k)
    if first is not None and not kept:
        raise InputError(with_flags(f"no member takes the declared tolerances: {first}"))
    return (
        [pfs[k] for k in kept],
        None if owners is None else tuple(owners[k] for k in kept),
        left_out,
    )


AnalyzeRotationErrorOpt = Annotated[
    float | None,
    typer.Option(
        "--rotation-error",
        metavar="DEG",
        help="Also check the pairs the ideal model tells apart for strong plans under a "
        "rotation error of ±DEG (default 0: section 8's ideal model only; 1, as plan and "
        "changeover compile, with a shape or COM tolerance; the cell profile is not read).",
    ),
]


def analysis_uncertainty(
    rotation_error: float | None, shape_tolerance: float, com_tolerance: float
) -> Uncertainty:
    """The declared uncertainty the analysis checks the pairs under (errors name the flags).

    Without any of the three flags, and no tolerance stored in the catalog, the analysis is
    the ideal model's (section 8). A shape or COM tolerance (given, or the largest the
    revisions store: :func:`~feederkit.catalog.declared_tolerances`) without
    ``--rotation-error`` takes design.md's default rotation error (1 degree), as ``plan``
    and ``changeover compile`` do without a cell profile: the same flags screen for the pairs
    compile reports. ``--rotation-error 0`` with a tolerance is that tolerance alone, not the
    ideal model (``Uncertainty.is_ideal``), as in compile.
    """
    if rotation_error is None:
        tolerant = bool(shape_tolerance) or bool(com_tolerance)
        rotation_error = DEFAULT_ROTATION_ERROR_DEG if tolerant else 0.0
    return uncertainty_option(rotation_error, shape_tolerance, com_tolerance)


def _why_undecided(result: MixAnalysis) -> str:
    """Why checks under the uncertainty were left undecided."""
    return "too many sets, or the time limit" if result.cut else "too many sets"


def analyze_command(
    sensorless: SensorlessOpt = False,
    tolerance: ToleranceOpt = None,
    led_pitch: LedPitchOpt = None,
    noise: NoiseOpt = None,
    rotation_error: AnalyzeRotationErrorOpt = None,
    shape_tolerance: ShapeToleranceOpt = None,
    com_tolerance: ComToleranceOpt = None,
    json_out: JsonOpt = False,
    catalog: CatalogOpt = None,
    time_limit: Annotated[
        float | None,
        typer.Option(
            "--time-limit",
            metavar="S",
            help="Seconds, from the command's start, for the checks under a declared "
            "uncertainty; the members and pairs left are counted undecided (exit 1). "
            "Default: no limit.",
        ),
    ] = None,
) -> None:
    """Behaviour classes (same push function, same push-diameter function: section 8.3) of the
    catalog's parts, and with a sensor every pair of parts no plan can tell apart, with its
    witness: the states that can never be told apart and why (decided exactly).

    Every landing of every part is a member, as ``plan`` plans a mix (a flat part face up
    and face down: a part and its mirror image read alike face up against face down).

    The analysis is the ideal model's (exact rotations and diameters, as section 8 decides
    it), and says so: under a declared uncertainty a strong plan may tell fewer pairs apart.
    ``--rotation-error DEG``, ``--shape-tolerance MM`` and ``--com-tolerance MM`` (the flags
    of ``plan`` and ``changeover compile``) check the pairs it tells apart whose states may
    read alike under them again, each pair for strong plans (``feederkit.mix.strongpairs``),
    and list those told apart only on the ideal model (a near-duplicate 0.05 mm longer is
    one at 1 degree). Without them, the shape and COM tolerances are the largest the parts'
    latest revisions store (none stored: the ideal model, as before).

    Under a declared uncertainty each member is checked alone first: one no strong plan
    orients even alone is listed once and its pairs are not checked.

    Exit 1 when some pair cannot be told apart (without a sensor: whenever there are two
    members or more, as no pair is told apart), or some member has no strong plan alone,
    or ``--time-limit`` ended the checks (design.md: a result to act on)."""
    started = COMMAND_START.started()
    sensor = make_sensor(
        sensorless=sensorless, tolerance=tolerance, led_pitch=led_pitch, noise=noise
    )
    with flag_words():
        time_limit = check_limits(time_limit, None)[0]
    # The flags, checked before the catalog is read.
    analysis_uncertainty(
        rotation_error, flag_tolerance(shape_tolerance), flag_tolerance(com_tolerance)
    )
    pfs, skipped, owners, stored = load_catalog_parts(catalog_file(catalog))
    declared = declared_tolerances(stored, shape_tolerance, com_tolerance)
    unc = analysis_uncertainty(
        rotation_error, declared.shape_tolerance_mm, declared.com_tolerance_mm
    )
    pfs, owners, too_small = members_taking(pfs, owners, unc, declared)
    print_warnings(declared.warnings)
    skipped += too_small
    over_landings = owners is not None
    # A tolerance too large for a member is refused first: one line naming it and the flag.
    with flag_words(), progress_bar() as bar:
        # Counts of the members and pairs checked under the uncertainty (the ideal model's
        # exact analysis before them is quick).
        task = bar.add_task("analyzing (members, then pairs)", total=None)

        def advance(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        result = analyze_mix(
            pfs,
            sensor,
            uncertainty=unc,
            deadline=limit_instant(started, time_limit),
            progress=advance,
        )
    if json_out:
        data = result.to_dict()
        data["skipped"] = skipped
        data["members"] = "landings" if over_landings else "parts"
        data["uncertainty_from"] = declared.sources()
        print_json(data)
    else:
        print_warnings(skipped)
        _print_report(result, pfs, over_landings, declared)
    what = "landings" if over_landings else "parts"
    problems = []
    if result.pairs is None and len(pfs) > 1:
        # Sensorless: every pair is unrecognizable (section 8.6), as the table says.
        problems.append(
            f"without a sensor no pair of the {len(pfs)} {what} can be told apart (section "
            "8.6): a sensorless plan orients them but cannot say which one it holds; give a "
            "sensor (--tolerance MM or --led-pitch MM) to find the pairs no plan can tell apart"
        )
    if result.pairs or result.strong_pairs:
        found = (result.pairs or ()) + result.strong_pairs
        n = len(found)
        named = "; ".join(f"{w.part_a} & {w.part_b}" for w in found[:5])
        more = f" and {n - 5} more" if n > 5 else ""
        under = (
            ""
            if unc.is_ideal or not result.strong_pairs
            else f" (of them {len(result.strong_pairs)} only under {_under(unc)})"
        )
        sides = [w for w in found if owners and owners[w.index_a] == owners[w.index_b]]
        one_part = (
            f"; {len(sides)} of them two landings of one part, which no mix keeps apart: "
            "plan only one of them (--landings); rejecting one (changeover compile --accept) "
            "leaves no plan, as no plan tells an accepted landing from a rejected one it "
            "cannot tell apart"
            if sides
            else ""
        )
        problems.append(
            f"{plural(n, 'pair')} of {what} no plan can tell apart with this sensor{under}: "
            f"{named}{more}; " + _advice({w.kind for w in found}, unc) + one_part
        )
    if result.alone:
        n = len(result.alone)
        named = ", ".join(result.names[i] for i, _states in result.alone[:5])
        more = f" and {n - 5} more" if n > 5 else ""
        problems.append(
            f"{n} of the {what} no strong plan orients even alone under {_under(unc)}: "
            f"{named}{more}; no mix that plans one has a strong plan (a finer sensor or tighter "
            "tolerances may help; else leave it out of the mix or, for a landing, reject it: "
            "changeover compile --accept)"
        )
    if result.cut:
        problems.append(
            f"the time limit of {time_limit:g} s ended the checks under {_under(unc)}: "
            f"{result.undecided_alone} {what} alone and {plural(result.undecided, 'pair')} "
            "not decided (allow more time with --time-limit S)"
        )
    if problems:
        raise CheckFailed("; and ".join(problems))


def _under(unc: Uncertainty, article: str = "the") -> str:
    """The declared uncertainty in words: the rotation error, and the shape and COM
    tolerances when either is given (``article``: "the" or "a")."""
    if unc.rotation_error_deg == 0.0:
        words = "exact rotations"
    else:
        words = (
            f"the rotation error ±{unc.rotation_error_deg:g} deg"
            if article == "the"
            else f"a rotation error of ±{unc.rotation_error_deg:g} deg"
        )
    if unc.radius_error_mm > 0.0:
        words += (
            f", a shape tolerance of {unc.shape_tolerance_mm:g} mm and a COM tolerance of "
            f"{unc.com_tolerance_mm:g} mm"
        )
    return words


def _advice(kinds: set[str], unc: Uncertainty | None = None) -> str:
    """What helps, by the witnesses' kinds: no sensor separates parts with the same
    push-diameter function (Lemma 8), a finer one may separate the others. A pair told apart
    only on the ideal model may or may not be told apart at a smaller rotation error or
    tighter shape and COM tolerances (those ``unc`` declares; None: the rotation error): any
    declared uncertainty switches the feeder's vibration on, which no smaller value removes
    (``feederkit.plans.certify.VIBRATION_OBSTACLE``), so no smaller value is promised to help."""
    if "uncertainty" in kinds:
        rest = _advice(kinds - {"uncertainty"}) if kinds - {"uncertainty"} else None
        less = []
        if unc is None or unc.rotation_error_deg > 0.0:
            less.append("a smaller rotation error")
        if unc is not None and unc.radius_error_mm > 0.0:
            less.append("tighter shape and COM tolerances")
        told = (
            "the pairs told apart only on the ideal model (no error and no vibration) may or "
            f"may not be told apart with {' or '.join(less)}: any declared uncertainty "
            "switches on the feeder's vibration (push bands, merged fragile states: "
            "docs/uncertainty.md), which no smaller value removes; screen again at the "
            "smaller values to know"
        )
        return told if rest is None else f"{rest}; {told}"
    if kinds == {"same-push-diameter"}:
        return "keep them out of one mix: no sensor tells them apart (same push-diameter function)"
    if "same-push-diameter" in kinds:
        return (
            "keep them out of one mix; a finer sensor helps only the pairs whose push-diameter "
            "functions differ"
        )
    return "keep them out of one mix or use a finer sensor"


def _catalog_words(declared: DeclaredTolerances | None) -> str:
    """The tolerances taken from the catalog, each with the revision storing it (the largest
    stored), or nothing when none was."""
    if declared is None:
        return ""
    found = [
        f"{what} {value:g} mm{declared.note(key)}"
        for key, what, value in (
            ("shape_tolerance_mm", "shape tolerance", declared.shape_tolerance_mm),
            ("com_tolerance_mm", "COM tolerance", declared.com_tolerance_mm),
        )
        if declared.note(key)
    ]
    return "; ".join(found)


def _print_report(
    result: MixAnalysis,
    pfs: list[PushFunction],
    over_landings: bool,
    declared: DeclaredTolerances | None = None,
) -> None:
    c = result.counts()
    summary = Table(title="catalog analysis (section 8)", show_header=False)
    # Over landings each member is a part face up or face down (or a mesh pose).
    summary.add_row("landings" if over_landings else "parts", str(c["parts"]))
    summary.add_row("sensor", sensor_text(result.sensor))
    unc = result.uncertainty
    summary.add_row(
        "declared uncertainty",
        "none: the ideal model (exact rotations and diameters, section 8); under a rotation "
        "error or a shape tolerance plans may tell fewer pairs apart (--rotation-error DEG, "
        "--shape-tolerance MM, --com-tolerance MM check the pairs again)"
        if unc.is_ideal
        else f"the ideal model (section 8), then each pair it tells apart whose states may "
        f"read alike again for strong plans under {_under(unc, 'a')}"
        if result.pairs is not None
        else f"{_under(unc, 'a')}: without a sensor no pair is told apart anyway (section 8.6)",
    )
    stored = _catalog_words(declared)
    if stored:
        summary.add_row("from the catalog", stored)
    summary.add_row(
        "tolerances",
        f"{result.angle_tol_deg:g} deg per resting-range side, "
        f"{result.length_tol_mm:g} mm per diameter",
    )
    summary.add_row(
        "push functions",
        f"{c['push_classes']} distinct; {plural(c['parts_sharing_a_push_function'], 'part')} "
        f"share one ({plural(len(result.shared_push), 'class', 'classes')})",
    )
    summary.add_row(
        "push-diameter functions",
        f"{c['push_diameter_classes']} distinct; "
        f"{plural(c['parts_sharing_a_push_diameter_function'], 'part')} share one "
        f"({plural(len(result.shared_push_diameter), 'class', 'classes')})",
    )
    if result.pairs is None:
        summary.add_row(
            "unrecognizable pairs",
            "all: without a sensor no part can be recognized (section 8.6); parts with one push "
            "function share a sensorless plan (Corollary 5)",
        )
    else:
        summary.add_row(
            "unrecognizable pairs",
            f"{c['unrecognizable_pairs']} (exact test on {c['candidate_pairs']} candidate pairs)",
        )
    if not unc.is_ideal:
        summary.add_row(
            "no strong plan orients alone",
            f"{len(result.alone)}"
            + (
                f" ({result.undecided_alone} undecided: {_why_undecided(result)})"
                if result.undecided_alone
                else ""
            ),
        )
    if not unc.is_ideal and result.pairs is not None:
        summary.add_row(
            "apart only on the ideal model",
            f"{len(result.strong_pairs)}"
            + (
                f" ({result.undecided} undecided: {_why_undecided(result)})"
                if result.undecided
                else ""
            )
            + (
                " (pairs with a member no strong plan orients alone not checked)"
                if result.alone
                else ""
            ),
        )
    console.print(summary)
    for title, classes in (
        ("parts with the same push function", result.shared_push),
        ("parts with the same push-diameter function", result.shared_push_diameter),
    ):
        if not classes:
            continue
        t = Table(title=title)
        t.add_column("class", justify="right")
        t.add_column("parts (phase shift alpha from the first, deg)", overflow="fold")
        for k, cls in enumerate(classes, 1):
            names = ", ".join(
                f"{escape(result.names[m])} ({a:.4g})" if j else escape(result.names[m])
                for j, (m, a) in enumerate(zip(cls.members, cls.phases_deg, strict=True))
            )
            t.add_row(str(k), names)
        console.print(t)
    if result.pairs:
        console.print(_pairs_table(result.pairs, pfs))
    reads = _Readings(pfs, result.sensor, unc)
    if result.strong_pairs:
        console.print(
            _pairs_table(
                result.strong_pairs,
                pfs,
                "pairs told apart only on the ideal model: no strong plan tells them apart "
                f"under {_under(unc, 'a')}",
                reads,
            )
        )
    if result.alone:
        t = Table(title=f"no strong plan orients these even alone under {_under(unc, 'a')}")
        add_name_column(t, "part")
        t.add_column(f"states no strong plan orients together ({READS_HEADING})")
        for i, states in result.alone:
            t.add_row(escape(result.names[i]), ", ".join(reads.state(i, k) for k in states))
        console.print(t)
    if not result.pairs and result.pairs is not None and not isinstance(result.sensor, NoSensor):
        console.print(
            "every pair of parts can be told apart by some plan on the ideal model (Theorem 11)"
        )
        if unc.is_ideal:
            console.print(IDEAL_ONLY_NOTE)


IDEAL_ONLY_NOTE = (
    "that is the ideal model (exact rotations and diameters); changeover compile plans under "
    f"a rotation error of {DEFAULT_ROTATION_ERROR_DEG:g} degree by default, where fewer pairs "
    "may be told apart and some parts may have no strong plan: --rotation-error "
    f"{DEFAULT_ROTATION_ERROR_DEG:g} screens at compile's default"
)
"""The line after an ideal analysis that tells every pair apart: the analysis defaults to the
ideal model (section 8), compile to design.md's rotation error, and a screen at the one is no
verdict at the other."""

READS_HEADING = "edge, reads: the diameters mm its physical state reads over"
"""The witness columns' heading under a declared uncertainty (:class:`_Readings`)."""


class _Readings:
    """Each member's states in a witness table: on the ideal model the edge and exact
    diameter; under a declared uncertainty the edge and the interval the machine reads the
    physical state holding it over (its resting edge may turn, its fragile neighbours merge,
    its contact hull simplifies the outline: :func:`~feederkit.machine.build.build_machine`,
    :func:`~feederkit.machine.widths.widen_widths`), so that states whose nominal diameters
    lie far apart show why they read alike. Each member's machine is built once, when
    first named."""

    def __init__(self, pfs: list[PushFunction], sensor: Sensor, unc: Uncertainty) -> None:
        self.pfs, self.sensor, self.unc = pfs, sensor, unc
        self._spans: dict[int, dict[int, tuple[float, float]]] = {}

    def spans(self, member: int) -> dict[int, tuple[float, float]]:
        """Ideal state -> the diameters its physical state reads over, for one member."""
        if member not in self._spans:
            pf = self.pfs[member]
            machine = build_machine([pf], self.sensor, self.unc)
            machine = widen_widths(machine, part_offsets([pf]))
            self._spans[member] = {
                k: s.diameter_range or (s.diameter, s.diameter)
                for s in machine.states
                for k in s.ideal_states
            }
        return self._spans[member]

    def edge(self, member: int, state: int) -> str:
        """``e7 15`` on the ideal model, ``e7, reads 12.78-15.63`` under uncertainty."""
        s = self.pfs[member].states[state]
        if self.unc.is_ideal:
            return f"e{s.edge} {s.diameter:.4g}"
        lo, hi = self.spans(member).get(state, (s.diameter, s.diameter))
        span = f"{lo:.4g}" if f"{lo:.4g}" == f"{hi:.4g}" else f"{lo:.4g}-{hi:.4g}"
        return f"e{s.edge}, reads {span}"

    def state(self, member: int, state: int) -> str:
        """One state of a member, numbered: ``1 (e2, reads 12.78-15.63)``."""
        return f"{state} ({self.edge(member, state)})"


WHOLE_NAME_WIDTH = 26
"""A pair table keeps a member name up to this long on one line (a longer one folds)."""


def name_width(names: Iterable[str]) -> int:
    """The width of a pair table's name column that keeps each name whole: at 80 columns the
    words of the other columns wrap first, so ``l-bracket-mirror/down`` never breaks before
    its landing (up to :data:`WHOLE_NAME_WIDTH`)."""
    return min(max((len(n) for n in names), default=1), WHOLE_NAME_WIDTH)


def add_pair_column(table: Table, pairs: Iterable[PairWitness]) -> None:
    """The column of a pair table naming both members, one a line (:func:`pair_cell`), as
    wide as the longest name (:func:`name_width`): two name columns side by side leave the
    other columns too little room at 80 columns."""
    widths = [name_width([w.part_a + " &", w.part_b]) for w in pairs]
    add_name_column(table, "parts (A & B)", width=max(widths, default=1))


def pair_cell(w: PairWitness) -> str:
    """Both members of a pair, one a line (escaped for rich)."""
    return f"{escape(w.part_a)} &\n{escape(w.part_b)}"


def _pairs_table(
    pairs: tuple[PairWitness, ...],
    pfs: list[PushFunction],
    title: str = "pairs no plan can tell apart (section 8.4)",
    reads: _Readings | None = None,
) -> Table:
    """A table of pairs with their witnesses: ``reads`` None for the ideal model's (exact
    diameters), else the reading intervals under the declared uncertainty."""
    how = "edge, diameter mm" if reads is None else READS_HEADING
    t = Table(title=title)
    add_pair_column(t, pairs)
    t.add_column(f"inseparable states (A ~ B: {how})")
    t.add_column("why")
    exact = reads or _Readings(pfs, NoSensor(), IDEAL)
    for w in pairs:
        states = ", ".join(
            f"{i}~{j} ({exact.edge(w.index_a, i)} / {exact.edge(w.index_b, j)})" for i, j in w.pairs
        )
        t.add_row(pair_cell(w), states, escape(w.reason))
    return t
