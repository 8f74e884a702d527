"""``feederkit changeover compile|list|show|remove|export|report``: one verified plan for a
product mix, stored in the catalog against the exact part revisions (section 8.5;
docs/changeovers.md).

``compile`` plans every landing of every part (design.md, "Landings": face up and face down,
a mesh's resting poses), each one member of the mix named ``PART/LANDING``; ``--landings``
picks them and ``--accept`` names those the next station takes. It exits 1 when the mix has
parts or landings no plan can tell apart (:func:`feederkit.mix.changeover.reported_pairs`,
the rule ``plan`` follows): the plan still orients them (Corollary 7), is still written and
stored, and its results list each candidate. Every command that shows a stored changeover
warns when a part has a newer revision; changeovers stored before landings (no landing keys)
show, export and report as they were.
"""

from __future__ import annotations

import math
import re
import sys
import time
from collections.abc import Collection, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.box import SIMPLE_HEAD
from rich.markup import escape
from rich.table import Table

from feederkit.catalog import (
    DEFAULT_WAIT,
    UNREADABLE,
    check_name,
    declared_uncertainties,
    list_changeovers,
    part_names,
    remove_changeover,
    resolve_catalog_path,
)
from feederkit.cell import annotate_cycle_time, cycle_time_text
from feederkit.cli.catalog import WaitOpt, opened
from feederkit.cli.catalog_analyze import add_pair_column, pair_cell
from feederkit.cli.common import (
    COMMAND_START,
    DEFAULT_TIME_LIMIT_S,
    DONE_WORK,
    FLAG_TERMS,
    LANDING_TERMS,
    AcceptOpt,
    CatalogOpt,
    CellOpt,
    ComToleranceOpt,
    GroupingOpt,
    JsonOpt,
    LandingsOpt,
    LedPitchOpt,
    LumpingOpt,
    MemoryLimitOpt,
    MinMarginOpt,
    NoiseOpt,
    ObjectiveOpt,
    PlanOutputOpt,
    ProfileRotationErrorOpt,
    ProfileSensorlessOpt,
    ReportOpt,
    ShapeToleranceOpt,
    ToleranceOpt,
    add_name_column,
    cell_planning_options,
    cell_settings,
    check_mix_revision,
    check_output_folders,
    check_outputs,
    check_report_name,
    console,
    cycle_line,
    declared_uncertainty,
    earlier_outputs_noted,
    flag_tolerance,
    flag_words,
    json_found,
    limit_instant,
    note_written,
    plural,
    print_json,
    print_warnings,
    print_written,
    searching,
    stored_tolerance_words,
    time_limit_note,
    uncertainty_option,
    uncertainty_text,
)
from feederkit.cli.plan_render import plan_tree, sensor_text, stats_table
from feederkit.errors import CheckFailed, InputError
from feederkit.jsonio import OutputFile, write_files
from feederkit.landing.plan import landing_names, left_out_words
from feederkit.loading import load_parts
from feederkit.mechanics.push import PushFunction
from feederkit.mix.changeover import (
    CompiledChangeover,
    changeover_exists,
    compile_changeover,
    landing_rows,
    left_out_landings,
    load_changeover,
    member_name,
    mix_landings,
    stale_revisions,
)
from feederkit.mix.pairs import PairWitness
from feederkit.plans.model import Plan, pairs_words
from feederkit.plans.readplan import as_plan
from feederkit.plans.verify import VerificationReport
from feederkit.plans.writeplan import plan_file_text
from feederkit.sensors import LedSensor, ToleranceSensor, sensor_from_dict
from feederkit.uncertainty import IDEAL, Uncertainty, check_for_part

changeover_app = typer.Typer(
    rich_markup_mode="markdown",
    name="changeover",
    help="Changeovers: one verified plan that orients and recognizes every part of a mix.",
    no_args_is_help=True,
)

NameArg = Annotated[str, typer.Argument(help="Name of the changeover.")]


def parse_mix(text: str) -> list[str]:
    """``A,B@2,C`` (or with shares, ``A:0.7,B``) as catalog SOURCEs (``NAME@REV`` is resolved
    by :mod:`feederkit.sources`)."""
    return parse_mix_shares(text)[0]


