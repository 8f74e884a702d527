"""``feederkit simulate PLAN --part SOURCE``: a plan's part simulated on its own outline.

A plan file carries the contact hull import simplified (chords across arcs), and ``simulate``
simulates that hull by default, so a plan right for the model and wrong for the real part
passes it. With ``--part`` the physics uses the SOURCE's exact hull and COM, the plan runs as
before, and a trial succeeds when the part finally rests within the declared rotation error
plus the settle tolerance of the resting range of a state the leaf names
(docs/simulation.md, "A part's own outline"). The motivating case is the reviewer's washer
with a flat, planned on a hull simplified at 0.05 mm.
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path

import fixtures_cad as fx
import pytest

from feederkit.cli.app import main
from feederkit.errors import InputError
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline, save_outline_json
from feederkit.part import Part, make_part
from feederkit.plans.fileformat import plan_json
from feederkit.plans.make import make_plan
from feederkit.plans.model import Leaf, ResultEntry
from feederkit.plans.readplan import as_plan
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.sim.pushalign import SettleRule, range_distance
from feederkit.sim.real import (
    REAL_SETTLE_RULE,
    check_match,
    exact_part,
    hull_distance,
    real_parts,
    resting_ranges,
    split_spec,
)
from feederkit.sim.summary import wilson
from feederkit.sim.trial import PoseRule
from feederkit.sources import load_part
from feederkit.uncertainty import IDEAL, Uncertainty

ROOT = Path(__file__).resolve().parents[1]
CATALOG = ROOT / "catalog"

needs_mujoco = pytest.mark.skipif(
    not __import__("feederkit.sim", fromlist=["mujoco_available"]).mujoco_available(),
    reason="MuJoCo is not installed here: pip install 'feederkit[sim]' to run these",
)


# ---------------------------------------------------------------- the washer with a flat


def _washer_with_flat(msp) -> None:
    """An R15 washer with a flat at y = 12 and an R6 hole (the reviewer's washer_flat.dxf): it
    rests on the flat (27 mm) or on its arc's lowest point (the COM is 0.87 mm below the
    centre), also 27 mm wide."""
    x = math.sqrt(15.0**2 - 12.0**2)
    a0, a1 = math.degrees(math.atan2(12.0, -x)), math.degrees(math.atan2(12.0, x)) + 360.0
    bulge = math.tan(math.radians(a1 - a0) / 4.0)
    msp.add_lwpolyline([(x, 12.0, 0, 0, 0), (-x, 12.0, 0, 0, bulge)], format="xyseb", close=True)
    msp.add_circle((0.0, 0.0), 6.0)


@pytest.fixture(scope="module")
def washer(tmp_path_factory) -> Path:
    return fx.write_entities(tmp_path_factory.mktemp("washer") / "washer.dxf", _washer_with_flat)


@lru_cache(maxsize=4)
def _washer_plan(path: str, hull_tolerance: float | None) -> str:
    """The washer's plan (tolerance sensor 0.1 mm, rotation error 1 degree): on the part the
    import makes (``None``: its own hull tolerance, lowered until the hull rests where the
    outline does), or on a hull simplified at ``hull_tolerance`` as import did before."""
    part = load_part(path)
    if hull_tolerance is None:
        return plan_json(make_plan([push_function(part)], ToleranceSensor(0.1)).plan)
    # On the arc's chords no strong plan exists under the vibration (a push rolls on over the
    # chords' shallow wells, docs/uncertainty.md): the ideal model's plan, for the match check.
    part = make_part(part.outline, part.com, hull_tolerance=hull_tolerance)
    return plan_json(make_plan([push_function(part)], ToleranceSensor(0.1), uncertainty=IDEAL).plan)


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@lru_cache(maxsize=4)
def _catalog_plan(*names: str) -> str:
    pfs = [push_function(load_part(str(CATALOG / f"{n}.json"))) for n in names]
    return plan_json(make_plan(pfs, ToleranceSensor(0.05)).plan)


def _lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip()]


def _words(text: str) -> str:
    return " ".join(text.split())  # the terminal wraps lines


# ---------------------------------------------------------------- pure pieces


def test_hull_distance_is_the_largest_gap_between_two_convex_regions() -> None:
    square = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
    assert hull_distance(square, square) == 0.0
    shifted = [(x + 0.3, y) for x, y in square]
    assert hull_distance(square, shifted) == pytest.approx(0.3)
    cut = [(0.0, 0.0), (10.0, 0.0), (10.0, 8.0), (8.0, 10.0), (0.0, 10.0)]  # a corner off
    assert hull_distance(square, cut) == pytest.approx(math.sqrt(2.0))
    assert hull_distance(cut, square) == hull_distance(square, cut)


def test_range_distance_and_the_pose_rule() -> None:
    assert range_distance(100.0, 90.0, 110.0) == 0.0
    assert range_distance(85.0, 90.0, 110.0) == pytest.approx(5.0)
    assert range_distance(1.0, 350.0, 365.0) == 0.0  # hi past 360
    assert range_distance(340.0, 350.0, 365.0) == pytest.approx(10.0)
    rule = PoseRule(2.0, {0: ((270.0, 270.0),), 1: ((80.0, 100.0),)})
    leaf = Leaf((ResultEntry("w", 0, 0.0), ResultEntry("w", 1, 180.0)))
    assert rule.leaf_error(leaf, "w", None, 268.5) == pytest.approx(1.5)
    assert rule.leaf_error(leaf, "w", None, 101.0) == pytest.approx(1.0)
    assert rule.leaf_error(leaf, "other", None, 270.0) == math.inf


def test_the_settle_rule_for_an_outline_waits_out_a_jitter_but_not_a_drift() -> None:
    jitter = [270.0 + (1.4 if k % 2 else -1.4) for k in range(20)]
    drift = [250.0 + 0.1 * k for k in range(20)]  # 1 degree over the window
    assert not SettleRule().still(jitter)  # the default: range below 1 degree
    assert REAL_SETTLE_RULE.still(jitter)
    assert not REAL_SETTLE_RULE.still(drift)
    assert SettleRule().still([0.0, 0.5, 0.9]) and not SettleRule().still([0.0, 1.0])


def test_the_washers_outline_rests_at_its_arcs_lowest_point_and_on_its_flat(washer) -> None:
    plan = as_plan(json.loads(_washer_plan(str(washer), None)))
    (real,) = real_parts(plan, [str(washer)])  # the drawing's arc flattened finely
    rests = resting_ranges(real.part)
    assert rests == real.rests
    lowest = sorted(round(r[2], 1) for r in rests)
    assert lowest == [90.0, pytest.approx(270.0, abs=0.5)]
    arc = next(r for r in rests if r[2] != 90.0)
    assert arc[0] <= arc[2] <= arc[1]


def test_the_match_check_accepts_the_plans_part_and_refuses_another(washer) -> None:
    plan = as_plan(json.loads(_washer_plan(str(washer), 0.05)))
    (real,) = real_parts(plan, [str(washer)])
    assert real.part.hull == exact_part(real.part).hull  # nothing simplified
    assert len(real.part.hull) > len(plan.parts[0].hull)
    # the plan's chords lie within the hull tolerance (plus the flattening) of the true arc
    assert 0.04 < real.hull_distance_mm <= real.allowed_mm == pytest.approx(0.05 + 0.01, abs=1e-4)
    # beyond the declared shape tolerance 0 by more than the flattening: said (this plan names
    # wrong poses for the true outline, docs/simulation.md)
    assert real.beyond_tolerance and "declared shape tolerance of 0 mm" in real.tolerance_warning()
    assert real.com_distance_mm < 0.01
    # another part, the same part moved 1 mm, a COM elsewhere: refused, naming the distance
    disc = make_part(
        make_outline("disc", [(15 * math.cos(k / 10), 15 * math.sin(k / 10)) for k in range(63)])
    )
    with pytest.raises(InputError, match=r"disc\.dxf: not the part the plan was made for: its "):
        check_match(plan, 0, disc, "disc.dxf")
    part = load_part(str(washer))
    moved = make_part(
        make_outline(
            "moved",
            [(x + 1.0, y) for x, y in part.outline.vertices],
            holes=[[(x + 1.0, y) for x, y in h] for h in part.outline.holes],
        )
    )
    far = r"hull lies 1\.0\d* mm from the plan's hull of washer \(allowed 0\.06"
    with pytest.raises(InputError, match=far):
        check_match(plan, 0, moved, "moved.json")
    heavy = make_part(part.outline, (part.com[0] + 0.5, part.com[1]))
    with pytest.raises(InputError, match=r"its COM lies 0\.5 mm from the plan's COM"):
        check_match(plan, 0, heavy, "heavy.json")
    # the hull tolerance of the plan's import is what is allowed: a plan said to be exact is
    # not this part's (its chords lie 0.048 mm inside the arc)
    with pytest.raises(InputError, match=r"\(allowed 0\.01\d* mm: shape tolerance 0 \+ hull "):
        check_match(plan, 0, part, str(washer), hull_tolerance=0.0)
    assert check_match(plan, 0, part, str(washer), hull_tolerance=0.1).allowed_mm > 0.1


@lru_cache(maxsize=1)
def _bracket_plan_at(shape_tolerance: float) -> str:
    """The l-bracket's sensorless plan declaring ``shape_tolerance`` mm (COM 0.3 mm)."""
    part = load_part(str(CATALOG / "l-bracket.json"))
    unc = Uncertainty(1.0, shape_tolerance, 0.3)  # the moved corner moves the COM too
    return plan_json(make_plan([push_function(part)], NoSensor(), uncertainty=unc).plan)


