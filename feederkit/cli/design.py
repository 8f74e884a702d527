"""``feederkit design sensor SOURCE... | --mix A,B,...``: which sensor a product mix needs.

A thin layer over :mod:`feederkit.design`: read the cell profile (``--cell FILE`` or
``./feederkit.toml``) and the command line's overrides, with the declared uncertainty
(``--rotation-error``, ``--shape-tolerance``, ``--com-tolerance``, as ``plan`` takes them),
load the parts with their landings (each landing one member of the mix, as ``plan`` plans
it; ``--landings`` picks them, ``--accept`` names those the next station takes, exactly as
``changeover compile`` reads them), decide the critical tolerances (or each LED pitch) for
strong plans at that uncertainty, print the tables, the one-line answer, the profile and
the uncertainty used, and exit 1 when no sensor in the range makes the mix recognizable
(docs/design.md). While it runs, a progress bar on stderr (on a terminal only, so
``--json`` output stays clean) shows the pairs decided, then the length table; past
``--time-limit`` it stops with one line saying what was decided (exit 1), after printing
the pairs' table when every pair was decided (a tolerance sensor's design without its
length table).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from feederkit.cell import load_cell
from feederkit.cli.catalog_analyze import name_width
from feederkit.cli.common import (
    FLAG_TERMS,
    LANDING_TERMS,
    AcceptOpt,
    CatalogOpt,
    ComToleranceOpt,
    JsonOpt,
    LandingsOpt,
    ShapeToleranceOpt,
    add_name_column,
    check_mix_revision,
    check_outputs,
    console,
    declared_uncertainty,
    default_memory_limit,
    fail,
    flag_tolerance,
    flag_words,
    json_found,
    print_json,
    print_warnings,
    progress_bar,
    stored_tolerance_words,
    uncertainty_option,
    uncertainty_text,
)
from feederkit.design.limit import DesignTimeout, check_limits
from feederkit.design.pitches import parse_pitches
from feederkit.design.sensor import (
    PitchDesign,
    ToleranceDesign,
    design_pitches,
    design_tolerance,
    landing_design_members,
    member_landing_rows,
)
from feederkit.errors import InputError
from feederkit.landing.plan import landing_names, load_landings
from feederkit.mechanics import push_function
from feederkit.mix.changeover import plans_over_landings
from feederkit.words import shown_tolerance

design_app = typer.Typer(
    rich_markup_mode="markdown",
    name="design",
    help="Choose the cell: which sensor a product mix needs.",
    no_args_is_help=True,
)

DEFAULT_DESIGN_TIME_LIMIT_S = 300.0
"""``design sensor``'s time limit unless ``--time-limit`` is given. Longer than ``plan``'s
60 s: a design has no anytime answer (at the limit all its work is lost, not a best plan
kept), it is run once per changeover, and a 50-part mix of the benchmark takes over a
minute at the default rotation error; five minutes still stop a mix that would run for
hours (docs/design.md, "Time limit")."""

SHOWN_PAIRS = 10
"""Pairs listed on the terminal (the lowest critical tolerances); --json lists every pair."""


def parse_mix(text: str) -> list[str]:
    """``--mix A,B,...``: catalog part names, each once; InputError for an empty name."""
    names = [t.strip() for t in text.split(",")]
    if not names or any(not n for n in names):
        raise InputError(f"--mix must list part names separated by commas, got {text!r}")
    for n in names:
        check_mix_revision(n)
        if ":" in n:
            raise InputError(
                f"--mix {n}: design sensor takes part names only; mix shares weigh expected "
                "figures, which it computes for equal shares"
            )
    return names


@design_app.command("sensor")
def sensor_command(
    sources: Annotated[
        list[str] | None,
        typer.Argument(help="Outline or CAD files or catalog part names (or use --mix)."),
    ] = None,
    mix: Annotated[
        str | None, typer.Option("--mix", metavar="A,B,...", help="Catalog part names.")
    ] = None,
    pitches: Annotated[
        str | None,
        typer.Option(
            "--pitches",
            metavar="P,...|START:STOP:STEP",
            help="Design an LED array: these pitches (mm), each evaluated on its own.",
        ),
    ] = None,
    noise: Annotated[
        float | None,
        typer.Option("--noise", metavar="MM", help="The LED array's alignment noise (mm)."),
    ] = None,
    max_tolerance: Annotated[
        float | None,
        typer.Option(
            "--max-tolerance",
            metavar="MM",
            help="Tabulate lengths up to this tolerance (default: the critical tolerance).",
        ),
    ] = None,
    rotation_error: Annotated[
        float | None,
        typer.Option(
            "--rotation-error",
            metavar="DEG",
            help="The robot's rotation is off by up to ±DEG (default: the cell profile's, 1; "
            "0 with the tolerances 0: the ideal model).",
        ),
    ] = None,
    shape_tolerance: ShapeToleranceOpt = None,
    com_tolerance: ComToleranceOpt = None,
    cell: Annotated[
        Path | None,
        typer.Option("--cell", metavar="FILE", help="Cell profile (default ./feederkit.toml)."),
    ] = None,
    plot: Annotated[
        Path | None,
        typer.Option("--plot", metavar="FILE.png|svg", help="Also draw the lengths here."),
    ] = None,
    time_limit: Annotated[
        float,
        typer.Option(
            "--time-limit",
            metavar="S",
            help="Seconds; past them the design stops with one line saying what it decided "
            "(exit 1), printing the pairs' table when every pair was decided.",
        ),
    ] = DEFAULT_DESIGN_TIME_LIMIT_S,
    memory_limit: Annotated[
        float | None,
        typer.Option(
            "--memory-limit",
            metavar="MB",
            help="Stop when the process holds this many megabytes, with one line as at the "
            "time limit (default: half the machine's memory).",
        ),
    ] = None,
    landings: LandingsOpt = None,
    accept: AcceptOpt = None,
    catalog: CatalogOpt = None,
    json_out: JsonOpt = False,
) -> None:
    """The exact critical tolerance (or LED pitch) of a mix and its pairs (Theorem 9), and
    the optimal plan length as a step function of the tolerance, for strong plans at the
    declared uncertainty (``--rotation-error``, default 1 degree; all 0: the ideal model).

    Every landing of every part is a member of the mix, as ``plan`` plans it (a flat part
    face up and face down, a mesh in each resting pose; ``--landings up`` designs for the
    parts face up only). Landings not in ``--accept`` end in reject results, as ``changeover
    compile --accept`` plans them: the design is then of plans that tell the accepted
    landings apart from each other and from the rejected ones (docs/design.md)."""
    names = list(sources or [])
    if mix is not None:
        if names:
            raise InputError("give the parts as SOURCE... or as --mix, not both")
        names = parse_mix(mix)
    if not names:
        raise InputError("no parts: give SOURCE... or --mix A,B,...")
    profile = load_cell(cell)
    r = profile.robot.rotation_error_deg if rotation_error is None else rotation_error
    # Validates r and the flags; the tolerances are the parts' when not given (below).
    uncertainty = uncertainty_option(
        r, flag_tolerance(shape_tolerance), flag_tolerance(com_tolerance)
    )
    led = pitches is not None or profile.sensor.model == "led"
    if not led and noise is not None:
        raise InputError("--noise goes with --pitches (or a profile with an LED array)")
    if led:
        default = (float(profile.sensor.pitch_mm or 0.0),)  # a profile's LED array has one
        values = parse_pitches(pitches) if pitches is not None else default
        e = noise if noise is not None else profile.sensor.noise_mm
        if not e >= 0.0:
            raise InputError(f"--noise must be zero or a positive number of mm, got {e}")
    if plot is not None and plot.suffix.lower() not in (".png", ".svg"):
        raise InputError(f"{plot}: the plot is written as .png or .svg")
    check_outputs((plot, "plot"))
    if memory_limit is None:
        memory_limit = default_memory_limit()
    with flag_words():
        check_limits(time_limit, memory_limit)

    terms = (*FLAG_TERMS, *LANDING_TERMS)
    with flag_words(terms):
        # As ``changeover compile`` reads them: the same parser, then the library's checks.
        which = "all" if landings in (None, "all") else landing_names(landings)
        accepted = None if accept is None else landing_names(accept, "--accept")
        found = load_landings(names, catalog=catalog, which=which)
    loaded = found.parts
    uncertainty, declared = declared_uncertainty(
        r, loaded.tolerances, shape_tolerance, com_tolerance
    )
    # design.md: plans cover every landing unless told otherwise, so the design is of the
    # mix whose members are the landings, as ``plan`` and ``changeover compile`` plan it.
    over_landings = plans_over_landings(found.landings, landings is not None, accepted is not None)
    members = None
    if over_landings:
        pfs = [push_function(x.part) for x in found.all]
        with flag_words(terms):
            members = landing_design_members(found.all, accepted)
    else:
        pfs = list(loaded.push_functions)
    json_found(
        parts=[pf.part.name for pf in pfs],
        landings=member_landing_rows(members),
        cell_profile=profile.source,
        uncertainty=uncertainty.to_dict(),
        uncertainty_from=declared.sources(),
    )
    # The design's expected figures weigh its members alike (plan weighs each part's landings).
    kind = "landings" if over_landings else "parts"
    design: ToleranceDesign | PitchDesign
    with progress_bar() as bar, flag_words(terms), stored_tolerance_words(declared):
        tasks: dict[str, Any] = {}

        def progress(what: str, done: int, total: int) -> None:
            if what not in tasks:
                tasks[what] = bar.add_task(what, total=total)
            bar.update(tasks[what], completed=done, total=total)

        try:
            if led:
                design = design_pitches(
                    pfs,
                    values,
                    noise=e,
                    uncertainty=uncertainty,
                    time_limit_s=time_limit,
                    progress=progress,
                    memory_limit_mb=memory_limit,
                    members=members,
                )
            else:
                design = design_tolerance(
                    pfs,
                    max_tolerance=max_tolerance,
                    uncertainty=uncertainty,
                    time_limit_s=time_limit,
                    progress=progress,
                    memory_limit_mb=memory_limit,
                    partial=True,
                    members=members,
                )
        except DesignTimeout as exc:
            hints = {"memory": "memory with --memory-limit MB", "time": "time with --time-limit S"}
            more = hints[exc.reason]
            raise DesignTimeout(f"{exc}; allow more {more}", exc.reason) from None
    # stderr, with --json too; after bad options are refused; fragile states per landing
    print_warnings([*declared.warnings, *found.warnings(over_landings)])
    if plot is not None:
        from feederkit.design.plot import plot_design

        plot_design(design, plot)

    if json_out:
        data = design.to_dict()
        data["cell_profile"] = profile.source
        data["uncertainty_from"] = declared.sources()
        if plot is not None:
            data["plot"] = str(plot)
        print_json(data)
    else:
        if design.rejected:
            console.print(
                f"rejected {kind} (they end in reject results; two of them need not be told "
                f"apart): {', '.join(design.rejected)}",
                highlight=False,
                markup=False,
                soft_wrap=True,
            )
        if isinstance(design, ToleranceDesign):
            _print_tolerance(design, kind)
        else:
            _print_pitches(design, kind)
        model = "" if uncertainty.is_ideal else " (the figures are for strong plans)"
        console.print(
            f"cell profile: {profile.source}; uncertainty: "
            f"{uncertainty_text(uncertainty.to_dict(), declared)}{model}",
            highlight=False,
            markup=False,
            soft_wrap=True,
        )
        if plot is not None:
            console.print(f"wrote {plot}", highlight=False, markup=False, soft_wrap=True)
        console.print(design.answer(), highlight=False, markup=False, soft_wrap=True)
    if isinstance(design, ToleranceDesign) and not design.complete:
        fail(f"{design.answer()}; allow more with --time-limit S or --memory-limit MB", code=1)
    if not design.recognizable:
        fail(design.answer(), code=1)


def _mm(x: float | None) -> str:
    """A critical tolerance (a largest value that works) for display (``shown_tolerance``)."""
    return "none" if x is None else shown_tolerance(x)


def names(pairs: Iterable[Any]) -> Iterator[str]:
    """The member names of a design's pairs (``a`` and ``b`` of each)."""
    for p in pairs:
        yield from (p.a + " &", p.b)


