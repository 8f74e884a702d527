"""``design sensor`` at a declared uncertainty: strong-plan critical tolerances and lengths.

The reference bisects on floats with the strong pair test built here from ``build_machine``
and ``inseparable_masks`` at the uncertainty (a bisimilar state of the one part and the
other means no strong plan tells them apart) and knows nothing of breakpoints or
sub-machines; the table's lengths are held to the planner at every interval; plans just
below and above a critical tolerance are made and verified. With every bound zero the
figures are the ideal model's, exactly.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from test_design_critical import random_pf
from test_design_critical import reference_critical as bisect_critical
from test_lumping_policy import chamfered, near_rectangle

import feederkit.cli.app as app_module
from feederkit.cli import design as design_cli
from feederkit.cli.app import main
from feederkit.design.critical import interval_probe, mix_critical_tolerance
from feederkit.design.sensor import design_pitches, design_tolerance, report_design
from feederkit.design.steps import length_steps
from feederkit.design.strong import (
    StrongLengthOracle,
    StrongMix,
    chain_changes,
    gap_breakpoints,
    machine_breakpoints,
    strong_mix_critical,
)
from feederkit.errors import InputError
from feederkit.landing.plan import load_landings
from feederkit.loading import load_parts
from feederkit.machine import Grouping, members
from feederkit.machine.build import build_machine
from feederkit.machine.inseparable import inseparable_masks
from feederkit.mechanics.push import push_function
from feederkit.mix.changeover import strong_witnesses
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan
from feederkit.planning.problem import Problem
from feederkit.planning.reindex import by_diameter
from feederkit.planning.solvable import NoStrongPlan, unsolvable
from feederkit.plans.make import make_plan
from feederkit.sensors import LedSensor, NoSensor, ToleranceSensor, span
from feederkit.uncertainty import IDEAL, Uncertainty

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
MIX = [str(CATALOG / f"{n}.json") for n in ("quadrilateral", "rectangle-2x1", "l-bracket")]
ONE_DEG = Uncertainty(1.0)
REL = 1e-4
"""Relative resolution of the reference bisection (the exact value is then checked to be the
breakpoint where the test changes)."""


def small_pf(rng: np.random.Generator, name: str):
    """A random convex 3- to 5-gon of 20-40 mm with a random COM inside (few states: the
    strong pair test solves over sets of them)."""
    while True:
        k = int(rng.integers(3, 6))
        s = float(rng.uniform(20.0, 40.0))
        ang = np.sort(rng.uniform(0.0, 2.0 * math.pi, k))
        r = rng.uniform(0.6, 1.0, k) * s / 2.0
        pts = np.c_[r * np.cos(ang), r * np.sin(ang)]
        try:
            part = make_part(make_outline(name, pts.tolist()))
            hull = np.asarray(part.hull)
            w = rng.dirichlet(np.ones(len(hull)))
            com = 0.5 * (w @ hull) + 0.5 * hull.mean(axis=0)
            pf = push_function(make_part(part.outline, (float(com[0]), float(com[1]))))
        except InputError:
            continue
        if pf.n >= 2:
            return pf


def tri():
    return push_function(make_part(make_outline("tri", [[0, 0], [4, 0], [0, 3]])))


def strong_test(pf_a, pf_b, unc=ONE_DEG):
    """Whether a strong plan tells the parts apart: no state of the one is bisimilar to a
    state of the other, and the two parts' machine at ``unc`` is solvable for the goal "one
    part" (every result holds one part's states), built here from ``build_machine``,
    ``inseparable_masks`` and the solver, independent of the design module."""
    machine = build_machine([pf_a, pf_b], NoSensor(), unc)
    first = [i for i, s in enumerate(machine.states) if s.part == 0]

    def test(e: float) -> bool:
        at = replace(machine, sensor=ToleranceSensor(e))
        masks = inseparable_masks(at)
        if any(machine.states[j].part == 1 for i in first for j in members(masks[i])):
            return False
        ordered, _old = by_diameter(at)
        parts = [s.part for s in ordered.states]
        goal = tuple(sum(1 << j for j, q in enumerate(parts) if q == p) for p in parts)
        problem = Problem(ordered, Grouping.EXACT, 0.0, goal)
        roots = [b.mask for b in problem.readings.branches(problem.full)]
        return unsolvable(problem, roots) == []

    return machine, test


def reference_critical(test, top: float) -> float | None:
    """Largest tolerance where ``test`` holds, by bisection on floats (test_design_critical's
    reference, to ``REL``: each probe here is a strong-plan solve)."""
    return bisect_critical(test, top, REL)


def cross_breakpoints(machine) -> tuple[float, ...]:
    spans = [span(s.sensed) for s in machine.states]
    a = [x for x, s in zip(spans, machine.states, strict=True) if s.part == 0]
    b = [x for x, s in zip(spans, machine.states, strict=True) if s.part == 1]
    return gap_breakpoints(a, b)


def check_pairs(seed: int, count: int, unc=ONE_DEG, make=small_pf) -> None:
    rng = np.random.default_rng(seed)
    for k in range(count):
        a, b = make(rng, f"a{k}"), make(rng, f"b{k}")
        (exact,) = strong_mix_critical(StrongMix([a, b], unc)).pairs
        machine, test = strong_test(a, b, unc)
        spans = [span(s.sensed) for s in machine.states]
        top = max(hi for _lo, hi in spans) - min(lo for lo, _hi in spans) + 1.0
        ref = reference_critical(test, top)
        x = exact.critical_tolerance
        if ref is None:
            assert x is None and exact.witness is not None
            continue
        assert x is not None and math.isclose(x, ref, rel_tol=2 * REL), (seed, k, x, ref)
        breaks = cross_breakpoints(machine)
        assert x in breaks  # exactly a breakpoint: at it the pair still reads apart
        assert test(x)
        nxt = breaks.index(x) + 1
        assert not test(interval_probe(breaks, nxt))


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 5, 6])
def test_strong_critical_matches_float_bisection(seed):
    check_pairs(seed, 5)  # 30 pairs in all


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(10, 20))
def test_strong_critical_matches_float_bisection_on_many_pairs(seed):
    check_pairs(seed, 10, make=random_pf)
    check_pairs(seed + 100, 5, Uncertainty(2.0, 0.05, 0.05))


def test_strong_distinguishability_is_monotone_in_the_tolerance():
    rng = np.random.default_rng(7)
    for k in range(6):
        a, b = small_pf(rng, f"a{k}"), small_pf(rng, f"b{k}")
        machine, test = strong_test(a, b)
        breaks = cross_breakpoints(machine)
        got = [test(interval_probe(breaks, i)) for i in range(len(breaks) + 1)]
        assert got == sorted(got, reverse=True) and not got[-1]


def test_the_bisimilar_relation_only_grows_with_the_tolerance():
    rng = np.random.default_rng(3)
    pfs = [random_pf(rng, f"p{i}") for i in range(3)]
    oracle = StrongLengthOracle(StrongMix(pfs, ONE_DEG))
    breaks = machine_breakpoints(oracle.machine)
    prev = None
    for k in range(0, len(breaks) + 1, max(1, len(breaks) // 40)):
        now = oracle.bisimilar(interval_probe(breaks, k))
        if prev is not None:
            assert all(p & ~n == 0 for p, n in zip(prev, now, strict=True))
        prev = now


def test_chain_changes_finds_every_step_of_a_chain():
    values = [0, 0, 1, 1, 1, 3, 3, 7, 7, 7]
    assert chain_changes(0, len(values) - 1, values.__getitem__) == {2, 5, 7}
    assert chain_changes(3, 4, values.__getitem__) == set()


def check_below_and_above(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for k in range(3):
        pfs = [random_pf(rng, f"a{k}"), random_pf(rng, f"b{k}")]
        (pair,) = strong_mix_critical(StrongMix(pfs, ONE_DEG)).pairs
        x = pair.critical_tolerance
        assert x is not None
        try:
            made = make_plan(pfs, ToleranceSensor(x), uncertainty=ONE_DEG, certify=False)
        except NoStrongPlan as exc:
            # A part no strong plan orients even alone (a slender part's wide push bands):
            # the pair's critical tolerance says nothing of orienting it.
            assert "has no strong plan even alone" in str(exc)
            continue
        assert made.report.ok  # verified for every outcome and reading (verify_strong)
        assert strong_witnesses(made.result.machine, made.result.lumped_pairs) == []
        machine, _test = strong_test(*pfs)
        breaks = cross_breakpoints(machine)
        above = interval_probe(breaks, breaks.index(x) + 1)
        try:
            over = make_plan(pfs, ToleranceSensor(above), uncertainty=ONE_DEG, certify=False)
        except NoStrongPlan:
            continue
        assert strong_witnesses(over.result.machine, over.result.lumped_pairs) != []


@pytest.mark.parametrize("seed", [5, 8, 9, 11])
def test_below_the_critical_tolerance_a_strong_plan_recognizes_the_pair(seed):
    check_below_and_above(seed)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [4, 6, 7, 10, *range(12, 20)])
def test_below_the_critical_tolerance_on_more_pairs(seed):
    check_below_and_above(seed)


def planner_length(pfs, tolerance: float, unc=ONE_DEG) -> int | None:
    try:
        return plan(build_machine(pfs, ToleranceSensor(tolerance), unc)).length
    except NoStrongPlan:
        return None


def check_steps_against_the_planner(
    pfs, unc=ONE_DEG, stride: int = 1, intervals: int | None = None
) -> None:
    """The table's length at every interval (up to the critical tolerance, or over the first
    ``intervals`` intervals: the larger tolerances' plans are the slow ones) is the
    planner's."""
    breaks = machine_breakpoints(build_machine(pfs, NoSensor(), unc))
    top = None if intervals is None else breaks[intervals - 1]
    design = design_tolerance(pfs, uncertainty=unc, max_tolerance=top)
    x = design.critical.critical_tolerance
    assert x is not None
    if top is not None:
        x = min(x, top)
    last = sum(1 for b in breaks if b <= x * (1 + 1e-9))
    for k in range(0, last, stride):
        e = interval_probe(breaks, k)
        step = design.step_at(e)
        assert step is not None, (k, e)
        assert step.length == planner_length(pfs, e, unc), (k, e, step)


