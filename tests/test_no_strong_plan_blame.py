"""What ``plan``, ``changeover compile`` and ``catalog analyze`` say when a mix has no strong
plan: the members no strong plan orients even alone, two landings of one part that have one
each but none together (plan one side: ``--landings``), what is left to loosen when even a
rotation error of 0 has none, the reading intervals of the witness tables under uncertainty,
and the ideal-model note of an analysis without uncertainty flags."""

from __future__ import annotations

from pathlib import Path

import pytest
from shared import catalog_with, no_stray_profile, run_cli  # noqa: F401 (autouse)

from feederkit.cli.catalog_analyze import IDEAL_ONLY_NOTE, _Readings
from feederkit.errors import PlanningError
from feederkit.machine import build_machine
from feederkit.mechanics.modelerror import part_offsets
from feederkit.mechanics.push import push_function
from feederkit.outline import load_outline_json, make_outline
from feederkit.part import make_part
from feederkit.planning.options import PlanningOptions
from feederkit.plans.advice import blocking_members
from feederkit.plans.certify import largest_uncertainty
from feederkit.plans.make import make_plan
from feederkit.plans.model import PlanMember
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
SENSOR = ToleranceSensor(0.05)
NO_LUMPING = PlanningOptions(lumping="none")


def _cham():
    """A 5 x 2.5 plate with one corner cut: no strong plan at 1 degree (its sides 180
    degrees apart read alike and do not look alike)."""
    pts = [[0, 0], [5, 0], [5, 2.3], [4.8, 2.5], [0, 2.5]]
    return push_function(make_part(make_outline("cham", pts)))


def _triangle():
    return push_function(make_part(make_outline("tri", [[0, 0], [30, 0], [5, 12]])))


def _rect(name: str, h: float):
    return push_function(make_part(make_outline(name, [[0, 0], [40, 0], [40, h], [0, h]])))


def _catalog_part(name: str):
    return push_function(make_part(load_outline_json(CATALOG / f"{name}.json")))


def _no_plan(pfs, unc=None, options=None, members=None) -> str:
    with pytest.raises(PlanningError) as exc:
        make_plan(pfs, SENSOR, options, uncertainty=unc, certify=False, members=members)
    return str(exc.value)


# --- the members to blame -------------------------------------------------------------------


def test_a_member_with_no_strong_plan_alone_is_named_with_leave_it_out():
    text = _no_plan([_triangle(), _cham()])
    assert "cham has no strong plan even alone at the declared uncertainty" in text
    assert "leave it out of the mix" in text and "tri has" not in text
    assert "vibration merges" not in text


def test_when_every_member_has_a_plan_alone_the_pairs_between_them_are_the_cause():
    """Two 40 mm bars 10 and 10.02 mm wide read alike at 0.05 mm: each plans alone, the two
    together (never listed together: lumping none) do not."""
    pfs = [_rect("r1", 10.0), _rect("r2", 10.02)]
    make_plan(pfs[:1], SENSOR, NO_LUMPING, certify=False)  # alone: a plan
    text = _no_plan(pfs, options=NO_LUMPING)
    assert "every member has a strong plan alone" in text and "pairs between members" in text
    assert "even alone" not in text and "--landings" not in text


def test_two_landings_of_one_part_with_no_plan_together_point_to_landings():
    members = [PlanMember("bar", "up"), PlanMember("bar", "down")]
    text = _no_plan([_rect("bar/up", 10.0), _rect("bar/down", 10.02)], None, NO_LUMPING, members)
    assert "two landings of one part each have a strong plan alone but none together" in text
    assert "bar/up and bar/down" in text and "plan only one side (--landings up)" in text
    assert "every member has" not in text


def test_nothing_is_blamed_without_time_to_decide():
    pfs = [_triangle(), _cham()]
    offsets = part_offsets(pfs)
    blame = blocking_members(pfs, SENSOR, Uncertainty(), PlanningOptions(), offsets, None, 0.0)
    assert blame.words == "" and blame.members == ()


def test_a_rejected_member_is_not_checked_alone():
    members = [PlanMember("tri", "up"), PlanMember("cham", "up", accept=False)]
    pfs = [_triangle(), _cham()]
    offsets = part_offsets(pfs)
    blame = blocking_members(pfs, SENSOR, Uncertainty(), PlanningOptions(), offsets, members)
    assert "cham" not in blame.words


# --- what is left to loosen -----------------------------------------------------------------


def test_no_rotation_error_names_the_tolerances_not_the_ideal_model():
    """At rotation error 0 the shape and COM tolerances are what leave no plan: the line names
    --com-tolerance, never "plan on the ideal model (rotation error 0)"."""
    pf = _catalog_part("isosceles-right-triangle")
    text = largest_uncertainty([pf], SENSOR, Uncertainty(0.0, 0.05, 0.1), PlanningOptions())
    assert "what is left to loosen is the tolerances" in text
    assert "a smaller --com-tolerance" in text and "alone leaves none" in text
    assert "plan on the ideal model (rotation error 0)" not in text
    assert "vibration merges" not in text


def test_the_declared_rotation_error_without_the_tolerances_is_named():
    pf = _catalog_part("isosceles-right-triangle")
    text = largest_uncertainty([pf], SENSOR, Uncertainty(1.0, 0.0, 0.1), PlanningOptions())
    assert text.startswith("even with rotation error 0 the COM tolerance 0.1 mm leaves no")
    assert "without it the declared rotation error 1 deg has a strong plan" in text
    assert "vibration" not in text