def _bracket_corner_moved(dx: float) -> Part:
    """The l-bracket with its corner (60, 0) moved ``dx`` mm along x: its hull lies ``dx``
    from the drawn one."""
    part = load_part(str(CATALOG / "l-bracket.json"))
    vertices = [(x + dx, y) if (x, y) == (60.0, 0.0) else (x, y) for x, y in part.outline.vertices]
    return make_part(make_outline(part.name, vertices, holes=part.outline.holes))


def test_a_part_beyond_the_declared_shape_tolerance_is_simulated_with_a_warning() -> None:
    """Within the match check's allowance (shape tolerance + a CAD hull tolerance + slack) but
    beyond the shape tolerance the plan declares: accepted, and said in one line."""
    plan = as_plan(json.loads(_bracket_plan_at(0.2)))
    beyond = check_match(plan, 0, _bracket_corner_moved(0.25), "beyond.json")
    assert beyond.hull_distance_mm == pytest.approx(0.25) and beyond.beyond_tolerance
    line = beyond.tolerance_warning()
    assert line is not None and "\n" not in line
    assert "beyond.json's hull lies 0.25 mm from the plan's hull" in line
    assert "declared shape tolerance of 0.2 mm" in line
    assert "guaranteed only within its declared tolerance" in line
    assert "its certificate's largest shape tolerance: " in line
    assert "up to 0.2601 mm is accepted" in line
    # The plan file does not record its import's hull tolerance: the default is a bound.
    assert "up to 0.05 mm of it may be the hull tolerance of the plan's import" in line
    assert beyond.to_dict()["warning"] == line
    within = check_match(plan, 0, _bracket_corner_moved(0.2), "within.json")
    assert not within.beyond_tolerance and within.tolerance_warning() is None
    assert within.to_dict()["warning"] is None


