"""``feederkit report PLAN -o REPORT.html``: the self-contained HTML changeover report."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from feederkit.cli.common import console, progress_bar
from feederkit.errors import InputError
from feederkit.reports import read_plan_file, render_report, write_report


def _simulate(plan: dict[str, Any], trials: int, seed: int) -> dict[str, Any]:
    """Run the plan in the MuJoCo model (issue 7) and return its summary for the page."""
    from feederkit.sim import require_mujoco, simulate_plan

    require_mujoco()
    with progress_bar() as bar:
        task = bar.add_task("simulating", total=trials)

        def progress(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        return simulate_plan(plan, trials, seed, progress=progress).to_dict()


def report_command(
    plan: Annotated[Path, typer.Argument(help="A plan file (feederkit-plan JSON).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="The HTML file to write.")],
    seconds_per_op: Annotated[
        float | None,
        typer.Option("--seconds-per-op", help="Seconds per push-align operation: adds cycle time."),
    ] = None,
    simulate: Annotated[
        int | None,
        typer.Option(
            "--simulate",
            metavar="N",
            help="Also run N trials in the MuJoCo model (feederkit[sim]); show the success rate.",
        ),
    ] = None,
    seed: Annotated[int, typer.Option("--seed", help="Random seed of --simulate.")] = 0,
) -> None:
    """Write one self-contained HTML page: the mix, the plan as a tree, statistics, part plots."""
    data = read_plan_file(plan)
    if simulate is not None and simulate < 1:
        raise InputError(f"--simulate must be a positive number of trials, got {simulate}")
    simulation = None if simulate is None else _simulate(data, simulate, seed)
    html = render_report(data, seconds_per_op=seconds_per_op, simulation=simulation)
    write_report(output, html)
    if simulation is not None:
        console.print(
            f"simulated {simulation['successes']} successes in {simulation['trials']} trials",
            highlight=False,
            markup=False,
        )
    console.print(f"wrote {output}", highlight=False, markup=False)


def register(app: typer.Typer) -> None:
    """Add the ``report`` command to the app."""
    app.command("report")(report_command)
