"""``feederkit report PLAN -o REPORT.html``: the self-contained HTML changeover report.

The plan is loaded and checked as ``run`` and ``simulate`` load it; a plan that fails
verification is still drawn, under a red banner that says so (docs/reports.md), and the
command exits 1 as ``run`` and ``simulate`` do: a result the user must act on. The report
is HTML only: ``-o`` must end in .html (print it to PDF from a browser).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any

import typer

from feederkit.cli.common import (
    check_outputs,
    check_report_name,
    console,
    note_written,
    plural,
    print_written,
    progress_bar,
)
from feederkit.cli.plan_render import DEFAULT_MAX_PLAN_MB, MaxPlanMbOpt, load_plan
from feederkit.errors import CheckFailed, InputError
from feederkit.jsonio import read_json, write_text_atomic
from feederkit.landing.model import renamed
from feederkit.mechanics.push import push_function
from feederkit.mix.changeover import rejected_members, reported_pairs
from feederkit.mix.pairs import unrecognizable_pairs
from feederkit.plans.model import Plan, member_name, push_function_of
from feederkit.plans.verify import verify_declared
from feederkit.reports import render_report


def _simulate(plan: Plan, trials: int, seed: int) -> dict[str, Any]:
    """Run the plan in the MuJoCo model (docs/simulation.md) and return its summary."""
    from feederkit.sim import require_mujoco, simulate_plan

    require_mujoco()
    with progress_bar() as bar:
        task = bar.add_task("simulating", total=trials)

        def progress(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        return simulate_plan(plan, trials, seed, progress=progress).to_dict()


def plan_pairs(plan: Plan) -> list[dict[str, Any]]:
    """The pairs of the plan's members no plan tells apart, with the mix analysis's witness
    and reason (``PairWitness.to_dict``), decided from the plan file alone as ``changeover
    report`` decides a stored changeover's: :func:`~feederkit.mix.pairs.unrecognizable_pairs`
    on the members' hulls and COMs (named ``PART/LANDING``), kept by
    :func:`~feederkit.mix.changeover.reported_pairs` (two rejected landings left out)."""
    if len(plan.parts) < 2:
        return []
    pfs = [
        push_function(renamed(push_function_of(p).part, member_name(*p.key))) for p in plan.parts
    ]
    found = unrecognizable_pairs(pfs, plan.sensor)
    return [w.to_dict() for w in reported_pairs(found, rejected_members(plan))]


def _cycle_time(path: Path) -> dict[str, Any] | None:
    """The plan file's ``stats.cycle_time`` (docs/cell.md), read from its JSON: the plan
    model keeps only the statistics it checks. None when the file has none."""
    try:
        raw = read_json(path, "plan file", max_depth=DEEP_JSON)
    except (InputError, RecursionError):
        return None  # the plan itself was read and checked; only the figure is missing
    stats = raw.get("stats") if isinstance(raw, dict) else None
    cycle = stats.get("cycle_time") if isinstance(stats, dict) else None
    return cycle if isinstance(cycle, dict) else None


DEEP_JSON = 10_000
"""How deep a plan file's JSON may nest when only its statistics are looked up."""


def report_command(
    plan: Annotated[Path, typer.Argument(help="A plan file (feederkit-plan JSON).")],
    output: Annotated[
        Path, typer.Option("-o", "--output", metavar="REPORT.html", help="The HTML file to write.")
    ],
    seconds_per_op: Annotated[
        float | None,
        typer.Option(
            "--seconds-per-op",
            metavar="S",
            help="Seconds per push-align operation: a flat cycle time instead of the plan's "
            "own (made with a cell profile, docs/cell.md).",
        ),
    ] = None,
    simulate: Annotated[
        int | None,
        typer.Option(
            "--simulate",
            metavar="N",
            help="Also run N trials in the MuJoCo model (feederkit[sim]); show the success rate.",
        ),
    ] = None,
    seed: Annotated[
        int, typer.Option("--seed", metavar="N", help="Random seed of --simulate.")
    ] = 0,
    max_plan_mb: MaxPlanMbOpt = DEFAULT_MAX_PLAN_MB,
) -> None:
    """Write one self-contained HTML page: the mix, the plan as a tree, statistics, part plots.

    A plan that fails verification is still drawn, under a red banner; exit 1 then.
    """
    check_report_name(output)  # .html, or a device such as /dev/null
    check_outputs((output, "report"))
    data = load_plan(plan, max_plan_mb)
    if seconds_per_op is not None and not (math.isfinite(seconds_per_op) and seconds_per_op > 0):
        raise InputError(
            f"--seconds-per-op must be a finite positive number of seconds, got {seconds_per_op:g}"
        )
    if simulate is not None and simulate < 1:
        raise InputError(f"--simulate must be a finite positive number of trials, got {simulate}")
    simulation = None if simulate is None else _simulate(data, simulate, seed)
    # One verification: the page's banner shows it, the exit code says it (design.md).
    verdict = verify_declared(data)
    html = render_report(
        data,
        seconds_per_op=seconds_per_op,
        simulation=simulation,
        cycle_time=None if seconds_per_op is not None else _cycle_time(plan),
        unrecognizable=plan_pairs(data),
        verification=verdict,
    )
    write_text_atomic(output, html, what="report")  # its name checked above
    note_written((output, "report"))
    if simulation is not None:
        console.print(
            f"simulated {plural(simulation['successes'], 'success', 'successes')} in "
            f"{plural(simulation['trials'], 'trial')}",
            highlight=False,
            markup=False,
        )
    print_written(None, output)  # in the words of plan and changeover
    if not verdict.ok:
        raise CheckFailed(
            f"the plan failed verification: {verdict.first_problem()} (the report {output} "
            "shows it under a red banner; do not run this plan)"
        )


def register(app: typer.Typer) -> None:
    """Add the ``report`` command to the app."""
    app.command("report")(report_command)
