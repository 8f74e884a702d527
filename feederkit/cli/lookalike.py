"""``feederkit lookalike SOURCE --keep push|push-diameter [-o OUT.json]`` (Theorems 4 and 6).

Builds a non-similar convex polygon with the same push function or the same push-diameter
function as SOURCE, checks it, writes its outline file (with the source's center of mass
stated) and prints what was checked. Without ``-o`` the outline goes to stdout and the
check to stderr.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from feederkit.cli.common import (
    CatalogOpt,
    JsonOpt,
    check_outputs,
    console,
    err_console,
    print_json,
)
from feederkit.cli.importopts import print_import_warnings, takes_import_options
from feederkit.errors import InputError
from feederkit.importers import ImportOptions
from feederkit.jsonio import write_text_atomic
from feederkit.mix.lookalike import build_lookalike
from feederkit.outline import outline_to_dict
from feederkit.sources import load_part_with_warnings


@takes_import_options
def lookalike_command(
    source: Annotated[str, typer.Argument(help="An outline file, CAD file or catalog part name.")],
    keep: Annotated[
        str,
        typer.Option(
            "--keep",
            metavar="push|push-diameter",
            help="What the look-alike keeps: push or push-diameter.",
        ),
    ],
    output: Annotated[
        Path | None,
        typer.Option("-o", "--output", metavar="OUT.json", help="Outline file (.json) to write."),
    ] = None,
    name: Annotated[
        str | None, typer.Option("--name", metavar="NAME", help="Name of the new part.")
    ] = None,
    seed: Annotated[
        int, typer.Option("--seed", metavar="N", help="Seed of the construction's choices.")
    ] = 0,
    catalog: CatalogOpt = None,
    import_opts: ImportOptions = ImportOptions(),
    json_out: JsonOpt = False,
) -> None:
    """A non-similar part with the same push function (Theorem 4) or the same push-diameter
    function (Theorem 6), checked numerically before it is written.

    With --json the check and the outline are printed as one JSON object (the outline is
    still written to -o when given)."""
    if keep not in ("push", "push-diameter"):
        raise InputError(f"--keep must be push or push-diameter, got {keep!r}")
    if output is not None and output.suffix.lower() != ".json":
        raise InputError(f"{output}: the look-alike is written as an outline file (.json)")
    check_outputs((output, "file"))
    loaded = load_part_with_warnings(source, catalog=catalog, options=import_opts)
    print_import_warnings(source, loaded.warnings)
    part = loaded.part
    result = build_lookalike(part, keep, seed)
    data = outline_to_dict(result.part.outline)
    if name:
        data["name"] = name
    text = json.dumps(data, indent=2) + "\n"
    check = result.check
    table = Table(title=f"look-alike of {part.name} (keep {keep})", show_header=False)
    table.add_row("construction", result.construction)
    table.add_row("hull vertices", f"{check.source_vertices} -> {check.vertices}")
    table.add_row(
        "same push function",
        _yes(check.same_push) + f" (max error {check.angle_error_deg:.2g} deg)",
    )
    table.add_row(
        "same push-diameter function",
        _yes(check.same_push_diameter) + f" (max diameter error {check.diameter_error_mm:.2g} mm)",
    )
    table.add_row("similar to the source", _yes(check.similar))
    table.add_row(
        "center of mass",
        f"({part.com[0] + 0.0:.6g}, {part.com[1] + 0.0:.6g}) mm, stated in the file",  # no -0
    )
    if json_out:
        if output is not None:
            write_text_atomic(output, text)
        print_json(
            {
                "source": part.name,
                "keep": keep,
                "construction": result.construction,
                "hull_vertices": [check.source_vertices, check.vertices],
                "same_push": check.same_push,
                "max_angle_error_deg": check.angle_error_deg,
                "same_push_diameter": check.same_push_diameter,
                "max_diameter_error_mm": check.diameter_error_mm,
                "similar": check.similar,
                "output": None if output is None else str(output),
                "outline": data,
            }
        )
        return
    if output is None:
        err_console.print(table)
        typer.echo(text, nl=False)
        return
    write_text_atomic(output, text)
    console.print(table)
    console.print(f"wrote {output}", highlight=False, markup=False, soft_wrap=True)


def _yes(flag: bool) -> str:
    return "yes" if flag else "no"


def register(app: typer.Typer) -> None:
    """Add ``lookalike`` to the app."""
    app.command("lookalike")(lookalike_command)