@pytest.mark.parametrize("seed", [0, 1])
def test_strong_steps_match_the_planner_at_every_interval(seed):
    rng = np.random.default_rng(40 + seed)
    check_steps_against_the_planner([random_pf(rng, "a"), random_pf(rng, "b")], intervals=16)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(2, 6))
def test_strong_steps_match_the_planner_up_to_the_critical_tolerance(seed):
    rng = np.random.default_rng(40 + seed)
    check_steps_against_the_planner([random_pf(rng, "a"), random_pf(rng, "b")])


def test_steps_with_a_lumped_near_symmetric_part_match_the_planner():
    check_steps_against_the_planner([near_rectangle(), tri()])


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6))
def test_strong_steps_match_the_planner_on_three_part_mixes(seed):
    rng = np.random.default_rng(60 + seed)
    check_steps_against_the_planner([random_pf(rng, f"p{i}") for i in range(3)], stride=2)


def test_no_strong_plan_is_a_step_without_a_length():
    design = design_tolerance([chamfered(), tri()], uncertainty=ONE_DEG)
    assert design.critical.critical_tolerance is not None  # the parts read apart...
    (step,) = design.steps  # ...but unlike poses of cham keep every strong plan from working
    assert step.length is None and step.expected is None and not step.recognizable
    assert design.critical_tolerance is None and not design.recognizable
    assert "no strong plan exists" in design.answer() and "rotation error 1 deg" in design.answer()
    data = design.to_dict()
    assert data["critical_tolerance_mm"] is None and data["lengths"][0]["length"] is None
    # On the ideal model the same mix is recognizable.
    assert design_tolerance([chamfered(), tri()], uncertainty=IDEAL).recognizable