def test_part_values_name_a_member_of_the_plan() -> None:
    mix = as_plan(json.loads(_catalog_plan("rectangle-2x1", "equilateral-triangle")))
    rect = str(CATALOG / "rectangle-2x1.json")
    assert split_spec(mix, f"rectangle-2x1={rect}") == ("rectangle-2x1", rect)
    with pytest.raises(InputError, match=r"'bogus' is not one of the plan's parts"):
        split_spec(mix, f"bogus={rect}")
    with pytest.raises(InputError, match=r"the plan has 2 parts .* --part NAME=SOURCE"):
        split_spec(mix, rect)
    with pytest.raises(InputError, match=r"given twice"):
        real_parts(mix, [f"rectangle-2x1={rect}", f"rectangle-2x1={rect}"])
    (one,) = real_parts(mix, [f"rectangle-2x1={rect}"])
    assert (one.member, one.label, one.hull_distance_mm) == (0, "rectangle-2x1", 0.0)
    single = as_plan(json.loads(_catalog_plan("t-clip")))
    assert split_spec(single, "anything.dxf") == ("t-clip", "anything.dxf")


# ---------------------------------------------------------------- the command line (MuJoCo)


@needs_mujoco
def test_a_part_that_is_not_the_plans_is_refused_in_one_line(
    tmp_path: Path, washer, capsys
) -> None:
    plan = _write(tmp_path, "washer.plan.json", _washer_plan(str(washer), 0.05))
    other = fx.write_entities(tmp_path / "disc.dxf", lambda msp: msp.add_circle((0, 0), 15.0))
    cases = [
        ([str(other)], "not the part the plan was made for: its outline's hull lies"),
        (["no-such-part"], "no-such-part: no such file or catalog part"),
        ([f"bogus={washer}"], "'bogus' is not one of the plan's parts (washer)"),
    ]
    for parts, words in cases:
        args = ["simulate", str(plan), "--trials", "2"]
        for p in parts:
            args += ["--part", p]
        assert main(args) == 2, parts
        captured = capsys.readouterr()
        (line,) = _lines(captured.err)
        assert line.startswith("error: ") and words in line, line
        assert captured.out == ""
    # the plan's own part is accepted (the fast test below runs it)