def parse_mix_shares(text: str) -> tuple[list[str], tuple[float, ...] | None]:
    """``--mix A:0.7,B:0.2,C:0.1``: the members and their shares, normalised to sum to 1.

    A member without ``:SHARE`` takes an equal part of what the given shares leave of 1
    (``A:0.5,B,C``: 0.5, 0.25, 0.25); none given: equal shares (None). Shares must be
    positive finite numbers; a member may appear once. InputError (one line) otherwise.
    """
    items = [m.strip() for m in text.split(",")]
    if not text.strip() or any(not m for m in items):
        raise InputError(
            f"--mix must be a comma-separated list of catalog part names, got {text!r}"
        )
    names: list[str] = []
    given: list[float | None] = []
    for item in items:
        name, colon, share = item.partition(":")
        name = name.strip()
        if not name:
            raise InputError(f"--mix: {item!r} names no part (write NAME or NAME:SHARE)")
        check_mix_revision(name)
        if name in names:
            raise InputError(f"--mix: {name} is listed twice; give each part once")
        names.append(name)
        if not colon:
            given.append(None)
            continue
        try:
            value = float(share)
        except ValueError:
            raise InputError(
                f"--mix: the share of {name} must be a number, got {share.strip()!r}"
            ) from None
        if not (math.isfinite(value) and value > 0.0):
            hint = " (leave a part out of the mix rather than give it no share)"
            raise InputError(
                f"--mix: the share of {name} must be a finite positive number, got "
                f"{share.strip()!r}{hint if value == 0.0 else ''}"
            )
        given.append(value)
    if all(g is None for g in given):
        return names, None
    try:
        total = math.fsum(g for g in given if g is not None)
    except OverflowError:
        listed = ", ".join(f"{n}:{g:g}" for n, g in zip(names, given, strict=True) if g is not None)
        raise InputError(
            f"--mix: the shares {listed} add up to more than a number can hold; give smaller "
            "shares (only their ratios count)"
        ) from None
    missing = given.count(None)
    if missing:
        if total >= 1.0:
            raise InputError(
                f"--mix: the shares given add up to {total:g}, leaving nothing for "
                f"{', '.join(n for n, g in zip(names, given, strict=True) if g is None)}; "
                "give every part a share, or shares below 1 in all"
            )
        rest = (1.0 - total) / missing
        given = [rest if g is None else g for g in given]
        total = 1.0
    shares = tuple(float(g) / total for g in given)  # type: ignore[arg-type]
    for name, g, share in zip(names, given, shares, strict=True):
        if share < sys.float_info.min:  # underflow beside the others, or near it
            raise InputError(
                f"--mix: the share of {name} ({g:g}) is too small beside the others (together "
                f"{total:g}) to compute with; give shares of nearer sizes"
            )
    return names, shares


def check_mix_names(text: str, names: Collection[str]) -> None:
    """Refuse a ``--mix`` item that is, whole, the name of a catalog part holding ':' (stored
    before such names were refused): ``--mix`` reads it as ``NAME:SHARE``, another part at a
    share, so it would silently compile the wrong part."""
    for item in (m.strip() for m in text.split(",")):
        whole = re.sub(r"@[0-9]+$", "", item)
        if ":" in whole and whole in names:
            part, _, share = item.partition(":")
            raise InputError(
                f"--mix {item} is ambiguous: it names the catalog part {whole!r} and reads as "
                f"part {part.strip()!r} at share {share.strip()}; a part whose name holds ':' "
                "cannot be put in a mix: add its file again under a name without ',' or ':' "
                "(catalog add FILE --name NAME)"
            )


def shares_text(revisions: Sequence[tuple[str, int]], plan: dict[str, Any]) -> str:
    """The mix with each part's share as the plan file stores it (equal when none)."""
    shares = _shares(plan)
    return ", ".join(
        f"{name}@{rev} ({100.0 * shares.get(name, 0.0):.3g} %)" for name, rev in revisions
    )


def landings_text(plan: dict[str, Any], rejected: frozenset[str]) -> str | None:
    """The landings in words, each with its share and whether it is accepted, and the share
    of the parts the plan rejects (None for a plan of parts)."""
    rows = landing_rows(plan, rejected)
    if not rows:
        return None

    def share(x: float | None) -> str:
        return "" if x is None else f" {100.0 * x:.3g} %"

    shown = ", ".join(
        f"{member_name(r['part'], r['landing'])}{share(r['share'])}"
        + ("" if r["accept"] else " rejected")
        for r in rows
    )
    out = [r for r in rows if not r["accept"]]
    if not out:
        return f"landings (share): {shown}; every landing accepted"
    total = math.fsum(r["share"] or 0.0 for r in out)
    return (
        f"landings (share): {shown}; {len(out)} rejected ({100.0 * total:.3g} % of the parts "
        "end in a reject result: recirculate or re-drop them)"
    )


REPORT_DESIGN_MIN_S = 1.0
"""Seconds a report's sensor design gets at least, however little of ``--time-limit`` the plan
left: a small mix's design still comes out; a large one's section says it was cut short."""