def test_rotation_error_zero_gives_the_ideal_table_exactly():
    pfs = list(load_parts(MIX).push_functions)
    design = design_tolerance(pfs, uncertainty=IDEAL)
    assert design.critical == mix_critical_tolerance(pfs)
    assert design.steps == length_steps(pfs, design.critical_tolerance)
    assert design.critical_tolerance == 0.9367394278317269
    assert [(s.lo, s.hi, s.length) for s in design.steps] == [
        (0.0, 0.040352929301701534, 2),
        (0.040352929301701534, 0.4367394278317269, 3),
        (0.4367394278317269, 0.9367394278317269, 4),
    ]
    expected = [s.expected for s in design.steps]
    assert expected == pytest.approx([1.659754751993261, 1.8599569254850503, 2.500651315261598])
    assert design.to_dict()["model"] == "ideal model: plans assume no rotation error"


def test_strong_and_ideal_figures_differ_at_one_degree():
    pfs = list(load_parts(MIX).push_functions)
    strong = design_tolerance(pfs, uncertainty=ONE_DEG)
    ideal = design_tolerance(pfs, uncertainty=IDEAL)
    assert strong.critical_tolerance is not None
    assert [s.length for s in strong.steps] != [s.length for s in ideal.steps]
    top = strong.step_at(strong.critical_tolerance)
    assert top is not None and top.length == planner_length(pfs, strong.critical_tolerance)