def _pairs_table(design: ToleranceDesign | PitchDesign) -> Table:
    pairs = sorted(
        design.critical.pairs,
        key=lambda p: -1.0 if p.critical_tolerance is None else p.critical_tolerance,
    )
    shown = pairs[:SHOWN_PAIRS]
    more = len(pairs) - len(shown)
    title = "critical tolerance of each pair (the largest that still tells them apart)"
    if more > 0:
        title += f"; the {len(shown)} lowest of {len(pairs)}"
    if design.rejected:
        title += "; none of two rejected ones"
    table = Table(title=title)
    # One column, a name a line: each name whole (its landing shown) at 80 columns.
    add_name_column(table, "parts (a & b)", width=name_width([*names(shown)]))
    table.add_column("critical tolerance (mm)", justify="right")
    table.add_column("why not", overflow="fold")
    for p in shown:
        why = p.witness.reason if p.witness is not None else ""
        table.add_row(f"{p.a} &\n{p.b}", _mm(p.critical_tolerance), why)
    return table


def _print_tolerance(design: ToleranceDesign, members: str) -> None:
    console.print(_pairs_table(design))
    what = "optimal plan length" if design.uncertainty.is_ideal else "optimal strong plan length"
    table = Table(title=f"{what} by tolerance (each step holds on (lo, hi])")
    table.add_column("tolerance (mm)")
    table.add_column("length", justify="right")
    table.add_column(f"expected (at hi; {members} equally likely)", justify="right")
    for s in design.steps:
        hi = "..." if s.hi is None else shown_tolerance(s.hi)  # the step holds up to hi
        length = "no strong plan" if s.length is None else str(s.length)
        expected = "-" if s.expected is None else f"{s.expected:.4f}"
        table.add_row(f"({shown_tolerance(s.lo)}, {hi}]", length, expected)  # both ends alike
    if design.steps:
        console.print(table)