REPORT_DRAW_S_PER_PART = 0.35
"""Seconds the report takes to draw each part's section (its outline, radius function, push
function and diameters in one SVG figure; 20 landings of a 10-part mix took 6-7 s): kept
from the report's sensor design, so that the command answers within about its limit."""


def report_design_budget(
    time_limit_s: float | None, started: float, parts: int = 0, cap: float | None = None
) -> float:
    """Seconds the report's sensor design may take in a command that started at ``started``
    (``time.monotonic()``) under ``--time-limit`` ``time_limit_s``: what is left of it less
    ``REPORT_DRAW_S_PER_PART`` for each of the report's ``parts`` (at least
    ``REPORT_DESIGN_MIN_S``), never more than ``cap`` (default ``REPORT_DESIGN_LIMIT_S``: a
    compile's limit is the plan's); with no time limit, the cap (docs/reports.md). Tenths of
    a second: the warning of a design cut short names it."""
    from feederkit.design import sensor

    cap = sensor.REPORT_DESIGN_LIMIT_S if cap is None else cap
    if time_limit_s is None:
        return cap
    left = time_limit_s - (time.monotonic() - started) - REPORT_DRAW_S_PER_PART * parts
    return min(cap, max(REPORT_DESIGN_MIN_S, math.floor(10.0 * left) / 10.0))


def changeover_design(
    plan: dict[str, Any],
    pfs: Sequence[PushFunction],
    time_limit_s: float,
    view: Plan | None = None,
) -> tuple[dict[str, Any] | None, str | None]:
    """The sensor design a changeover report shows (``ToleranceDesign.to_dict``; None for a
    single part) within ``time_limit_s`` seconds, and a warning when it was cut short there.
    Cut short after every pair is decided, it is the design without its length table (its
    ``stopped`` says so); before that, a design of nothing but the one line of what was
    decided (``stopped`` and ``answer``): the report's section says it was cut short and what
    it found, as ``design sensor``'s own time limit does (docs/reports.md)."""
    from feederkit.design import DesignTimeout, design_tolerance
    from feederkit.design.sensor import model_note, plan_members

    if len(pfs) < 2:
        return None, None
    u = plan.get("uncertainty")
    # The design of the plan's own question: its accepted landings told apart, the others
    # rejected (as compile planned them).
    unc = Uncertainty.from_dict(u) if u else None
    try:
        design = design_tolerance(
            list(pfs),
            uncertainty=unc,
            time_limit_s=time_limit_s,
            members=plan_members(plan, view),
            partial=True,
        ).to_dict()
    except (DesignTimeout, InputError) as exc:
        # Cut short, or a design this mix cannot have (a step finer than the diameters are
        # known): the plan is made and stored, so the report is written with what is known.
        timeout = isinstance(exc, DesignTimeout)
        design = {
            "sensor_model": "tolerance",
            "parts": [pf.part.name for pf in pfs],
            "critical_tolerance_mm": None,
            "pairs": [],
            "lengths": [],
            "complete": False,
            "stopped": str(exc) if timeout else None,
            "model": model_note(unc or IDEAL),
            "answer": f"not decided: {exc}" if timeout else f"not made: {exc}",
        }
        if not timeout:
            return design, f"the report's sensor design could not be made: {exc}"
    if design.get("stopped") is None:
        return design, None
    return design, (
        f"the report's sensor design was cut short by the command's --time-limit: "
        f"{design['stopped']}; feederkit design sensor --time-limit S decides it"
    )


def changeover_report(
    plan: dict[str, Any],
    pfs: Sequence[PushFunction],
    witnesses: Sequence[PairWitness],
    design_limit_s: float | None = None,
    verification: VerificationReport | None = None,
    plots_until: float | None = None,
    cautions: Sequence[str] = (),
    view: Plan | None = None,
    name: str | None = None,
) -> str:
    """The changeover's HTML report: the plan with its cycle time (``stats.cycle_time``) and,
    for a mix, the sensor design (critical tolerances and the plan length against the
    tolerance, :func:`changeover_design`; docs/reports.md) within ``design_limit_s`` seconds
    (None: ``REPORT_DESIGN_LIMIT_S``); ``verification``: the compile's own of the plan (None:
    made here), ``plots_until``: the command's time limit for the part plots
    (``render_report``); ``cautions`` open the page (parts revised since); ``view``: the
    plan as its file reads back, when the caller has it (else read here, once); ``name``: the
    changeover's, which heads the page."""
    from feederkit.design import sensor
    from feederkit.reports import render_report

    limit = sensor.REPORT_DESIGN_LIMIT_S if design_limit_s is None else design_limit_s
    if view is None:
        view = as_plan(plan)  # read and checked once: the design's members and the page
    design, warning = changeover_design(plan, pfs, limit, view)
    if warning is not None:
        print_warnings([warning])
    stats = plan.get("stats")
    return render_report(
        view,
        cycle_time=stats.get("cycle_time") if isinstance(stats, dict) else None,
        unrecognizable=[w.to_dict() for w in witnesses],
        outlines={pf.part.name: pf.part.outline for pf in pfs},
        design=design,
        verification=verification,
        cautions=cautions,
        plots_until=plots_until,
        changeover=name,
    )