def test_led_pitches_are_planned_at_the_uncertainty():
    pfs = list(load_parts(MIX[:2]).push_functions)
    design = design_pitches(pfs, [0.2, 1.0, 50.0], uncertainty=ONE_DEG)
    for row in design.rows:
        if row.recognizable:
            sensor = LedSensor(row.pitch)
            made = make_plan(pfs, sensor, uncertainty=ONE_DEG, certify=False)
            assert row.length == made.result.length
        else:
            assert row.length is None and (row.unrecognizable or row.no_plan)
    assert design.rows[-1].unrecognizable  # a 50 mm pitch reads everything alike
    data = design.to_dict()
    assert data["uncertainty"]["applied"] is True and data["uncertainty"]["rotation_error_deg"] == 1
    cham = design_pitches([chamfered(), tri()], [0.05], uncertainty=ONE_DEG)
    assert cham.rows[0].no_plan is not None and not cham.recognizable
    assert cham.answer().startswith("no LED pitch in the list makes this mix recognizable: no ")
    assert (
        "strong plan exists with any of them (strong plans, rotation error 1 deg" in cham.answer()
    )


def test_report_design_takes_the_changeovers_uncertainty():
    pfs = list(load_parts(MIX[:2]).push_functions)
    unc = Uncertainty(0.5, 0.0, 0.01)
    got = report_design(pfs, unc)
    assert got is not None and got["uncertainty"] == {**unc.to_dict(), "applied": True}
    assert report_design(pfs, 0.5)["uncertainty"]["rotation_error_deg"] == 0.5
    assert report_design(pfs, None)["model"].startswith("ideal model")
    with pytest.raises(InputError, match="Uncertainty"):
        design_tolerance(pfs, uncertainty={"rotation_error_deg": 1.0})


# --- the command ----------------------------------------------------------------------------


@pytest.fixture
def cli(tmp_path, monkeypatch):
    group = app_module._click_command()
    if "design" not in getattr(group, "commands", {}):
        design_cli.register(app_module.app)
        app_module._click_command.cache_clear()
    monkeypatch.chdir(tmp_path)


