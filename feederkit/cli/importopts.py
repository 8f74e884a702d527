"""The import options every command that takes a SOURCE shares, and how it prints import warnings.

One place for the typer option types (``--units --layer --all-parts --pose --space
--keep-linetype`` and the import budgets, docs/import.md), the builder of
:class:`~feederkit.importers.ImportOptions` and the printing of the importer's warnings
(parts left out, frames skipped, gaps closed, units in doubt), so ``part analyze``, ``part
plot``, ``lookalike``, ``plan`` and ``catalog`` say the same thing about the same file.

A command takes them all with :func:`takes_import_options`: it declares one parameter
``import_opts: ImportOptions`` and gets the options (same names, defaults and help on every
command) in its place.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
from collections.abc import Callable, Iterable
from typing import Annotated, Any, TypeVar

import typer

from feederkit.errors import InputError
from feederkit.importers import (
    DEFAULT_FLATTEN_TOLERANCE,
    DEFAULT_HULL_TOLERANCE,
    DEFAULT_MAX_FILE_MB,
    ImportOptions,
)
from feederkit.importers.budget import (
    DEFAULT_MAX_CROSSINGS,
    DEFAULT_MAX_ENTITIES,
    DEFAULT_MAX_FACES,
    DEFAULT_MAX_HULL_FACES,
    DEFAULT_MAX_LOOPS,
    DEFAULT_MAX_VERTICES,
    DEFAULT_TIME_LIMIT_S,
    ImportLimits,
)
from feederkit.importers.model import REL_HULL_TOLERANCE

UnitsOpt = Annotated[
    str | None,
    typer.Option(
        "--units",
        metavar="UNIT",
        help="Units of the file's coordinates (mm, cm, m, in, ft, um): overrides the file.",
    ),
]
LayerOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--layer", metavar="NAME", help="DXF layer to read (repeat for several; default all)."
    ),
]
KeepLinetypeOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--keep-linetype",
        metavar="NAME",
        help="Keep closed DXF loops drawn in this hidden or centre linetype (e.g. HIDDEN) as "
        "outline or holes; left out by default (repeat for several).",
    ),
]
SpaceOpt = Annotated[
    str,
    typer.Option("--space", metavar="model|paper", help="DXF space to read: model or paper."),
]
FlattenOpt = Annotated[
    float,
    typer.Option(
        "--flatten-tolerance", min=1e-6, metavar="MM", help="Largest curve-to-chord distance (mm)."
    ),
]
HullOpt = Annotated[
    float | None,
    typer.Option(
        "--hull-tolerance",
        min=0.0,
        metavar="MM",
        help=f"Hull simplification (mm); default {REL_HULL_TOLERANCE:g} of the part's size, at "
        f"most {DEFAULT_HULL_TOLERANCE}, for CAD files; exact for outline files.",
    ),
]
AllPartsOpt = Annotated[
    bool,
    typer.Option(
        "--all-parts", help="Import every separate part of a drawing, not only the largest."
    ),
]
PoseOpt = Annotated[
    int | None,
    typer.Option(
        "--pose",
        min=0,
        metavar="K",
        help="Mesh resting pose K to import (0: the most probable); plan picks poses with "
        "--landings K.",
    ),
]
AllowLargeOpt = Annotated[
    bool, typer.Option("--allow-large", help=f"Read files over {DEFAULT_MAX_FILE_MB:g} MB.")
]
MaxEntitiesOpt = Annotated[
    int,
    typer.Option(
        "--max-entities",
        min=1,
        metavar="N",
        help="Import budget: DXF entities after block expansion.",
    ),
]
MaxVerticesOpt = Annotated[
    int,
    typer.Option(
        "--max-vertices", min=1, metavar="N", help="Import budget: vertices after flattening."
    ),
]
MaxLoopsOpt = Annotated[
    int,
    typer.Option(
        "--max-loops", min=1, metavar="N", help="Import budget: closed loops (parts and holes)."
    ),
]
MaxCrossingsOpt = Annotated[
    int,
    typer.Option(
        "--max-crossings",
        min=1,
        metavar="N",
        help="Import budget: pairs of DXF lines that may cross.",
    ),
]
MaxFacesOpt = Annotated[
    int, typer.Option("--max-faces", min=1, metavar="N", help="Import budget: mesh triangles.")
]
MaxHullFacesOpt = Annotated[
    int,
    typer.Option(
        "--max-hull-faces",
        min=1,
        metavar="N",
        help="Import budget: faces of a mesh's convex hull (poses).",
    ),
]
ImportTimeOpt = Annotated[
    float,
    typer.Option(
        "--import-time-limit", min=0.001, metavar="S", help="Import budget: wall time (s) per file."
    ),
]


def import_options(
    units: str | None = None,
    layer: list[str] | None = None,
    flatten_tolerance: float = DEFAULT_FLATTEN_TOLERANCE,
    hull_tolerance: float | None = None,
    all_parts: bool = False,
    pose: int | None = None,
    com: tuple[float, float] | None = None,
    allow_large: bool = False,
    *,
    space: str = "model",
    keep_linetype: list[str] | None = None,
    max_entities: int = DEFAULT_MAX_ENTITIES,
    max_vertices: int = DEFAULT_MAX_VERTICES,
    max_loops: int = DEFAULT_MAX_LOOPS,
    max_crossings: int = DEFAULT_MAX_CROSSINGS,
    max_faces: int = DEFAULT_MAX_FACES,
    max_hull_faces: int = DEFAULT_MAX_HULL_FACES,
    import_time_limit: float = DEFAULT_TIME_LIMIT_S,
) -> ImportOptions:
    """The importer options from the command-line options (bad values: InputError)."""
    return ImportOptions(
        units=units,
        layers=tuple(layer or ()),
        flatten_tolerance=flatten_tolerance,
        hull_tolerance=hull_tolerance,
        all_parts=all_parts,
        pose=pose,
        com=None if com is None else (float(com[0]), float(com[1])),
        allow_large=allow_large,
        space=space,
        keep_linetypes=tuple(keep_linetype or ()),
        limits=ImportLimits(
            entities=max_entities,
            vertices=max_vertices,
            loops=max_loops,
            crossings=max_crossings,
            faces=max_faces,
            hull_faces=max_hull_faces,
            seconds=import_time_limit,
        ),
    )


def _option(name: str, annotation: Any, default: Any) -> inspect.Parameter:
    return inspect.Parameter(
        name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=annotation
    )


IMPORT_PARAMETERS: tuple[inspect.Parameter, ...] = (
    _option("units", UnitsOpt, None),
    _option("layer", LayerOpt, None),
    _option("space", SpaceOpt, "model"),
    _option("keep_linetype", KeepLinetypeOpt, None),
    _option("all_parts", AllPartsOpt, False),
    _option("pose", PoseOpt, None),
    _option("flatten_tolerance", FlattenOpt, DEFAULT_FLATTEN_TOLERANCE),
    _option("hull_tolerance", HullOpt, None),
    _option("allow_large", AllowLargeOpt, False),
    _option("max_entities", MaxEntitiesOpt, DEFAULT_MAX_ENTITIES),
    _option("max_vertices", MaxVerticesOpt, DEFAULT_MAX_VERTICES),
    _option("max_loops", MaxLoopsOpt, DEFAULT_MAX_LOOPS),
    _option("max_crossings", MaxCrossingsOpt, DEFAULT_MAX_CROSSINGS),
    _option("max_faces", MaxFacesOpt, DEFAULT_MAX_FACES),
    _option("max_hull_faces", MaxHullFacesOpt, DEFAULT_MAX_HULL_FACES),
    _option("import_time_limit", ImportTimeOpt, DEFAULT_TIME_LIMIT_S),
)
"""The import options as command parameters, in the order ``--help`` lists them; each
default is the library's (:class:`~feederkit.importers.ImportOptions`, ``ImportLimits``)."""