def _pairs_table(witnesses: Sequence[PairWitness]) -> Table:
    """The pairs a changeover's plan cannot tell apart, as ``compile`` and ``show`` print
    them."""
    t = Table(title="parts (or landings) this plan cannot tell apart (section 8.4, Corollary 7)")
    add_pair_column(t, witnesses)
    t.add_column("inseparable states (A ~ B)")
    t.add_column("why")
    for w in witnesses:
        t.add_row(
            pair_cell(w),
            ", ".join(f"{i}~{j}" for i, j in w.pairs),
            escape(w.reason),
        )
    return t


CompileTimeLimitOpt = Annotated[
    float | None,
    typer.Option(
        "--time-limit",
        metavar="S",
        help=(
            "Seconds for the plan, its verification and its file, then for a --report's sensor "
            "design (what is left, at least 1 s; cut short, its section says so); then the "
            "best plan found (optimal: false) and a proven lower bound."
        ),
    ),
]


@changeover_app.command("compile")
def compile_command(
    name: NameArg,
    mix: Annotated[
        str,
        typer.Option(
            "--mix",
            metavar="A[:SHARE],B,...",
            help="Catalog parts, comma-separated: A,B,C (NAME@REV pins one); A:0.7,B:0.2,C:0.1 "
            "gives their shares of the production (default equal; normalised).",
        ),
    ],
    sensorless: ProfileSensorlessOpt = False,
    tolerance: ToleranceOpt = None,
    led_pitch: LedPitchOpt = None,
    noise: NoiseOpt = None,
    objective: ObjectiveOpt = "worst",
    min_margin: MinMarginOpt = 0.0,
    time_limit: CompileTimeLimitOpt = DEFAULT_TIME_LIMIT_S,
    memory_limit: MemoryLimitOpt = None,
    grouping: GroupingOpt = "exact",
    lumping: LumpingOpt = "near-symmetric",
    output: PlanOutputOpt = None,
    report: ReportOpt = None,
    replace: Annotated[
        bool, typer.Option("--replace", help="Replace a stored changeover of the same name.")
    ] = False,
    json_out: JsonOpt = False,
    catalog: CatalogOpt = None,
    cell: CellOpt = None,
    rotation_error: ProfileRotationErrorOpt = None,
    shape_tolerance: ShapeToleranceOpt = None,
    com_tolerance: ComToleranceOpt = None,
    landings: LandingsOpt = None,
    accept: AcceptOpt = None,
    wait: WaitOpt = DEFAULT_WAIT,
) -> None:
    """Plan one verified sequence of push-align operations that orients (and, where possible,
    recognizes) every part of the mix, and store it against the parts' exact revisions.

    Every landing of every part is planned for (a flat part face up and face down, a mesh in
    each resting pose; ``--landings up`` plans the parts face up only), each named
    ``PART/LANDING``; landings not in ``--accept`` end in reject results (docs/landings.md).

    The cell profile (``--cell`` or ./feederkit.toml) gives the sensor, the rotation error
    and the timing; options override it. With timing, the output gives the cycle time. The
    shape and COM tolerances default to the largest the parts' revisions store (one for the
    mix: its plan declares one uncertainty).
    Exit 1 when some parts or landings cannot be told apart, the two sides of one part too
    (the plan is still written and stored), or when an accepted and a rejected landing
    cannot be, or when a plan made on the ideal model (``--rotation-error 0``) holds no
    rotation error on a feeder that vibrates (stored; check it with ``feederkit simulate``).
    """
    started = COMMAND_START.started()  # --time-limit bounds the plan, then the report's design
    check_name(name, "changeover")  # before any work: the store would refuse it at the end
    members, shares = parse_mix_shares(mix)
    check_output_folders(output, report)
    settings = cell_settings(cell, sensorless, tolerance, led_pitch, noise, rotation_error)
    sensor = settings.sensor
    options = cell_planning_options(
        settings, objective, grouping, min_margin, time_limit, memory_limit, lumping
    )
    uncertainty = uncertainty_option(  # the flags, checked before the parts are loaded
        settings.rotation_error_deg, flag_tolerance(shape_tolerance), flag_tolerance(com_tolerance)
    )
    over: dict[str, Any] = {}
    with flag_words((*FLAG_TERMS, *LANDING_TERMS)):
        if landings is not None:
            over["landings"] = "all" if landings == "all" else landing_names(landings)
        if accept is not None:
            over["accept"] = landing_names(accept, "--accept")
    json_found(name=name, mix=members, cell=settings.to_dict())
    path = resolve_catalog_path(catalog)
    if ":" in mix:  # every input is checked before the catalog's changeovers
        check_mix_names(mix, part_names(path))
    terms = (*FLAG_TERMS, *LANDING_TERMS)
    with flag_words(terms):
        loaded = load_parts(members, catalog=path)
    uncertainty, declared = declared_uncertainty(
        settings.rotation_error_deg, loaded.tolerances, shape_tolerance, com_tolerance
    )
    json_found(uncertainty=uncertainty.to_dict(), uncertainty_from=declared.sources())
    with flag_words(terms), stored_tolerance_words(declared):  # one line, before any warning
        for pf in loaded.push_functions:
            check_for_part(uncertainty, pf.part)
        mix_landings(path, loaded, over.get("landings"))  # a landing a part does not have
    if not replace and changeover_exists(path, name):  # every input is checked before this
        raise InputError(f"a changeover named {name!r} already exists (use --replace)")
    left = left_out_landings(path, loaded, over.get("landings"))
    print_warnings([*declared.warnings, *left_out_words(left, "the changeover")])

    def outputs(c: CompiledChangeover, text: str) -> list[OutputFile]:
        # Runs before the changeover is stored, on the plan as its file reads back.
        files = [] if output is None else [OutputFile(output, text, "plan file")]
        if report is not None:
            budget = report_design_budget(options.time_limit_s, started, len(c.parts))
            until = limit_instant(started, options.time_limit_s)
            html = changeover_report(
                c.plan,
                list(c.parts),
                list(c.witnesses),
                budget,
                c.made.report,
                until,
                view=c.view,
                name=name,
            )
            files.append(OutputFile(report, html, "report"))
        return files

    with (
        searching(f"compiling changeover {name}", options.time_limit_s),
        flag_words(terms),
        stored_tolerance_words(declared),
        earlier_outputs_noted(output, report),
    ):
        compiled = compile_changeover(
            path,
            name,
            members,
            sensor,
            options,
            replace=replace,
            outputs=outputs,
            prepare=lambda made: annotate_cycle_time(made, settings),  # the file carries it
            uncertainty=uncertainty,
            shares=shares,
            loaded=loaded,
            started=started,
            on_stored=lambda: stored_and_written(name, path, output, report),
            wait=wait,
            **over,
        )
    plan, witnesses = compiled.plan, list(compiled.witnesses)
    lands = landings_text(plan, compiled.rejected)
    cycle = plan["stats"].get("cycle_time")
    warnings = [*compiled.warnings, *filter(None, [settings.belt_warning()])]
    note = time_limit_note(plan["stats"], options.time_limit_s)
    if note is not None:
        warnings.append(note)
    print_warnings(warnings)
    if json_out:
        print_json(
            {
                "name": name,
                "parts": [
                    {"name": n, "revision": r, "share": _shares(plan).get(n)}
                    for n, r in compiled.revisions
                ],
                "cell": settings.to_dict(),
                "uncertainty": plan.get("uncertainty"),  # as the exit-1 object says it
                "uncertainty_from": declared.sources(),
                "landings": landing_rows(plan, compiled.rejected),
                "cycle_time": cycle,
                "unrecognizable_pairs": [w.to_dict() for w in witnesses],
                "warnings": warnings,
                "plan": plan,
            }
        )
    else:
        console.print(
            f"[bold]changeover {escape(name)}[/]: "
            f"{escape(shares_text(compiled.revisions, plan))}\n"
            + ("" if lands is None else f"{escape(lands)}\n")
            + f"{escape(settings.describe())}\n"
            f"sensor: {sensor_text(sensor.to_dict())}\n"
            f"uncertainty: {uncertainty_text(plan.get('uncertainty'), declared)}",
            highlight=False,
        )
        view = compiled.view or as_plan(plan)  # checked once, for the drawing and the table
        console.print(plan_tree(view))
        console.print(stats_table(view, compiled.made.report))
        console.print(escape(cycle_line(cycle, settings)), highlight=False)
        if witnesses:
            console.print(_pairs_table(witnesses))
        console.print(f"stored changeover {name!r} in {path}", highlight=False, markup=False)
        print_written(output, report)
    lumped = compiled.lumped
    if witnesses or lumped:
        if not witnesses:
            named = ", ".join(f"{a} & {b}" for a, b in lumped)
            raise CheckFailed(
                f"changeover {name!r} cannot tell these apart: {named}; the plan's results "
                "list each candidate with its pose"
            )
        view = compiled.view or as_plan(plan)
        member = {member_name(p.name, p.landing): p.key for p in view.parts}
        raise CheckFailed(
            pairs_words(
                f"changeover {name!r}",
                [(member[w.part_a], member[w.part_b], w.reason) for w in witnesses],
            )
        )
    if compiled.made.unoriented is not None:
        raise CheckFailed(f"changeover {name!r}: {compiled.made.unoriented}")
    if compiled.made.holds_nothing is not None:
        raise CheckFailed(f"changeover {name!r}: {compiled.made.holds_nothing}")