def test_the_json_says_which_uncertainty_was_applied(cli, capsys):
    args = ["design", "sensor", *MIX[:2], "--rotation-error", "0.5", "--com-tolerance", "0.01"]
    assert main([*args, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["uncertainty"] == {
        "rotation_error_deg": 0.5,
        "shape_tolerance_mm": 0.0,
        "com_tolerance_mm": 0.01,
        "applied": True,
    }
    assert "rotation error 0.5 deg" in data["model"] and "COM tolerance 0.01 mm" in data["answer"]
    rows = data["lengths"]
    assert rows and rows[-1]["tolerance_mm"][1] == data["critical_tolerance_mm"]
    assert main(args) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "uncertainty: rotation error ±0.5°, shape tolerance 0 mm, COM tolerance 0.01 mm" in out
    assert "strong plan length by tolerance" in out


def test_rotation_error_zero_on_the_command_line_is_the_ideal_table(cli, capsys):
    assert main(["design", "sensor", *MIX, "--rotation-error", "0", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    # The command designs for every landing (design.md, "Landings").
    pfs = [push_function(x.part) for x in load_landings(MIX).all]
    want = design_tolerance(pfs, uncertainty=IDEAL).to_dict()
    assert data["lengths"] == want["lengths"] and data["pairs"] == want["pairs"]
    assert data["uncertainty"]["applied"] is True and data["uncertainty"]["rotation_error_deg"] == 0


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--shape-tolerance", "-1"], "--shape-tolerance"),
        (["--com-tolerance", "nan"], "--com-tolerance"),
        (["--rotation-error", "95"], "--rotation-error"),
        (["--shape-tolerance", "50"], "shape tolerance"),
    ],
)
def test_bad_uncertainties_are_one_line_exit_2(cli, capsys, args, needle):
    assert main(["design", "sensor", *MIX[:2], *args]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and needle in err


def test_an_answer_names_its_uncertainty_once():
    """A pair no sensor separates under uncertainty gives its reason with the uncertainty in
    it: the answer's end does not say it again (a new user's review: "(no strong plan tells
    ... under rotation error 1 deg, ...) (strong plans, rotation error 1 deg, ...)")."""
    from feederkit.design.sensor import _model_words
    from feederkit.design.strong import uncertainty_words

    u = Uncertainty(1.0, 0.0, 0.0)
    end = f" (strong plans, {uncertainty_words(u)})"
    assert _model_words(("a", "b"), None, u, "") == end
    said = f"no sensor separates a and b (no strong plan tells them apart under {end[16:-1]})"
    assert _model_words(("a", "b"), None, u, said) == ""
    assert _model_words(("a", "b"), None, IDEAL, "") == ""


def test_a_member_with_no_strong_plan_alone_is_named_by_the_design():
    # d-washer has no strong plan at a 0.02 mm shape tolerance: "no tolerance makes this
    # mix recognizable: no strong plan exists up to ..." beside a table deciding every pair
    # read as a contradiction; the design now says which member leaves none, as the
    # compile does.
    from feederkit.uncertainty import Uncertainty

    root = Path(__file__).resolve().parents[1] / "catalog"
    pfs = list(
        load_parts(
            [str(root / f"{n}.json") for n in ("l-bracket", "t-clip", "d-washer")]
        ).push_functions
    )
    design = design_tolerance(pfs, uncertainty=Uncertainty(1.0, 0.02, 0.0), time_limit_s=60.0)
    assert design.critical_tolerance is None and design.critical.critical_tolerance is not None
    assert design.blame.startswith("d-washer has no strong plan even alone")
    assert "(d-washer has no strong plan even alone" in design.answer()
    fine = design_tolerance(pfs[:2], uncertainty=Uncertainty(1.0, 0.02, 0.0), time_limit_s=60.0)
    assert fine.blame == "" and fine.critical_tolerance is not None
