"""Compile a changeover: one verified plan for a product mix, stored in the catalog against
the parts' exact revisions (section 8.5). The command line and the demo both call this.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from feederkit.catalog import (
    get_revision,
    list_changeovers,
    open_catalog,
    part_from_revision,
    save_changeover,
)
from feederkit.errors import InputError
from feederkit.mechanics.analysis import fragile_warning
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.mix.pairs import PairWitness, unrecognizable_pairs
from feederkit.plans.fileformat import plan_json
from feederkit.plans.make import MadePlan, make_plan
from feederkit.plans.match import leaf_part_pairs
from feederkit.sensors import SensorModel, sensor_to_dict


@dataclass(frozen=True)
class CompiledChangeover:
    """A stored changeover: its verified plan, exact revisions, pairs no plan tells apart."""

    name: str
    revisions: tuple[tuple[str, int], ...]
    parts: tuple[PushFunction, ...]
    made: MadePlan
    witnesses: tuple[PairWitness, ...]

    @property
    def plan(self) -> dict[str, Any]:
        """The plan file's object."""
        return self.made.plan

    @property
    def warnings(self) -> list[str]:
        """One line per part with fragile states (the plan may rely on them)."""
        return [w for pf in self.parts if (w := fragile_warning(pf)) is not None]

    @property
    def lumped(self) -> list[tuple[str, str]]:
        """Pairs of parts that some result of the plan lists together."""
        return leaf_part_pairs(self.made.plan)


def load_mix(
    catalog: Path, members: Sequence[tuple[str, int | None]]
) -> tuple[list[PushFunction], list[tuple[str, int]]]:
    """The push functions and exact revisions of catalog parts (None: the latest revision).

    A part the catalog marks not orientable by pushing is bad input.
    """
    conn = open_catalog(catalog)
    try:
        pfs, revisions = [], []
        for name, rev in members:
            revision = get_revision(conn, name, rev)
            if not revision.orientable:
                raise InputError(
                    f"{name}: not orientable by pushing: {revision.not_orientable_reason}"
                )
            pfs.append(push_function(part_from_revision(revision)))
            revisions.append((revision.name, revision.revision))
    finally:
        conn.close()
    return pfs, revisions


def plan_mix(
    parts: Sequence[PushFunction],
    sensor: SensorModel,
    *,
    objective: str = "worst",
    min_margin: float = 0.0,
    grouping: str = "exact",
    time_limit: float | None = None,
) -> tuple[MadePlan, list[PairWitness]]:
    """A verified plan for one part or a mix (section 8.5), and the pairs of parts no plan
    can tell apart (section 8.4), each with its witness.
    """
    made = make_plan(
        parts,
        sensor,
        objective=objective,
        min_margin=min_margin,
        grouping=grouping,
        time_limit=time_limit,
    )
    witnesses = unrecognizable_pairs(parts, sensor) if len(parts) > 1 else []
    return made, witnesses


def compile_changeover(
    catalog: Path,
    name: str,
    members: Sequence[tuple[str, int | None]],
    sensor: SensorModel,
    *,
    objective: str = "worst",
    min_margin: float = 0.0,
    grouping: str = "exact",
    time_limit: float | None = None,
    replace: bool = False,
) -> CompiledChangeover:
    """Plan, verify and store the changeover ``name`` for ``members`` (catalog parts).

    Raises InputError for an existing name (unless ``replace``) or bad parts, PlanningError
    when no plan meets the request, CheckFailed when the plan fails verification.
    """
    if not replace and any(c.name == name for c in list_changeovers(catalog)):
        raise InputError(f"a changeover named {name!r} already exists (use --replace)")
    pfs, revisions = load_mix(catalog, members)
    made, witnesses = plan_mix(
        pfs,
        sensor,
        objective=objective,
        min_margin=min_margin,
        grouping=grouping,
        time_limit=time_limit,
    )
    save_changeover(
        catalog, name, revisions, sensor_to_dict(sensor), plan_json(made.plan), replace=replace
    )
    return CompiledChangeover(name, tuple(revisions), tuple(pfs), made, tuple(witnesses))