def _shares(plan: dict[str, Any]) -> dict[str, float]:
    """Each part's share (the plan file's, its landings' summed; else equal)."""
    parts = plan.get("parts", [])
    names = list(dict.fromkeys(p.get("name") for p in parts))
    out: dict[str, float] = {}
    for p in parts:
        share = p.get("share")
        if share is None:
            return {n: 1.0 / len(names) for n in names}
        out[p.get("name")] = out.get(p.get("name"), 0.0) + float(share)
    return out


def stored_and_written(
    name: str, path: Path | str, output: Path | None, report: Path | None
) -> None:
    """Note for a Ctrl-C from now on that the changeover is stored and its files written."""
    DONE_WORK.note(f"stored changeover {name!r} in {path}")
    note_written((output, "plan"), (report, "report"))


def listed_uncertainty(stored: object) -> tuple[Uncertainty | None, bool | None]:
    """A listed changeover's declared uncertainty and whether its plan declares one: a
    plan without one is the ideal model (a version-1 file); ``(None, None)`` when the stored
    value cannot be read (:data:`~feederkit.catalog.UNREADABLE`, or not three bounds)."""
    if stored is None:
        return IDEAL, False
    if stored is UNREADABLE:
        return None, None
    try:
        return Uncertainty.from_dict(stored), True
    except (InputError, TypeError, ValueError):
        return None, None


