"""``feederkit run PLAN [SOURCE...]``: execute a plan on the kinematic model.

A thin layer over :mod:`feederkit.plans`: the plan file holds each part's hull and COM, so
without SOURCE every part of the plan is run; a SOURCE names a part that must be one of the
plan's (same hull and COM: the plan is checked against the current part). One run from
``--start-deg`` step by step, or ``--all`` for the full verification at the plan's declared
uncertainty (a strong plan: every outcome and reading; the ideal model: the kinematic model).
In a plan over landings every member is a part in one landing: the tables and messages name
it as ``PART (LANDING)``, and a run that ends in a reject result says "reject" (the next
station cannot take that landing: recirculate or re-drop). A run that ends in a result
listing several parts or landings says so, naming them (the plan cannot tell them apart),
and ``--all`` counts such paths apart. Exit 1 when anything fails,
including a plan that fails verification.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any

import typer

from feederkit.angles import norm360
from feederkit.cli.common import CatalogOpt, JsonOpt, console, print_json, print_warnings
from feederkit.cli.plan_render import (
    DEFAULT_MAX_PLAN_MB,
    MaxPlanMbOpt,
    load_plan,
    trace_table,
    verification_table,
)
from feederkit.errors import CheckFailed, InputError
from feederkit.hull import hull_distance
from feederkit.landing.plan import load_landings
from feederkit.loading import load_parts
from feederkit.part import Part
from feederkit.plans.execute import execute
from feederkit.plans.match import match_part, offsets_words, same_geometry
from feederkit.plans.model import UNRECOGNIZED_WORDS, Plan, PlanPart
from feederkit.plans.verify import VerificationReport, verify_declared
from feederkit.sim.likeness import refusal_words
from feederkit.sources import load_part


def run_command(
    plan_path: Annotated[Path, typer.Argument(metavar="PLAN", help="A plan file (JSON).")],
    sources: Annotated[
        list[str] | None,
        typer.Argument(
            metavar="SOURCE",
            help="Check and run these parts (outline or CAD files, catalog names); "
            "default: every part of the plan, from the hull and COM it records.",
            show_default=False,
        ),
    ] = None,
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
        typer.Option("--all", help="Every stable start, every reading, every rotation."),
    ] = False,
    json_out: JsonOpt = False,
    catalog: CatalogOpt = None,
    max_plan_mb: MaxPlanMbOpt = DEFAULT_MAX_PLAN_MB,
) -> None:
    """Execute a plan for its parts: each step's rotation, reading and branch, the pose."""
    if start_deg is not None and all_starts:
        raise InputError("choose one of --start-deg and --all")
    if start_deg is not None and not math.isfinite(start_deg):
        raise InputError(f"--start-deg must be a finite angle in degrees, got {start_deg}")
    plan = load_plan(plan_path, max_plan_mb)
    indices: list[int] = []
    left: list[str] = []
    for source in sources or []:
        found, words = _members_of(plan, source, catalog)
        left += words
        for k in found:
            if k not in indices:
                indices.append(k)
    if not sources:
        indices = list(range(len(plan.parts)))
    # The fragile states of the parts run (a SOURCE's member), not of every part of the mix.
    held = (plan.low_margin_warning(), plan.ideal_model_warning())
    warnings = [w for w in held if w] + plan.fragile_warnings(indices)
    warnings += stored_beyond(plan, sources or [], catalog) + left
    if not json_out:
        print_warnings(warnings)  # stderr, one line each (docs/cli.md)
    if not json_out:
        console.print(
            f"declared uncertainty: {plan.uncertainty_words()}",
            highlight=False,
            markup=False,
            soft_wrap=True,
        )
    report = verify_declared(plan, None if not sources else indices)
    cert = plan.certificate_words()
    if cert is not None and not json_out:
        # What the file claims; a plan that fails its verification guarantees nothing.
        said = "certificate" if report.ok else "certificate claimed (the plan failed verification)"
        console.print(f"{said}: {cert}", highlight=False, markup=False, soft_wrap=True)
    if all_starts:
        if json_out:
            print_json({**report.to_dict(), **_declared(plan), "warnings": warnings})
        else:
            if report.parts:  # a failed strong check has no counts, only its first problem
                console.print(verification_table(report, plan))
            if report.ok:
                console.print(
                    f"{_every_path(report.paths)} in their result{_of_them(report)}",
                    highlight=False,
                    markup=False,
                    soft_wrap=True,
                )
        if not report.ok:
            raise CheckFailed(f"the plan failed: {report.first_problem()}")
        return
    # The same orientation on the circle, said as 40 degrees rather than 400.
    start = 0.0 if start_deg is None else norm360(start_deg)
    traces = [execute(plan, k, start) for k in indices]
    if json_out:
        runs = [t.to_dict() for t in traces]
        print_json({"plan": str(plan_path), "runs": runs, **_declared(plan), "warnings": warnings})
    else:
        for t in traces:
            console.print(trace_table(t))
            style = "yellow" if t.unrecognized else "green" if t.success else "bold red"
            console.print(t.message, style=style, highlight=False, markup=False, soft_wrap=True)
    failed = [t for t in traces if not t.success]
    if failed:
        raise CheckFailed(failed[0].message)
    if not report.ok:
        raise CheckFailed(f"the plan failed verification: {report.first_problem()}")


