"""``feederkit simulate PLAN``: check a plan in MuJoCo over many trials (docs/simulation.md).

The plan is loaded and checked as ``run`` and ``report`` load it, and verified at its declared
uncertainty first (a strong plan: every outcome and reading): a plan that fails verification
exits 1 before any trial. Each trial samples the declared uncertainty and the friction ranges
(``--ideal``: nothing sampled); a trial the plan's model did not predict is listed first. Trial
failures are data: the command exits 0 whatever the success rate, unless
``--require-success`` names a rate the run must reach (then exit 1 below it).
Without MuJoCo it exits 2 with one line saying to install ``feederkit[sim]``.

``--part SOURCE`` (``NAME=SOURCE`` for a part of a mix, repeatable) simulates that member on
the part a SOURCE holds, its outline's exact hull and its own COM, instead of the plan's
hull, and judges its trials by where the part rests (docs/simulation.md, "A part's own
outline"); a SOURCE that is not the plan's part is bad input (exit 2). The match check allows
the hull tolerance stored with the catalog revision the plan was made from, when the catalog
in use holds it (``--hull-tolerance`` overrides it).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from feederkit.cli.common import (
    CatalogOpt,
    add_name_column,
    console,
    err_console,
    json_found,
    json_option,
    plural,
    print_json,
    print_warnings,
)
from feederkit.cli.plan_render import DEFAULT_MAX_PLAN_MB, MaxPlanMbOpt, load_plan
from feederkit.errors import CheckFailed, InputError
from feederkit.importers import ImportOptions
from feederkit.part import Part
from feederkit.plans.model import REJECTED_WORDS, UNRECOGNIZED_WORDS, member_label
from feederkit.sim.api import (
    DEFAULT_BELT_SPEED,
    DEFAULT_FRICTION_BELT_RANGE,
    DEFAULT_FRICTION_FENCE_RANGE,
    check_rotation_noise,
    simulate_plan,
)
from feederkit.sim.engine import require_mujoco
from feederkit.sim.real import RealPart, real_parts
from feederkit.sim.summary import SimulationSummary
from feederkit.sim.trial import CAUSES

SHOWN_ROWS = 20
"""Failures and misses listed in the terminal (all of them are in ``--json``)."""


def _print_summary(s: SimulationSummary, declared: str) -> None:
    st = s.settings
    console.print(
        f"[bold]simulated[/] {escape(', '.join(s.parts))}: {plural(st.trials, 'trial')}, "
        f"seed {st.seed}, "
        f"belt {st.belt_speed:g} m/s; declared uncertainty: {escape(declared)}; "
        f"{escape(st.sampled_words())}; contact: {escape(st.contact)}",
        highlight=False,
        soft_wrap=True,
    )
    if s.real_parts:
        for _name, words in s.geometry():
            console.print(f"[bold]geometry[/] {escape(words)}", highlight=False, soft_wrap=True)
        if s.pose_rule is not None:
            console.print(
                f"[bold]success rule[/] {escape(s.pose_rule.words())}",
                highlight=False,
                soft_wrap=True,
            )
    table = Table(show_header=False, box=None, pad_edge=False)
    table.add_row("successes", escape(s.success_words()))
    if len(s.parts) > 1:
        for name, t, k in zip(s.parts, s.part_trials, s.part_successes, strict=True):
            table.add_row(f"  {escape(name)}", f"{k} of {t}")
    if s.rejects:
        table.add_row("  of them", f"{s.rejects} {REJECTED_WORDS}")
    if s.unrecognized:
        table.add_row("  of them", f"{s.unrecognized} {UNRECOGNIZED_WORDS}")
    table.add_row("failures", str(len(s.failures)))
    if s.wrong_accepts:
        table.add_row("  wrong accepts", f"{s.wrong_accepts} (accepted, landing or state wrong)")
    table.add_row("never settled", str(len(s.unsettled)))
    table.add_row("model errors (not predicted)", str(s.model_errors))
    for cause, n in s.by_cause().items():
        # Finer than the simulated widths are accurate, such readings measure the simulator.
        why = " (the simulator's widths: see the warning)" if cause == CAUSES[2] else ""
        table.add_row(f"  {escape(cause)}", f"{n}{why if s.width_warning else ''}")
    table.add_row("push agreement", s.push_words())
    # As plan prints it (plan_render): the same digits in both places.
    margin = "none (no rotations)" if s.min_margin_deg is None else f"±{s.min_margin_deg:.4f}°"
    table.add_row("plan's smallest margin", margin)
    if s.certified is not None:
        table.add_row(f"plan {s.certified.verb}", escape(s.certified.words()))
    table.add_row(
        "wall time", f"{s.wall_time_s:.2f} s ({plural(s.pushes, 'push-align operation')})"
    )
    console.print(table)
    for note in s.scale_notes():  # "N of N" is about the part at the simulated size
        console.print(f"[yellow]note:[/] {escape(note)}", highlight=False, soft_wrap=True)
    if s.beyond_certified:
        console.print(f"[yellow]note:[/] {escape(s.beyond_certified)}", highlight=False)
    rows = s.went_wrong
    if rows:
        t = Table(title="trials that went wrong (model errors first)", title_justify="left")
        for col in ("trial", "part", "start deg", "step", "cause", "model predicted", "what"):
            t.add_column(col, overflow="fold")
        for r in rows[:SHOWN_ROWS]:
            t.add_row(
                str(r.index),
                escape(member_label(r.part, r.landing)),  # a landing the plan rejects, or not
                f"{r.start_deg:.2f}",
                str(r.step),
                escape(r.cause or ""),
                "yes" if r.predicted else "[bold red]no: model error[/]",
                escape(r.reason or ""),
            )
        console.print(t)
        if len(rows) > SHOWN_ROWS:
            console.print(f"... and {len(rows) - SHOWN_ROWS} more (see --json)")
    if s.push_misses:
        t = Table(title="pushes that disagree with the push function", title_justify="left")
        cols = (
            "trial",
            "part",
            "step",
            "theta deg",
            "from divergent",
            "predicted",
            "its margin",
            "sim",
        )
        for col in cols:
            if col == "part":
                add_name_column(t, col)
            else:
                t.add_column(col)
        for m in s.push_misses[:SHOWN_ROWS]:
            t.add_row(
                str(m.trial),
                escape(m.part),
                str(m.step),
                f"{m.theta_deg:.2f}",
                f"{m.divergent_distance_deg:.2f} deg",
                str(m.predicted_state),
                f"{m.predicted_margin_deg:.2f} deg",
                "-" if m.simulated_state is None else str(m.simulated_state),
            )
        console.print(t)


def simulate_command(
    plan: Annotated[Path, typer.Argument(help="A plan file (feederkit-plan JSON).")],
    trials: Annotated[
        int, typer.Option("--trials", min=1, metavar="N", help="Number of trials.")
    ] = 100,
    seed: Annotated[
        int, typer.Option("--seed", metavar="N", help="Seed of the random starts and errors.")
    ] = 0,
    ideal: Annotated[
        bool,
        typer.Option(
            "--ideal", help="Sample nothing: the drawn part, nominal friction, exact rotations."
        ),
    ] = False,
    rotation_noise: Annotated[
        float | None,
        typer.Option(
            "--rotation-noise",
            help="Draw rotation errors in [-DEG, +DEG] instead of the plan's declared error "
            "(a stress test beyond what the plan claims; not with --ideal).",
            metavar="DEG",
            show_default=False,
        ),
    ] = None,
    belt_speed: Annotated[
        float, typer.Option("--belt-speed", help="Belt speed.", metavar="M/S")
    ] = DEFAULT_BELT_SPEED,
    friction_belt: Annotated[
        str,
        typer.Option(
            "--friction-belt",
            help="Part-belt friction, drawn per trial from LO:HI (or one value).",
            metavar="LO:HI",
        ),
    ] = DEFAULT_FRICTION_BELT_RANGE.text(),
    friction_fence: Annotated[
        str,
        typer.Option(
            "--friction-fence",
            help="Part-fence friction, drawn per trial from LO:HI (or one value).",
            metavar="LO:HI",
        ),
    ] = DEFAULT_FRICTION_FENCE_RANGE.text(),
    require_success: Annotated[
        float | None,
        typer.Option(
            "--require-success",
            help="Exit 1 when the success rate falls below this fraction (0-1).",
            metavar="RATE",
        ),
    ] = None,
    parts: Annotated[
        list[str] | None,
        typer.Option(
            "--part",
            metavar="[NAME=]SOURCE",
            help="Simulate the plan's part NAME on the part SOURCE holds (an outline or CAD "
            "file, or a catalog name): its outline's exact hull and own COM, judged by where it "
            "rests. NAME= may be left out for a plan of one part; repeat for a mix.",
            show_default=False,
        ),
    ] = None,
    hull_tolerance: Annotated[
        float | None,
        typer.Option(
            "--hull-tolerance",
            metavar="MM",
            help="With --part: the hull tolerance the plan's part was imported with, which the "
            "match check allows (default: the one stored with the catalog revision the plan "
            "was made from, else a CAD import's for the part's size).",
            show_default=False,
        ),
    ] = None,
    catalog: CatalogOpt = None,
    json_out: Annotated[bool, json_option("Print the summary as JSON.")] = False,
    max_plan_mb: MaxPlanMbOpt = DEFAULT_MAX_PLAN_MB,
) -> None:
    """Execute a plan in a MuJoCo conveyor, fence and robot and compare it with its claims."""
    require_mujoco()  # InputError (exit 2): install feederkit[sim]
    if require_success is not None and not 0.0 <= require_success <= 1.0:
        raise InputError(f"--require-success must be a fraction in [0, 1], got {require_success:g}")
    check_rotation_noise(rotation_noise, ideal=ideal)  # before the plan: one line, exit 2
    if hull_tolerance is not None and not parts:
        raise InputError("--hull-tolerance goes with --part (the match check's allowance)")
    data = load_plan(plan, max_plan_mb)  # the one loader and validator
    real: tuple[RealPart, ...] = ()
    if parts:
        db = None if catalog is None else str(catalog)
        real = real_parts(
            data, parts, catalog=db, hull_tolerance=hull_tolerance, landings=_landing_parts
        )
    json_found(
        plan=str(plan),
        uncertainty=data.uncertainty.to_dict(),
        uncertainty_declared=data.uncertainty_declared,
    )
    held = [data.low_margin_warning(), data.ideal_model_warning()]
    print_warnings(line for line in [*held, *(r.tolerance_warning() for r in real)] if line)
    columns = (
        TextColumn("simulating"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("trials"),
        TimeRemainingColumn(),
    )
    with Progress(
        *columns, console=err_console, transient=True, disable=not err_console.is_terminal
    ) as bar:
        task = bar.add_task("simulate", total=trials)

        def advance(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        summary = simulate_plan(
            data,
            trials,
            seed,
            rotation_noise_deg=rotation_noise,
            belt_speed=belt_speed,
            friction_belt=friction_belt,
            friction_fence=friction_fence,
            progress=advance,
            ideal=ideal,
            real=real,
        )
    if json_out:
        print_json(
            {
                **summary.to_dict(),
                "uncertainty": data.uncertainty.to_dict(),
                "uncertainty_declared": data.uncertainty_declared,
            }
        )
    else:
        _print_summary(summary, data.uncertainty_words())
    if summary.width_warning:  # stderr, one line, as every warning (docs/cli.md)
        print_warnings([summary.width_warning])
    if require_success is not None and summary.success_rate < require_success:
        raise CheckFailed(
            f"{summary.successes} of {plural(summary.trials, 'trial')} succeeded "
            f"({100 * summary.success_rate:.1f}%), below the required {100 * require_success:g}%"
        )


def _landing_parts(
    source: str, held: tuple[str, ...], catalog: str | None, options: ImportOptions | None
) -> dict[str, Part]:
    """A SOURCE's part in each landing named, loaded as ``run`` checks a plan over landings."""
    from feederkit.landing.plan import load_landings

    found = load_landings([source], catalog=catalog, options=options, which=held)
    return {x.name: x.part for x in found.all}


def register(app: typer.Typer) -> None:
    """Add the ``simulate`` command to the app."""
    app.command("simulate")(simulate_command)