def uncertainty_cell(unc: Uncertainty | None, declared: bool | None) -> str:
    """The declared uncertainty in a few words, for a table: two changeovers of one mix at
    different tolerances must not look alike in ``list``."""
    if unc is None:
        return "unreadable"
    if not declared:
        return "ideal model (none declared)"
    if unc.is_ideal:
        return "ideal model (0)"
    return (
        f"±{unc.rotation_error_deg:g}°, shape {unc.shape_tolerance_mm:g} mm, "
        f"COM {unc.com_tolerance_mm:g} mm"
    )


def sensor_cell(sensor: dict[str, Any]) -> str:
    """The sensor in a few words, for a table (``show`` gives it in full)."""
    try:
        model = sensor_from_dict(sensor)
    except InputError:
        return "unreadable"
    if isinstance(model, LedSensor):
        return f"LED array {model.pitch:g} mm, noise {model.noise:g} mm"
    if isinstance(model, ToleranceSensor):
        return f"tolerance ±{model.tolerance:g} mm"
    return "sensorless"


@changeover_app.command("list")
def list_command(json_out: JsonOpt = False, catalog: CatalogOpt = None) -> None:
    """The stored changeovers: name, parts with revisions, sensor, declared uncertainty, when
    and by whom."""
    path = resolve_catalog_path(catalog)
    infos = list_changeovers(path)
    stored = declared_uncertainties(path) if infos else {}
    declared = {i.name: listed_uncertainty(stored.get(i.name, UNREADABLE)) for i in infos}
    stale = {i.name: stale_revisions(path, i.parts) for i in infos}
    pairs = {i.name: listed_pairs(path, i.name) for i in infos}
    print_warnings(f"changeover {i.name}: {w}" for i in infos for w in stale[i.name])
    if json_out:
        print_json([_listed_dict(i, declared[i.name], stale[i.name], pairs[i.name]) for i in infos])
        return
    if not infos:
        console.print("no changeovers in the catalog")
        return
    mixes = {i.name: [f"{n}@{r}" for n, r in i.parts] for i in infos}
    widest = max(len(m) for parts in mixes.values() for m in parts)
    # Narrow rules (as demo's tables): words wrap whole at 80 columns.
    t = Table(title="changeovers", box=SIMPLE_HEAD, pad_edge=False, collapse_padding=True)
    add_name_column(t, "name")
    # One NAME@REV a line, kept whole: the words of the other columns wrap first.
    t.add_column("parts", no_wrap=True, overflow="fold", min_width=min(widest, LIST_PARTS_WIDTH))
    for col in ("sensor", "uncertainty", "created", "by"):
        t.add_column(col, overflow="fold")
    for i in infos:
        t.add_row(
            escape(i.name) + (" (newer revisions)" if stale[i.name] else ""),
            escape("\n".join(mixes[i.name])),  # one part a line: names whole
            escape(sensor_cell(dict(i.sensor))),
            escape(uncertainty_cell(*declared[i.name])),
            _when(i.created_at),
            escape(i.created_by),
        )
    console.print(t)
    for i in infos:
        line = pairs_line(i.name, pairs[i.name])
        if line is not None:
            console.print(line, highlight=False, markup=False, soft_wrap=True)