def _print_pitches(design: PitchDesign, members: str) -> None:
    table = Table(title=f"LED pitches, each on its own (noise {design.noise:g} mm)")
    table.add_column("pitch (mm)", justify="right", max_width=7)
    table.add_column("recognizable")
    table.add_column("length", justify="right")
    table.add_column(f"expected ({members} equally likely)", justify="right", max_width=10)
    shown = [n for row in design.rows for pair in row.unrecognizable[:3] for n in pair]
    table.add_column("pairs it cannot tell apart", overflow="fold", width=name_width(shown) + 2)
    for row in design.rows:
        bad = ",\n".join(f"{a} & {b}" for a, b in row.unrecognizable[:3])  # a pair a line
        if len(row.unrecognizable) > 3:
            bad += f" and {len(row.unrecognizable) - 3} more"
        if row.no_plan is not None:
            bad = row.no_plan
        table.add_row(
            f"{row.pitch:.6g}",
            "yes" if row.recognizable else "no",
            "-" if row.length is None else str(row.length),
            "-" if row.expected is None else f"{row.expected:.4f}",
            bad,
        )
    console.print(table)
    x = design.critical.critical_tolerance
    exact = (
        "no tolerance tells every pair apart" if x is None else f"critical tolerance {_mm(x)} mm"
    )
    console.print(
        f"for comparison, an exact diameter sensor: {exact}",
        highlight=False,
        markup=False,
    )


def register(app: typer.Typer) -> None:
    """Add ``design sensor`` to the app."""
    app.add_typer(design_app, name="design")