IMPORT_OPTS = "import_opts"
"""The parameter of a command that :func:`takes_import_options` fills."""

Command = TypeVar("Command", bound=Callable[..., Any])


def takes_import_options(command: Command) -> Command:
    """The command with its ``import_opts`` parameter replaced by :data:`IMPORT_PARAMETERS`.

    Typer reads the new signature, so ``--help`` lists the shared options where
    ``import_opts`` stood; a call (from typer or Python) turns them into one
    :class:`~feederkit.importers.ImportOptions` (bad values: InputError, before the body
    runs). The options and every parameter after them become keyword-only.
    """
    signature = inspect.signature(command, eval_str=True)
    params = list(signature.parameters.values())
    names = [p.name for p in params]
    if IMPORT_OPTS not in names:
        raise TypeError(f"{command.__name__} has no {IMPORT_OPTS!r} parameter")
    taken = {p.name for p in IMPORT_PARAMETERS} & set(names)
    if taken:
        raise TypeError(f"{command.__name__} already has {', '.join(sorted(taken))}")
    at = names.index(IMPORT_OPTS)
    keyword = [p.replace(kind=inspect.Parameter.KEYWORD_ONLY) for p in params[at + 1 :]]
    new_signature = signature.replace(parameters=[*params[:at], *IMPORT_PARAMETERS, *keyword])

    @functools.wraps(command)
    def run(*args: Any, **kwargs: Any) -> Any:
        bound = new_signature.bind(*args, **kwargs)
        bound.apply_defaults()
        values = bound.arguments
        chosen = {p.name: values.pop(p.name) for p in IMPORT_PARAMETERS}
        check_one_part_options(names, chosen["pose"], values.get("com"))
        values[IMPORT_OPTS] = import_options(**chosen)
        return command(**values)

    run.__signature__ = new_signature  # type: ignore[attr-defined]
    run.__annotations__ = {p.name: p.annotation for p in new_signature.parameters.values()}
    if new_signature.return_annotation is not inspect.Signature.empty:
        run.__annotations__["return"] = new_signature.return_annotation
    return run  # type: ignore[return-value]