def listed_pairs(catalog: Path, name: str) -> list[PairWitness] | None:
    """The pairs a stored changeover's plan cannot tell apart (as ``show`` gives them), or
    None when it cannot be read (``show NAME`` says why): a damaged changeover must not hide
    the others of a listing."""
    try:
        return load_changeover(catalog, name).witnesses()
    except InputError:
        return None


def pairs_line(name: str, pairs: Sequence[PairWitness] | None) -> str | None:
    """The line under ``list``'s table for a changeover whose plan cannot tell some parts
    apart (``show`` names them in a table), or None."""
    if not pairs:
        return None
    named = "; ".join(f"{w.part_a} & {w.part_b}" for w in pairs[:3])
    more = f" and {len(pairs) - 3} more" if len(pairs) > 3 else ""
    return (
        f"changeover {name}: its plan cannot tell apart {plural(len(pairs), 'pair')}: "
        f"{named}{more} (changeover show {name})"
    )


LIST_PARTS_WIDTH = 40
"""``list`` keeps a ``NAME@REV`` up to this long on one line (a longer one folds)."""


def _when(created_at: str) -> str:
    """A stored time (ISO 8601) in UTC to the minute, for a table (``--json`` keeps it
    whole)."""
    try:
        when = datetime.fromisoformat(created_at)
    except ValueError:
        return escape(created_at)
    if when.utcoffset() is not None:
        when = when.astimezone(UTC)
    return when.strftime("%Y-%m-%d %H:%M")


def _listed_dict(
    info,
    declared: tuple[Uncertainty | None, bool | None],
    warnings: list[str],
    pairs: Sequence[PairWitness] | None,
) -> dict[str, Any]:
    """One changeover of ``list --json``: its record, its declared uncertainty (the plan
    file's names; the ideal model's when it declares none, null when unreadable) and
    whether the plan declares one, the pairs its plan cannot tell apart (null when it
    cannot be read), and its warnings."""
    unc, is_declared = declared
    return {
        **_info_dict(info),
        "uncertainty": None if unc is None else unc.to_dict(),
        "uncertainty_declared": is_declared,
        "unrecognizable_pairs": None if pairs is None else [w.to_dict() for w in pairs],
        "warnings": warnings,
    }


@changeover_app.command("show")
def show_command(name: NameArg, json_out: JsonOpt = False, catalog: CatalogOpt = None) -> None:
    """A stored changeover: its parts (exact revisions), sensor and plan."""
    co = load_changeover(resolve_catalog_path(catalog), name)
    print_warnings(co.warnings)
    witnesses = co.witnesses()
    declared = co.plan.get("uncertainty")  # None: a version-1 plan, the ideal model
    if json_out:
        print_json(
            {
                **_info_dict(co.info, co.plan),
                "uncertainty": IDEAL.to_dict() if declared is None else declared,
                "uncertainty_declared": declared is not None,  # as list --json
                "landings": landing_rows(co.plan, co.rejected),
                "cycle_time": co.plan["stats"].get("cycle_time"),
                "unrecognizable_pairs": [w.to_dict() for w in witnesses],
                "warnings": list(co.warnings),
                "plan": co.plan,
            }
        )
        return
    info = co.info
    lands = landings_text(co.plan, co.rejected)
    console.print(
        f"[bold]changeover {escape(info.name)}[/]: "
        f"{escape(shares_text(info.parts, co.plan))}\n"
        + ("" if lands is None else f"{escape(lands)}\n")
        + f"sensor: {sensor_text(dict(info.sensor))}\n"
        f"uncertainty: {escape(uncertainty_text(declared))}\n"
        f"created {info.created_at} by {escape(info.created_by)}",
        highlight=False,
    )
    view = as_plan(co.plan)
    console.print(plan_tree(view))
    console.print(stats_table(view))
    cycle = co.plan["stats"].get("cycle_time")
    console.print(escape(cycle_time_text(cycle, "as compiled")), highlight=False)
    if witnesses:
        console.print(_pairs_table(witnesses))


@changeover_app.command("remove")
def remove_command(name: NameArg, catalog: CatalogOpt = None, wait: WaitOpt = DEFAULT_WAIT) -> None:
    """Delete a stored changeover (its parts stay in the catalog)."""
    path = resolve_catalog_path(catalog)
    with opened(catalog, wait) as conn:
        remove_changeover(conn, name)
    console.print(f"removed changeover {name!r} from {path}", highlight=False, markup=False)


