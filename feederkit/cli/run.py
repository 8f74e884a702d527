"""``feederkit run PLAN SOURCE...``: execute a plan file on the kinematic model.

A thin layer over :mod:`feederkit.plans`: the parts named by SOURCE must be the plan's parts
(same hull and COM); one run from ``--start-deg`` step by step, or ``--all`` for the full
verification of those parts. Exit 1 when anything fails.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from feederkit.cli.common import CatalogOpt, JsonOpt, console, print_json
from feederkit.errors import CheckFailed, InputError
from feederkit.plans.execute import execute, kinematic_model
from feederkit.plans.fileformat import read_plan
from feederkit.plans.match import match_part
from feederkit.plans.render import trace_table, verification_table
from feederkit.plans.verify import verify_plan
from feederkit.sources import load_part


def run_command(
    plan_path: Annotated[Path, typer.Argument(metavar="PLAN", help="A plan file (JSON).")],
    sources: Annotated[
        list[str],
        typer.Argument(
            metavar="SOURCE", help="The part(s) to run: outline or CAD files, catalog names."
        ),
    ],
    start_deg: Annotated[
        float | None,
        typer.Option(
            "--start-deg",
            metavar="X",
            help="Fence orientation in the part frame at first contact (deg; default 0).",
        ),
    ] = None,
    all_starts: Annotated[
        bool,
        typer.Option("--all", help="Every stable start, every reading extreme, every branch."),
    ] = False,
    json_out: JsonOpt = False,
    catalog: CatalogOpt = None,
) -> None:
    """Execute a plan for the given part(s): each step's rotation, reading and branch, the pose."""
    if start_deg is not None and all_starts:
        raise InputError("choose one of --start-deg and --all")
    if start_deg is not None and not math.isfinite(start_deg):
        raise InputError(f"--start-deg must be a finite angle in degrees, got {start_deg}")
    plan = read_plan(plan_path)
    model = kinematic_model(plan)
    indices = []
    for source in sources:
        k = match_part(plan, load_part(source, catalog=catalog), source)
        if k not in indices:
            indices.append(k)
    if all_starts:
        report = verify_plan(model, indices)
        if json_out:
            print_json(report.to_dict())
        else:
            console.print(verification_table(report))
            if report.ok:
                console.print(f"all {report.paths} paths end in their result", highlight=False)
        if not report.ok:
            raise CheckFailed(f"the plan failed: {report.first_problem()}")
        return
    start = 0.0 if start_deg is None else start_deg
    traces = [execute(model, k, start) for k in indices]
    if json_out:
        print_json({"plan": str(plan_path), "runs": [t.to_dict() for t in traces]})
    else:
        for t in traces:
            console.print(trace_table(t))
            style = "green" if t.success else "bold red"
            console.print(t.message, style=style, highlight=False, markup=False, soft_wrap=True)
    failed = [t for t in traces if not t.success]
    if failed:
        raise CheckFailed(failed[0].message)


def register(app: typer.Typer) -> None:
    """Add the ``run`` command to the app."""
    app.command("run")(run_command)
