"""``feederkit plan SOURCE...``: a verified orienting plan for one part or a product mix.

A thin layer: build the sensor and the planning options once, load and check the parts and
their landings (:func:`feederkit.landing.plan.load_landings`), call
:func:`feederkit.mix.changeover.plan_mix` (planner, plan file, verification) or, when some
part has several landings or ``--landings``/``--accept`` is given,
:func:`feederkit.landing.plan.plan_landings` (every landing one member of the mix,
docs/landings.md), write the plan and the report together (both or neither), print the tree
and the warnings (a margin below 1 degree, a time limit reached).
"""

from __future__ import annotations

import sys
from dataclasses import replace
from typing import Annotated, Any

import typer
from rich.markup import escape

from feederkit.catalog import DeclaredTolerances
from feederkit.cell import BUILT_IN, annotate_cycle_time
from feederkit.cli.common import (
    COMMAND_START,
    DEFAULT_TIME_LIMIT_S,
    FLAG_TERMS,
    JSON_ANSWER,
    LANDING_TERMS,
    AcceptOpt,
    CatalogOpt,
    CellOpt,
    ComToleranceOpt,
    GroupingOpt,
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
    TimeLimitOpt,
    ToleranceOpt,
    cell_planning_options,
    cell_settings,
    check_output_folders,
    console,
    cycle_line,
    declared_uncertainty,
    earlier_outputs_noted,
    flag_tolerance,
    flag_words,
    json_found,
    json_option,
    limit_instant,
    note_written,
    plan_outputs,
    print_warnings,
    print_written,
    searching,
    stored_tolerance_words,
    time_limit_note,
    uncertainty_option,
    uncertainty_text,
)
from feederkit.cli.importopts import takes_import_options
from feederkit.cli.plan_render import plan_tree, sensor_text, stats_table
from feederkit.errors import CheckFailed, InputError
from feederkit.importers import ImportOptions
from feederkit.jsonio import write_files
from feederkit.landing.plan import LandingPlan, landing_names, load_landings, plan_landings
from feederkit.mechanics.push import push_function
from feederkit.mix.changeover import plan_mix, plans_over_landings
from feederkit.mix.pairs import PairWitness
from feederkit.planning.options import PlanningOptions
from feederkit.plans.fileformat import plan_json
from feederkit.plans.match import leaf_part_pairs
from feederkit.plans.model import member_label, pairs_words
from feederkit.uncertainty import check_for_part


def pairs_message(witnesses: list[PairWitness], lumped: list[tuple[str, str]]) -> str:
    """One line naming the pairs no plan can tell apart (section 8.4, :func:`pairs_words`),
    and any disagreement."""
    lumped_text = ", ".join(f"{a} & {b}" for a, b in lumped) or "none"
    if not witnesses:
        return (
            f"the plan's results lump {lumped_text}, which the mix analysis can tell apart: "
            "please report this as a bug"
        )
    pairs = [((w.part_a, None), (w.part_b, None), w.reason) for w in witnesses]
    msg = pairs_words("the plan", pairs)
    if {(w.part_a, w.part_b) for w in witnesses} != set(lumped):
        msg += f" (but the plan's results lump {lumped_text}: please report this as a bug)"
    return msg


def landing_lumps(planned: LandingPlan) -> set[tuple[str, str]]:
    """Pairs of landings (in words, in plan order) that an accepting result lists together;
    a reject result may list several rejected landings."""
    order: dict[str, int] = {}
    for k, x in enumerate(planned.landings):
        order.setdefault(member_label(x.part_name, x.name), k)
    lumped: set[tuple[str, str]] = set()
    for leaf in planned.leaves():
        if leaf.reject:
            continue
        names = sorted({member_label(r.part, r.landing) for r in leaf}, key=order.__getitem__)
        lumped |= {(a, b) for k, a in enumerate(names) for b in names[k + 1 :]}
    return lumped


def landing_pairs_message(planned: LandingPlan, lumped: set[tuple[str, str]]) -> str:
    """One line naming the landings no plan can tell apart (section 8.4, :func:`pairs_words`:
    two sides of one part are not oriented), and any disagreement with the plan's accepting
    results (``lumped``, :func:`landing_lumps`)."""
    pairs = {
        (member_label(p.a.part_name, p.a.name), member_label(p.b.part_name, p.b.name))
        for p in planned.indistinguishable
    }
    if not pairs:
        shown = ", ".join(f"{a} & {b}" for a, b in sorted(lumped))
        return (
            f"the plan's results lump {shown}, which the mix analysis can tell apart: "
            "please report this as a bug"
        )
    msg = pairs_words(
        "the plan",
        [
            ((p.a.part_name, p.a.name), (p.b.part_name, p.b.name), p.witness.reason)
            for p in planned.indistinguishable
        ],
    )
    if pairs != lumped:
        shown = ", ".join(f"{a} & {b}" for a, b in sorted(lumped)) or "none"
        msg += f" (but the plan's results lump {shown}: please report this as a bug)"
    return msg


