"""Load the parts to plan for and check them: one rule for every command (docs/changeovers.md).

A SOURCE is an outline or CAD file or a catalog name (``NAME`` or ``NAME@REV``, resolved by
:mod:`feederkit.sources`). A part that pushing cannot orient (disk-like: no stable edge with a
useful resting range, see :mod:`feederkit.importers.orientable`) has no plan; it is refused, or
left out with a note when a whole catalog is planned. A mix names each part once (section
8.5: the plan's results name the part). Each part's push function (section 3) is made here.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from feederkit.catalog import RevisionTolerances
from feederkit.errors import InputError
from feederkit.importers import ImportOptions
from feederkit.mechanics.analysis import fragile_warnings
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.sources import labelled_warnings, load_parts_with_warnings


@dataclass(frozen=True)
class LoadedParts:
    """The push functions of the parts to plan for, in the order given.

    ``import_warnings``: one line each from the imports (prefixed with the SOURCE);
    ``fragile_warnings``: the parts' fragile states, each part named and numbered as drawn
    (a plan over landings names each landing's own instead, so they are kept apart);
    ``left_out``: one line per part that is not orientable by pushing (only when such parts
    are left out rather than refused); ``origins``: the SOURCE each push function came from
    (a drawing read with ``all_parts`` gives several); ``tolerances``: what the catalog
    revisions among them store (:func:`feederkit.catalog.declared_tolerances` makes them the
    plan's; parts read from files store none).
    """

    push_functions: tuple[PushFunction, ...]
    import_warnings: tuple[str, ...] = ()
    fragile_warnings: tuple[str, ...] = ()
    left_out: tuple[str, ...] = ()
    origins: tuple[str, ...] = ()
    tolerances: tuple[RevisionTolerances, ...] = ()

    @property
    def warnings(self) -> tuple[str, ...]:
        """Every warning of the loading as a plan of the parts themselves says them: the
        imports', then the fragile states'."""
        return self.import_warnings + self.fragile_warnings

    @property
    def names(self) -> list[str]:
        """The parts' names."""
        return [pf.part.name for pf in self.push_functions]

    @property
    def revisions(self) -> list[tuple[str, int]]:
        """Each part's catalog name and exact revision; InputError for a part read from a file."""
        out = []
        for pf in self.push_functions:
            if pf.part.revision is None:
                raise InputError(
                    f"{pf.part.name}: a part read from a file, not a catalog part "
                    "(add it to the catalog first)"
                )
            out.append((pf.part.name, int(pf.part.revision)))
        return out


def load_parts(
    sources: Sequence[str],
    *,
    catalog: str | os.PathLike[str] | None = None,
    options: ImportOptions | None = None,
    leave_out_not_orientable: bool = False,
) -> LoadedParts:
    """Load and check the parts named by ``sources`` (files or catalog ``NAME[@REV]``).

    ``catalog`` is the catalog for names (default: :func:`feederkit.catalog.resolve_catalog_path`);
    ``options`` the CAD import's (with ``all_parts``, every separate part of a drawing joins
    the mix). A part not orientable by pushing is bad input unless
    ``leave_out_not_orientable``. Raises InputError for unreadable sources, unknown names,
    and a part named twice.
    """
    if not sources:
        raise InputError("no parts to plan for")
    db = None if catalog is None else str(Path(catalog))
    pfs: list[PushFunction] = []
    origins: list[str] = []
    import_warnings: list[str] = []
    left_out: list[str] = []
    tolerances: list[RevisionTolerances] = []
    for source in sources:
        every = load_parts_with_warnings(source, catalog=db, options=options)
        kept = []
        for loaded in every:
            where = source if len(every) == 1 else f"{source} ({loaded.part.name})"
            if not loaded.orientability.orientable:
                line = f"{where}: not orientable by pushing: {loaded.orientability.reason}"
                if not leave_out_not_orientable:
                    raise InputError(line)
                left_out.append(line)
                continue
            kept.append(loaded)
            pfs.append(push_function(loaded.part))
            origins.append(source)
            if loaded.tolerances is not None:
                tolerances.append(loaded.tolerances)
        import_warnings += labelled_warnings(source, kept, several=len(every) > 1)
    names = [pf.part.name for pf in pfs]
    for name in names:
        if names.count(name) > 1:
            raise InputError(f"the part {name!r} is named twice: a mix names each part once")
    return LoadedParts(
        tuple(pfs),
        import_warnings=tuple(import_warnings),
        fragile_warnings=tuple(fragile_warnings(pfs)),
        left_out=tuple(left_out),
        origins=tuple(origins),
        tolerances=tuple(tolerances),
    )