def test_the_vibration_is_the_cause_only_when_no_rotation_error_has_a_plan():
    """The chamfered plate has no plan at any rotation error above 0 even with no tolerance:
    there, and only there, the vibration is named."""
    text = largest_uncertainty([_cham()], SENSOR, Uncertainty(1.0, 0.02, 0.1), PlanningOptions())
    assert "nor does any rotation error without them" in text
    assert "the feeder's vibration" in text and "no shape or COM tolerance" in text


def test_out_of_time_the_largest_uncertainty_builds_no_machine():
    # Each step of the bisection builds a machine (0.3 s on a 200-part mix); once the time
    # is out it is undecided at once, with no build for nothing.
    built = []

    def build(unc):
        built.append(unc)
        return build_machine([_cham()], SENSOR, unc)

    text = largest_uncertainty(
        [_cham()], SENSOR, Uncertainty(1.0), PlanningOptions(), seconds=0.0, build=build
    )
    assert text == "the largest uncertainty with a strong plan was not found within the time limit"
    assert built == []
    largest_uncertainty([_cham()], SENSOR, Uncertainty(1.0), PlanningOptions(), build=build)
    assert built


# --- the command line -----------------------------------------------------------------------


def _mini_bracket(path: Path) -> Path:
    """A review's 15 x 9 mm bracket: a 5 x 4 notch with a drawn R1 fillet, a 3 mm hole."""
    from fixtures_cad import write_entities

    def build(msp):
        pts = [(0, 0, 0), (15, 0, 0), (15, 4, 0), (10, 4, 0), (10, 8, 0.41421356), (9, 9, 0)]
        msp.add_lwpolyline([*pts, (0, 9, 0)], format="xyb", close=True)
        msp.add_circle((4, 4.5), 1.5)

    return write_entities(path, build)


def test_the_command_line_points_a_chiral_parts_two_sides_to_landings(tmp_path, capsys):
    dxf = _mini_bracket(tmp_path / "mini-bracket.dxf")
    # Under 1 degree its fillet's hilltop (a near-metastable facet) leaves no plan even face
    # up; at 0.5 degree one side has one.
    flags = ["--led-pitch", "0.1", "--noise", "0.02", "--shape-tolerance", "0.05"]
    flags += ["--rotation-error", "0.5"]
    flags += ["--com-tolerance", "0.1", "-o", str(tmp_path / "p.json")]
    rc, _, err = run_cli(capsys, "plan", str(dxf), *flags)
    line = [x for x in err.splitlines() if x.startswith("result:")]
    assert rc == 1 and len(line) == 1
    assert "mini-bracket/up and mini-bracket/down" in line[0]
    assert "plan only one side (--landings up)" in line[0]
    rc, _, _ = run_cli(capsys, "plan", str(dxf), *flags, "--landings", "up")
    assert rc == 0  # the remedy named works


# --- catalog analyze ------------------------------------------------------------------------


@pytest.fixture()
def catalog(tmp_path, capsys) -> str:
    return catalog_with(tmp_path, capsys, ("rectangle-2x1", "isosceles-right-triangle"))


def test_analyze_offers_only_landings_for_one_parts_two_sides(catalog, capsys):
    rc, _, err = run_cli(capsys, "catalog", "analyze", "--tolerance", "1", "--catalog", catalog)
    assert rc == 1 and "rectangle-2x1/up & rectangle-2x1/down" in err
    assert "plan only one of them (--landings)" in err
    assert "or reject the others" not in err and "leaves no plan" in err


def test_an_ideal_analysis_that_tells_every_pair_apart_names_compiles_default(tmp_path, capsys):
    path = str(tmp_path / "c.db")
    assert run_cli(capsys, "catalog", "init", "--catalog", path)[0] == 0
    for name in ("l-bracket", "octagon"):
        source = str(CATALOG / f"{name}.json")
        assert run_cli(capsys, "catalog", "add", source, "--catalog", path)[0] == 0
    rc, out, _ = run_cli(capsys, "catalog", "analyze", "--tolerance", "0.1", "--catalog", path)
    flat = " ".join(out.split())
    assert rc == 0 and "(Theorem 11)" in flat
    assert "that is the ideal model" in flat and "--rotation-error 1 screens" in flat
    assert "--rotation-error 1 screens at compile's default" in IDEAL_ONLY_NOTE
    args = ["catalog", "analyze", "--tolerance", "0.1", "--rotation-error", "1"]
    rc, out, _ = run_cli(capsys, *args, "--catalog", path)
    assert "screens at compile's default" not in " ".join(out.split())  # not the ideal model


def test_analyze_under_uncertainty_shows_the_reading_intervals(catalog, capsys, monkeypatch):
    from feederkit.cli.common import console

    monkeypatch.setattr(console, "_width", 400)  # one table row a line
    args = ["catalog", "analyze", "--tolerance", "0.1", "--shape-tolerance", "0.05"]
    rc, out, _ = run_cli(capsys, *args, "--catalog", catalog)
    assert rc == 1 and "no strong plan orients these even alone" in out
    (row,) = [x for x in out.splitlines() if "isosceles-right-triangle" in x]
    assert ", reads " in row and "physical state reads over" in out


def test_the_readings_are_the_machines_intervals_under_uncertainty_exact_on_the_ideal_model():
    pf = _catalog_part("l-bracket")
    ideal = _Readings([pf], NoSensor(), IDEAL)
    s = pf.states[0]
    assert ideal.state(0, 0) == f"0 (e{s.edge} {s.diameter:.4g})"
    under = _Readings([pf], SENSOR, Uncertainty(1.0, 0.05))
    lo, hi = under.spans(0)[0]
    assert lo < s.diameter < hi
    assert under.state(0, 0) == f"0 (e{s.edge}, reads {lo:.4g}-{hi:.4g})"