def _landings_text(planned: LandingPlan) -> str:
    """The landings planned, each with its share and whether the next station takes it."""
    plan_parts = planned.made.plan["parts"]
    rows = []
    for x, part in zip(planned.landings, plan_parts, strict=True):
        share = part.get("share")
        take = "rejected" if x.label in planned.rejected else "accepted"
        shown = "" if share is None else f" {share:.3g}"
        rows.append(f"{member_label(x.part_name, x.name)}{shown} {take}")
    return "landings (share): " + ", ".join(rows)


def _header(
    plan: dict[str, Any],
    sensor_given: bool,
    landings: str | None = None,
    declared: DeclaredTolerances | None = None,
    why_sensorless: str = "no sensor option given",
) -> str:
    names = escape(", ".join(dict.fromkeys(p["name"] for p in plan["parts"])))
    sensor = sensor_text(plan["sensor"])
    if not sensor_given:
        sensor = f"none — {why_sensorless}, so the plan is sensorless"
    stats = plan["stats"]
    lines = "" if landings is None else f"{escape(landings)}\n"
    return (
        f"[bold]feederkit plan[/] for {names}\n{lines}"
        f"sensor: {sensor}\nuncertainty: {uncertainty_text(plan.get('uncertainty'), declared)}\n"
        f"objective: {stats['objective']}, reading branching: {stats['grouping']}"
    )


def _accepted_names(text: str | None, planned_names: set[str]) -> tuple[str, ...] | None:
    """The ``--accept`` list, each name a landing (or a merged name) of a part planned."""
    if text is None:
        return None
    names = landing_names(text, "--accept")
    for n in names:
        if n not in planned_names:
            known = ", ".join(sorted(planned_names))
            raise InputError(f"--accept: no landing {n} is planned (the landings: {known})")
    return names


def print_plan_file(plan: dict[str, Any]) -> None:
    """``--json``: the plan file's text on stdout, byte for byte what ``-o`` writes
    (:func:`~feederkit.plans.fileformat.plan_json`), so a plan saved from stdout is the file."""
    JSON_ANSWER.printed = True
    sys.stdout.write(plan_json(plan))
    sys.stdout.flush()