PLANS_LANDINGS = "landings"
"""The parameter of a command that plans over landings (``--landings``)."""

READS_FOLDER = "directory"
"""The parameter of a command that imports every file of a folder."""


def check_one_part_options(
    parameters: Iterable[str], pose: int | None, com: tuple[float, float] | None
) -> None:
    """Refuse ``--pose`` and ``--com`` where they cannot mean what they say (InputError).

    A command that plans over landings (a ``landings`` parameter: ``plan``) covers every
    resting pose of a mesh, so ``--pose K`` would pick nothing: the pose is ``--landings K``.
    A command that reads a folder (a ``directory`` parameter: ``catalog import``) would give
    one pose and one center of mass to every file of it.
    """
    names = set(parameters)
    if pose is not None and PLANS_LANDINGS in names:
        raise InputError(
            f"--pose {pose}: plan covers every resting pose of a mesh; plan pose {pose} alone "
            f"with --landings {pose}"
        )
    if READS_FOLDER in names:
        given = [o for o, v in (("--pose K", pose), ("--com X Y", com)) if v is not None]
        if given:
            said = " and ".join(given)
            verb = "describe" if len(given) > 1 else "describes"
            raise InputError(
                f"{said} {verb} one part, not every file of a folder: add that part's file "
                f"alone with catalog add FILE {said}"
            )


def with_com(options: ImportOptions, com: tuple[float, float] | None) -> ImportOptions:
    """The options with a ``--com X Y`` given on the command line (None: as they are)."""
    if com is None:
        return options
    return dataclasses.replace(options, com=(float(com[0]), float(com[1])))


def print_import_warnings(source: str, warnings: Iterable[str]) -> None:
    """Each import warning as ``warning: SOURCE: ...`` on stderr (plain text, as ``plan`` does)."""
    from feederkit.cli.common import print_warnings  # the console lives there

    print_warnings(f"{source}: {w}" for w in warnings)