OutputOpt = Annotated[
    Path, typer.Option("-o", "--output", metavar="FILE", help="Write the file here (atomic).")
]


@changeover_app.command("export")
def export_command(
    name: NameArg, output: OutputOpt, json_out: JsonOpt = False, catalog: CatalogOpt = None
) -> None:
    """Write a stored changeover's plan file, for feederkit run or a controller.

    Exit 1 when a part has a newer revision than the changeover names: the file is still
    written (the plan is valid for the revisions it names), but a script must notice that
    the changeover needs compiling again.
    """
    co = load_changeover(resolve_catalog_path(catalog), name)
    # What the plan itself warned of when compiled, as run and simulate repeat it: a plan
    # made on the ideal model that holds less on a feeder that vibrates goes to the line.
    held = [w for w in (as_plan(co.plan).ideal_model_warning(),) if w]
    print_warnings([*co.warnings, *held])
    write_files([OutputFile(output, plan_file_text(co.plan), "plan file")])
    note_written((output, "plan"))
    if json_out:
        print_json(
            {
                "changeover": name,
                "output": str(output),
                "parts": [{"name": n, "revision": r} for n, r in co.info.parts],
                "up_to_date": not co.warnings,
                "warnings": list(co.warnings),
                "plan_warnings": held,
            }
        )
    else:
        console.print(f"wrote the plan to {output}", highlight=False, markup=False, soft_wrap=True)
    if co.warnings:
        raise CheckFailed(_stale_result(name, len(co.warnings)))


def _stale_result(name: str, stale: int, written: str = "plan file") -> str:
    """The ``result:`` line of an export or report of a changeover whose parts have newer
    revisions (``stale`` of them, each named in a warning line)."""
    return (
        f"changeover {name!r} is out of date (newer catalog revisions of "
        f"{plural(stale, 'part')}, warned above); the {written} is written for the revisions "
        "it names: compile the changeover again to plan for the latest"
    )


ReportOutputOpt = Annotated[
    Path,
    typer.Option(
        "-o", "--output", metavar="REPORT.html", help="Write the HTML report here (atomic)."
    ),
]


@changeover_app.command("report")
def report_command(
    name: NameArg,
    output: ReportOutputOpt,
    time_limit: Annotated[
        float | None,
        typer.Option(
            "--time-limit",
            metavar="S",
            help="Seconds the report may take (default 60): its sensor design gets them less "
            "the drawing of each part; past them its section is cut short and says what it "
            "decided.",
        ),
    ] = None,
    catalog: CatalogOpt = None,
) -> None:
    """Write a stored changeover's HTML report, with the pairs of parts no plan can tell apart."""
    from feederkit.design.limit import check_limits
    from feederkit.design.sensor import REPORT_DESIGN_LIMIT_S

    started = COMMAND_START.started()  # --time-limit bounds the report's design
    with flag_words():
        design_limit, _ = check_limits(time_limit, None)  # InputError before any work
    check_report_name(output)  # a .txt or .pdf would hold HTML: refused before any work
    check_outputs((output, "report"))
    co = load_changeover(resolve_catalog_path(catalog), name)
    print_warnings(co.warnings)
    # The report's own limit (default the design's 60 s) is all the report's: its design gets
    # it less the drawings, however long.
    limit = REPORT_DESIGN_LIMIT_S if design_limit is None else design_limit
    budget = report_design_budget(limit, started, len(co.parts), cap=limit)
    html = changeover_report(
        co.plan,
        list(co.parts),
        co.witnesses(),
        budget,
        plots_until=started + limit,
        cautions=co.warnings,
        name=name,
    )
    write_files([OutputFile(output, html, "report")])
    note_written((output, "report"))
    console.print(f"wrote the report to {output}", highlight=False, markup=False, soft_wrap=True)
    if co.warnings:
        raise CheckFailed(_stale_result(name, len(co.warnings), "report"))


def _info_dict(info, plan: dict[str, Any] | None = None) -> dict[str, Any]:
    """A changeover's record; with its plan, each part's share."""
    shares = {} if plan is None else _shares(plan)
    parts = [{"name": n, "revision": r} for n, r in info.parts]
    if plan is not None:
        parts = [{**p, "share": shares.get(p["name"])} for p in parts]
    return {
        "name": info.name,
        "created_at": info.created_at,
        "created_by": info.created_by,
        "parts": parts,
        "sensor": dict(info.sensor),
    }


def register(app: typer.Typer) -> None:
    """Add the ``changeover`` command group to the app."""
    app.add_typer(changeover_app, name="changeover")