@takes_import_options
def plan_command(
    sources: Annotated[
        list[str],
        typer.Argument(
            metavar="SOURCE", help="Outline or CAD files, or catalog names; several: a mix."
        ),
    ],
    sensorless: ProfileSensorlessOpt = False,
    tolerance: ToleranceOpt = None,
    led_pitch: LedPitchOpt = None,
    noise: NoiseOpt = None,
    objective: ObjectiveOpt = "worst",
    min_margin: MinMarginOpt = 0.0,
    time_limit: TimeLimitOpt = DEFAULT_TIME_LIMIT_S,
    memory_limit: MemoryLimitOpt = None,
    grouping: GroupingOpt = "exact",
    lumping: LumpingOpt = "near-symmetric",
    output: PlanOutputOpt = None,
    json_out: Annotated[bool, json_option("Print the plan file's JSON on stdout.")] = False,
    report: ReportOpt = None,
    catalog: CatalogOpt = None,
    rotation_error: ProfileRotationErrorOpt = None,
    shape_tolerance: ShapeToleranceOpt = None,
    com_tolerance: ComToleranceOpt = None,
    landings: LandingsOpt = None,
    accept: AcceptOpt = None,
    cell: CellOpt = None,
    import_opts: ImportOptions = ImportOptions(),
) -> None:
    """Plan the shortest conditional sequence of push-align operations that orients the part(s).

    Every landing of every part is planned for (a flat part face up and face down, a mesh in
    each resting pose; ``--landings`` picks them) and the results name part, landing and
    state; landings not in ``--accept`` end in reject results. The plan is verified on the
    kinematic model (every start, reading and branch) before it is written or printed; under
    the declared uncertainty (``--rotation-error``, default 1 degree) it is a strong plan,
    verified for every outcome; the shape and COM tolerances default to the largest the
    parts' catalog revisions store. Exit 1 when some parts of a mix, or some landings, cannot
    be told apart (the plan is still written) or an accepted and a rejected landing cannot be,
    or when a plan made on the ideal model (``--rotation-error 0``) holds no rotation error
    on a feeder that vibrates (written; check it with ``feederkit simulate``).
    """
    started = COMMAND_START.started()  # --time-limit counts reading the parts too
    terms = (*FLAG_TERMS, *LANDING_TERMS)
    check_output_folders(output, report, sources)
    settings = cell_settings(cell, sensorless, tolerance, led_pitch, noise, rotation_error)
    sensor = settings.sensor
    options = cell_planning_options(
        settings, objective, grouping, min_margin, time_limit, memory_limit, lumping
    )
    uncertainty = uncertainty_option(  # the flags, checked before the parts are loaded
        settings.rotation_error_deg, flag_tolerance(shape_tolerance), flag_tolerance(com_tolerance)
    )
    json_found(
        sources=list(sources),
        cell=settings.to_dict(),
        sensor=sensor.to_dict(),
        uncertainty=uncertainty.to_dict(),
    )
    with flag_words(terms):
        which = "all" if landings in (None, "all") else landing_names(landings)
        found = load_landings(
            sources, catalog=catalog, options=within_limit(import_opts, options), which=which
        )
    loaded = found.parts
    uncertainty, declared = declared_uncertainty(
        settings.rotation_error_deg, loaded.tolerances, shape_tolerance, com_tolerance
    )
    json_found(uncertainty=uncertainty.to_dict(), uncertainty_from=declared.sources())
    # bad input: one line, before any warning about the parts
    with flag_words(terms), stored_tolerance_words(declared):
        for part in [pf.part for pf in loaded.push_functions] + [x.part for x in found.all]:
            check_for_part(uncertainty, part)
    planned: LandingPlan | None = None
    if not plans_over_landings(found.landings, landings is not None, accept is not None):
        print_warnings([*declared.warnings, *loaded.warnings])
        pfs = list(loaded.push_functions)
        json_found(members=[pf.part.name for pf in pfs])
        with (
            searching("planning and verifying", options.time_limit_s),
            flag_words(),
            stored_tolerance_words(declared),
            earlier_outputs_noted(output, report),
        ):
            made, witnesses = plan_mix(
                pfs, sensor, options, uncertainty=uncertainty, started=started
            )
    else:
        every = found.all
        names = {x.name for x in every} | {m for x in every for m in x.merged}
        taken = _accepted_names(accept, names)  # bad input: one line, before any warning
        pfs = [push_function(x.part) for x in every]
        print_warnings(
            [
                *declared.warnings,
                *found.warnings(over_landings=True),
                *found.left_out_words("the plan"),
            ]
        )
        json_found(members=[x.label for x in every])
        with (
            searching("planning and verifying", options.time_limit_s),
            flag_words(terms),
            stored_tolerance_words(declared),
            earlier_outputs_noted(output, report),
        ):
            planned = plan_landings(
                every, sensor, options, uncertainty=uncertainty, accept=taken, started=started
            )
        made, witnesses = planned.made, [p.witness for p in planned.indistinguishable]
    plan = made.plan
    cycle = annotate_cycle_time(made, settings)  # stats.cycle_time, before anything is written
    # The report takes the plan's verification (made once) and draws part plots only
    # within the limit.
    until = limit_instant(started, options.time_limit_s)
    files, view = plan_outputs(plan, pfs, witnesses, output, report, made.report, until)
    write_files(files)
    note_written((output, "plan"), (report, "report"))
    notes = [*made.warnings, *filter(None, [settings.belt_warning()])]
    note = time_limit_note(plan["stats"], options.time_limit_s)
    if note is not None:
        notes.append(note)
    print_warnings(notes)
    if json_out:
        print_plan_file(plan)
    else:
        sensor_given = sensorless or sensor.informative
        words = None if planned is None else _landings_text(planned)
        console.print(escape(settings.describe()), highlight=False)
        # The header's first line names the profile: say whether it or no option chose this.
        why = (
            "no sensor option given"
            if settings.profile.source == BUILT_IN
            else "no sensor option given, and the profile gives no sensor"
        )
        console.print(_header(plan, sensor_given, words, declared, why), highlight=False)
        console.print(plan_tree(view))
        console.print(stats_table(view, made.report))
        console.print(escape(cycle_line(cycle, settings)), highlight=False)
        print_written(output, report)
    if planned is not None:
        lumps = landing_lumps(planned)
        if planned.indistinguishable or lumps:
            raise CheckFailed(landing_pairs_message(planned, lumps))
    else:
        lumped = leaf_part_pairs(view)  # the plan as read back, not read again
        if witnesses or lumped:
            raise CheckFailed(pairs_message(witnesses, lumped))
    if made.unoriented is not None:
        raise CheckFailed(made.unoriented)
    if made.holds_nothing is not None:
        raise CheckFailed(made.holds_nothing)


IMPORT_MIN_S = 1.0
"""The least a plan's ``--time-limit`` leaves the import of its parts (:func:`within_limit`):
reading an ordinary file takes milliseconds, and a limit too short for any plan is answered
by the planner (no plan found, what it proved), not refused as input."""


def within_limit(import_opts: ImportOptions, options: PlanningOptions) -> ImportOptions:
    """The import options with the import's time limit no longer than the plan's
    ``--time-limit`` (at least ``IMPORT_MIN_S``), which then names itself when an import
    runs out of it: a mesh of hundreds of resting poses whose congruent landings took a
    minute to merge."""
    limits = import_opts.limits
    limit = None if options.time_limit_s is None else max(options.time_limit_s, IMPORT_MIN_S)
    if limit is None or limit >= limits.seconds:
        return import_opts
    return replace(
        import_opts, limits=replace(limits, seconds=limit, seconds_option="--time-limit")
    )


def register(app: typer.Typer) -> None:
    """Add the ``plan`` command to the app."""
    app.command("plan")(plan_command)