@needs_mujoco
def test_the_summary_and_json_name_the_outline_simulated(tmp_path: Path, washer, capsys) -> None:
    plan = _write(tmp_path, "washer.plan.json", _washer_plan(str(washer), None))
    args = ["simulate", str(plan), "--trials", "2", "--part", str(washer)]
    assert main([*args, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    (geo,) = d["geometry"]
    plan_hull = json.loads(plan.read_text(encoding="utf-8"))["parts"][0]["hull"]
    assert geo["part"] == "washer" and geo["simulated"] == "outline"
    assert geo["source"] == str(washer)
    assert geo["hull_vertices"] > 2 * len(plan_hull)  # the exact hull of the finely drawn arc
    assert geo["hull_distance_mm"] <= geo["allowed_mm"]
    assert d["success_rule"]["limit_deg"] == 2.0  # rotation error 1 + settle tolerance 1
    assert d["settings"]["sampled_uncertainty"]["shape_tolerance_mm"] == 0.0
    assert d["trials"] == 2 and d["successes"] == 2
    assert d["warnings"] == [] and geo["warning"] is None  # the import's hull: within slack
    assert main(args) == 0
    captured = capsys.readouterr()
    assert "shape tolerance" not in captured.err
    out = _words(captured.out)
    assert f"geometry washer: its own outline from {washer} (exact hull" in out
    assert (
        "success rule a part on its own outline succeeds when it finally rests within 2 deg" in out
    )
    # without --part: the plan's hull, and the JSON as it always was
    assert main(["simulate", str(plan), "--trials", "2", "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert "geometry" not in plain and "success_rule" not in plain


@needs_mujoco
def test_simulate_warns_of_a_part_beyond_the_declared_shape_tolerance(
    tmp_path: Path, capsys
) -> None:
    plan = _write(tmp_path, "lb.plan.json", _bracket_plan_at(0.2))
    source = tmp_path / "lb_beyond.json"
    save_outline_json(_bracket_corner_moved(0.25).outline, source)
    args = ["simulate", str(plan), "--trials", "1", "--part", str(source)]
    assert main(args) == 0
    captured = capsys.readouterr()
    (line,) = [w for w in _words(captured.err).split("warning: ") if "shape tolerance" in w]
    assert "lies 0.25 mm from the plan's hull" in line and "tolerance of 0.2 mm" in line
    assert main([*args, "--json"]) == 0
    captured = capsys.readouterr()
    (warning,) = json.loads(captured.out)["warnings"]
    assert "lies 0.25 mm" in warning and "guaranteed only within its declared" in warning
    assert "guaranteed only within its declared" in _words(captured.err)


@needs_mujoco
def test_the_physics_runs_on_the_sources_part(monkeypatch) -> None:
    """The members named by --part get an aligner of their own outline (and its resting
    ranges); the others keep the plan's hull."""
    import feederkit.sim.api as api

    mix = as_plan(json.loads(_catalog_plan("rectangle-2x1", "equilateral-triangle")))
    (real,) = real_parts(mix, [f"equilateral-triangle={CATALOG / 'equilateral-triangle.json'}"])
    built: list[tuple[object, object]] = []

    class Recording(api.PushAligner):
        def __init__(self, part, *args, **kwargs) -> None:
            built.append((part, kwargs.get("rests")))
            super().__init__(part, *args, **kwargs)

    monkeypatch.setattr(api, "PushAligner", Recording)
    summary = api.simulate_plan(mix, 2, 0, real=[real])
    assert built[0][0] == api.push_function_of(mix.parts[0]).part and built[0][1] is None
    assert built[1][0] is real.part and built[1][1] == real.rests
    assert summary.real_parts == (real,)
    assert [g for _, g in summary.geometry()][0] == "rectangle-2x1: the plan's hull"


# ---------------------------------------------------------------- the motivating case (slow)


def _run(args: list[str], capsys) -> dict:
    assert main([*args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@needs_mujoco
@pytest.mark.slow
def test_a_plan_on_a_simplified_hull_fails_on_the_washers_true_outline(
    tmp_path: Path, washer, capsys
) -> None:
    """The reviewer's washer with a flat: planned on its hull simplified at 0.05 mm (chords
    that hold the part where its arc rolls), the plan passes ``simulate`` and names the wrong
    pose on the true outline; the plan the import now makes passes on both.

    Measured (30 trials, seed 0) with that plan made under 1 degree: 12 of 30 on the true
    outline (95 % Wilson 24.5-57.7 %; 3 named the flat for a washer on its arc, 15 a pose
    2.9-3.6 degrees off), 30 of 30 on the plan's hull; the import's plan 30 of 30 on the true
    outline (docs/simulation.md). Under 1 degree the chords now have no strong plan (a push
    rolls on over their shallow wells, docs/uncertainty.md): the plan on them is the ideal
    model's: 2 of 30 on the true outline, its wrong poses chord states 1.6-3.6 degrees off.
    """
    trials = 30
    old = _write(tmp_path, "old.plan.json", _washer_plan(str(washer), 0.05))
    new = _write(tmp_path, "new.plan.json", _washer_plan(str(washer), None))
    common = ["--trials", str(trials), "--seed", "0"]
    on_hull = _run(["simulate", str(old), *common], capsys)
    assert on_hull["successes"] == trials  # simulate without --part cannot see it
    on_outline = _run(["simulate", str(old), *common, "--part", str(washer)], capsys)
    k = on_outline["successes"]
    lo, hi = wilson(k, trials)
    assert k <= 0.8 * trials and hi < 0.9, (k, lo, hi)  # a meaningful share fails
    # The true outline reads a little wider than the simplified hull: some runs end at a
    # reading the plan has no branch for, the others at a wrong pose.
    failures = on_outline["failures"]
    assert {r["cause"] for r in failures} <= {"wrong result", "reading in no branch"}
    wrong = [r for r in failures if r["cause"] == "wrong result"]
    assert wrong and all(r["pose_error_deg"] > 1.0 for r in wrong)  # chord states, not the arc
    fixed = _run(["simulate", str(new), *common, "--part", str(washer)], capsys)
    assert fixed["successes"] == trials, fixed["went_wrong"][:1]