def stored_beyond(plan: Plan, sources: Sequence[str], catalog: str | None) -> list[str]:
    """A line per catalog part among ``sources`` whose revision stores a shape or COM
    tolerance larger than the plan declares: the run checks the plan at what it declares,
    so a plan made before the revision stored it passes without covering it."""
    names = list(dict.fromkeys(s for s in sources if not Path(s).exists()))  # catalog parts
    if not names:
        return []
    declared = plan.uncertainty
    out = []
    for t in load_parts(names, catalog=catalog).tolerances:
        for what, stored, planned in (
            ("shape", t.shape_tolerance_mm, declared.shape_tolerance_mm),
            ("COM", t.com_tolerance_mm, declared.com_tolerance_mm),
        ):
            if stored is not None and stored > planned + STORED_EPS_MM:
                out.append(
                    f"{t.label} stores a {what} tolerance of {stored:g} mm, more than the "
                    f"{planned:g} mm this plan declares: the run checks the plan at what it "
                    "declares; plan (or compile) again to cover the stored tolerance"
                )
    return out


STORED_EPS_MM = 1e-9
"""A stored tolerance counts as larger than the declared one past this (mm): the plan
declares the stored value itself when it took it from the catalog."""


def _members_of(plan: Plan, source: str, catalog: str | None) -> tuple[list[int], list[str]]:
    """The plan's members a SOURCE names: its part (same hull and COM, ``match_part``) or,
    in a plan over landings, every landing of that part the plan holds, each checked
    against the source's own landing (docs/plans.md: every member is run); and a line when
    the part also lands in ways the plan does not hold (not run: a part landing so is not
    oriented by the plan)."""
    part = load_part(source, catalog=catalog)
    try:  # the plan's name for the part: a renamed file of the same geometry is the part
        k = match_part(plan, part, source)
    except InputError as exc:
        if not plan.over_landings or not any(m.name == part.name for m in plan.parts):
            hints = (_likeness_hint(plan, m, part, source) for m in plan.parts)
            raise InputError(f"{exc}{next((h for h in hints if h), '')}") from None
        k = None  # a plan of other landings only (down): checked landing by landing
    if not plan.over_landings:
        return [k], []
    name = part.name if k is None else plan.parts[k].name
    held = tuple(dict.fromkeys(m.landing for m in plan.parts if m.name == name and m.landing))
    out = []
    # Only the landings the plan holds: another may be one pushing cannot orient (a mesh
    # pose on a round face), which loading it would refuse.
    found = load_landings([source], catalog=catalog, which=held)
    for x in found.all:
        for j, member in enumerate(plan.parts):
            if member.name != name or member.landing != x.name:
                continue
            if not same_geometry(x.part, member, plan.uncertainty):
                raise InputError(
                    f"{source}: its {x.name} landing differs from the plan's ("
                    f"{offsets_words(x.part, member, plan.uncertainty)})"
                    + _likeness_hint(plan, member, x.part, source)
                )
            out.append(j)
    return sorted(out) or [match_part(plan, part, source)], found.left_out_words("the plan")


LIKENESS_REL = 1e-3
"""A SOURCE whose hull a turn, mirror, shift or unit brings within this share of the part's
size (plus the declared shape tolerance) of the plan's is named as the plan's part in another
frame or units (a drawing flattened again differs by rounding)."""


SIMPLIFIED_REL = 0.01
"""A SOURCE with other hull vertices than the plan's, whose hull lies within this share of
the part's size of the plan's, may be the drawing of a hull import simplified."""


def _likeness_hint(plan: Plan, member: PlanPart, part: Part, source: str) -> str:
    """``"; ..."``: the SOURCE is the plan's ``member`` in other units or another frame, in
    the words ``simulate --part`` uses (:func:`feederkit.sim.likeness.refusal_words`), or a
    drawing with other hull vertices than the plan's simplified hull; empty otherwise."""
    allowed = plan.uncertainty.shape_tolerance_mm + LIKENESS_REL * member.size
    words = refusal_words(
        member.hull,
        member.com,
        part.hull,
        part.com,
        allowed,
        source=source,
        name=member.name,
        is_file=Path(source).exists(),
        give="give NAME as the SOURCE",
    )
    near = hull_distance(part.hull, member.hull) <= SIMPLIFIED_REL * member.size
    if words is None and len(part.hull) != len(member.hull) and near:
        return (
            "; a drawing's hull simplified on import (--hull-tolerance) has other vertices: "
            "give the catalog part the plan was made from (NAME@REV), or check the drawing "
            "with feederkit simulate --part, which allows for the simplification"
        )
    return words or ""


def _of_them(report: VerificationReport) -> str:
    """What the right paths end in besides a known part and pose: a reject result, an
    unrecognized one (:data:`UNRECOGNIZED_WORDS`); empty when neither."""
    rejects = sum(p.rejects for p in report.parts)
    tail = ""
    if rejects:
        tail += (
            f", {rejects} of them in a reject result (a landing the next station cannot take: "
            "recirculate or re-drop)"
        )
    if report.unrecognized:
        tail += f", {report.unrecognized} of them {UNRECOGNIZED_WORDS}"
    return tail


def _every_path(n: int) -> str:
    """``all 3 paths end`` (``the one path ends``)."""
    return "the one path ends" if n == 1 else f"all {n} paths end"


def _declared(plan: Plan) -> dict[str, Any]:
    """The declared uncertainty and the certificate, for ``--json``."""
    cert = plan.stats.certificate
    return {
        "uncertainty": plan.uncertainty.to_dict(),
        "uncertainty_declared": plan.uncertainty_declared,
        "certificate": None if cert is None else cert.to_dict(),
    }


def register(app: typer.Typer) -> None:
    """Add the ``run`` command to the app."""
    app.command("run")(run_command)
