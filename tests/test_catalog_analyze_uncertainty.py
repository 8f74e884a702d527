"""``catalog analyze --rotation-error [--shape-tolerance] [--com-tolerance]``: the pairs
section 8 tells apart on the ideal model that no strong plan tells apart under the declared
uncertainty, decided per pair as ``changeover compile`` decides a mix
(feederkit.mix.strongpairs)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from shared import no_stray_profile, one_line_error  # noqa: F401 (autouse)

from feederkit.cli.app import main
from feederkit.cli.catalog_analyze import _advice

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


def run(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


@pytest.fixture()
def db(tmp_path, capsys) -> str:
    """The L bracket, a copy of it 0.05 mm longer (a near-duplicate), and the T clip."""
    path = str(tmp_path / "c.db")
    bracket = json.loads((CATALOG / "l-bracket.json").read_text())
    near = {**bracket, "name": "l-bracket-near"}
    near["vertices"] = [[x + 0.05 if x > 30 else x, y] for x, y in bracket["vertices"]]
    (tmp_path / "near.json").write_text(json.dumps(near))
    assert run(capsys, "catalog", "init", "--catalog", path)[0] == 0
    for source in (CATALOG / "l-bracket.json", tmp_path / "near.json", CATALOG / "t-clip.json"):
        assert run(capsys, "catalog", "add", str(source), "--catalog", path)[0] == 0
    return path


def test_a_near_duplicate_is_apart_only_on_the_ideal_model(db, capsys):
    args = ("catalog", "analyze", "--tolerance", "0.5", "--json", "--catalog", db)
    rc, out, _ = run(capsys, *args)
    ideal = json.loads(out)
    assert rc == 0 and ideal["unrecognizable_pairs"] == []
    assert ideal["apart_only_on_the_ideal_model"] == []
    assert ideal["uncertainty"]["rotation_error_deg"] == 0.0
    rc, out, err = run(capsys, *args, "--rotation-error", "1")
    data = json.loads(out)
    assert rc == 1 and "only under the rotation error ±1 deg" in err
    found = {(w["part_a"], w["part_b"]) for w in data["apart_only_on_the_ideal_model"]}
    assert found == {
        ("l-bracket/up", "l-bracket-near/up"),
        ("l-bracket/down", "l-bracket-near/down"),
    }
    assert data["uncertainty"]["rotation_error_deg"] == 1.0
    assert data["counts"]["apart_only_on_the_ideal_model"] == 2


def test_compile_agrees_pair_by_pair(db, capsys):
    """What the analysis lists, compile reports for the pair; what it clears, compile plans."""
    base = ("changeover", "compile")
    rc, out, _ = run(
        capsys, *base, "near", "--mix", "l-bracket,l-bracket-near", "--tolerance", "0.5",
        "--json", "--catalog", db,
    )  # fmt: skip
    assert rc == 1
    pairs = {(w["part_a"], w["part_b"]) for w in json.loads(out)["unrecognizable_pairs"]}
    assert ("l-bracket/up", "l-bracket-near/up") in pairs
    rc, _, _ = run(
        capsys, *base, "far", "--mix", "l-bracket,t-clip", "--tolerance", "0.5", "--catalog", db
    )
    assert rc == 0


def test_a_tolerance_too_large_for_a_part_is_refused_by_the_library():
    """Before any work, naming the part, as ``plan`` refuses it."""
    from feederkit.errors import InputError
    from feederkit.mechanics.push import push_function
    from feederkit.mix.analyze import analyze_mix
    from feederkit.outline import make_outline
    from feederkit.part import make_part
    from feederkit.sensors import ToleranceSensor
    from feederkit.uncertainty import Uncertainty

    bar = push_function(make_part(make_outline("bar", [(0, 0), (40, 0), (40, 4), (0, 4)])))
    with pytest.raises(InputError, match="^bar: shape tolerance 2 mm must be below"):
        analyze_mix([bar], ToleranceSensor(0.5), uncertainty=Uncertainty(1.0, 2.0))
    with pytest.raises(InputError, match="^bar: COM tolerance 2 mm must be below"):
        analyze_mix([bar], ToleranceSensor(0.5), uncertainty=Uncertainty(0.0, 0.0, 2.0))


def test_the_advice_names_the_rotation_error():
    from feederkit.uncertainty import Uncertainty

    assert "smaller rotation error" in _advice({"uncertainty"})
    assert "tolerances" not in _advice({"uncertainty"}, Uncertainty(1.0))
    both = _advice({"uncertainty", "tolerance"})
    assert both.startswith("keep them out of one mix or use a finer sensor;")
    shape = _advice({"uncertainty"}, Uncertainty(1.0, 0.05))
    assert "smaller rotation error or tighter shape and COM tolerances" in shape
    assert "rotation" not in _advice({"uncertainty"}, Uncertainty(0.0, 0.05))


def test_a_pair_whose_largest_widths_read_apart_is_checked_too(tmp_path, capsys):
    """Two 4 mm bars, 40 and 39.36 mm long: their long widths read apart at 0.2 mm, so the
    ideal analysis does not even make them candidates (a plan can always turn a bar onto its
    end there); under 1 degree the end is a state no strong plan relies on, and compile
    cannot tell them apart. The screen lists them, as compile reports them."""
    folder = tmp_path / "bars"
    folder.mkdir()
    for name, length in (("c40", 40.0), ("c39", 39.36)):
        ring = [[0, 0], [length, 0], [length, 4], [0, 4]]
        (folder / f"{name}.json").write_text(
            json.dumps({"name": name, "units": "mm", "vertices": ring})
        )
    db = str(tmp_path / "bars.db")
    assert run(capsys, "catalog", "init", "--catalog", db)[0] == 0
    assert run(capsys, "catalog", "import", str(folder), "--catalog", db)[0] == 0
    args = ("catalog", "analyze", "--tolerance", "0.2", "--json", "--catalog", db)
    rc, out, _ = run(capsys, *args, "--rotation-error", "1")
    data = json.loads(out)
    assert rc == 1 and data["counts"]["candidate_pairs"] == 0
    assert [{w["part_a"], w["part_b"]} for w in data["apart_only_on_the_ideal_model"]] == [
        {"c40", "c39"}
    ]
    compile_args = ("changeover", "compile", "bars", "--mix", "c40,c39", "--tolerance", "0.2")
    rc, _, err = run(capsys, *compile_args, "--catalog", db)
    assert rc == 1 and "cannot tell these apart" in err


def test_a_pair_the_search_cannot_decide_is_counted_not_cleared(db, capsys, monkeypatch):
    """A pair whose unresolvable-pairs search runs out of sets is neither listed nor cleared:
    the analysis counts it undecided, in the table and in the JSON."""
    import feederkit.mix.strongpairs as strongpairs

    monkeypatch.setattr(strongpairs, "unresolvable_pairs", lambda problem, deadline=None: None)
    args = ("catalog", "analyze", "--tolerance", "0.5", "--rotation-error", "1", "--catalog", db)
    rc, out, _ = run(capsys, *args, "--json")
    data = json.loads(out)
    assert data["apart_only_on_the_ideal_model"] == []
    assert data["counts"]["undecided_pairs"] >= 2  # the bracket and its near-duplicate, both sides
    rc, out, _ = run(capsys, *args)
    assert "undecided: too many sets" in out


@pytest.fixture()
def rects(tmp_path, capsys) -> str:
    """Two rectangles, 40 x 10 and 41.1 x 11.1 mm: at a sensor tolerance of 0.5 mm every
    state reads apart from the other's (1.1 mm > 2 x 0.5), but under a shape tolerance of
    0.05 mm the diameter intervals come within 2 x 0.5 (1.1 mm < 2 x 0.5 + 4 x 0.05)."""
    folder = tmp_path / "rects"
    folder.mkdir()
    for name, (length, width) in {"r10": (40.0, 10.0), "r11": (41.1, 11.1)}.items():
        ring = [[0, 0], [length, 0], [length, width], [0, width]]
        (folder / f"{name}.json").write_text(
            json.dumps({"name": name, "units": "mm", "vertices": ring})
        )
    path = str(tmp_path / "rects.db")
    assert run(capsys, "catalog", "init", "--catalog", path)[0] == 0
    assert run(capsys, "catalog", "import", str(folder), "--catalog", path)[0] == 0
    return path


def _listed(capsys, db: str, *flags: str) -> tuple[int, dict]:
    args = ("catalog", "analyze", "--tolerance", "0.5", "--json", "--catalog", db, *flags)
    rc, out, _ = run(capsys, *args)
    return rc, json.loads(out)


def test_a_shape_tolerance_lists_a_pair_that_reads_apart_nominally(rects, capsys):
    """The pair reads apart on the nominal diameters, so the screen under a rotation error
    alone never checks it; under the shape tolerance its diameter intervals read alike and
    it is listed, as ``changeover compile`` with the same flags reports it."""
    rc, data = _listed(capsys, rects, "--rotation-error", "1")
    assert rc == 0 and data["apart_only_on_the_ideal_model"] == []
    rc, data = _listed(capsys, rects, "--rotation-error", "1", "--shape-tolerance", "0.05")
    assert rc == 1 and data["counts"]["candidate_pairs"] == 0
    assert [(w["part_a"], w["part_b"]) for w in data["apart_only_on_the_ideal_model"]] == [
        ("r10", "r11")
    ]
    assert "shape 0.05 mm" in data["apart_only_on_the_ideal_model"][0]["reason"]
    base = ("changeover", "compile", "x", "--mix", "r10,r11", "--tolerance", "0.5", "--json")
    rc, out, _ = run(capsys, *base, "--catalog", rects)
    assert rc == 0 and json.loads(out)["unrecognizable_pairs"] == []
    rc, out, err = run(capsys, *base, "--replace", "--shape-tolerance", "0.05", "--catalog", rects)
    assert rc == 1 and "cannot tell these apart" in err
    pairs = json.loads(out)["unrecognizable_pairs"]
    assert [(w["part_a"], w["part_b"]) for w in pairs] == [("r10", "r11")]


def test_a_tolerance_without_a_rotation_error_takes_compiles_default(rects, capsys):
    """``--shape-tolerance`` alone is checked at design.md's rotation error (1 degree), as
    compile takes it without a cell profile; ``--rotation-error 0`` with it is the tolerance
    alone, still checked for strong plans (not the ideal model), as compile plans it; no
    flag at all stays the ideal analysis."""
    rc, data = _listed(capsys, rects, "--shape-tolerance", "0.05")
    assert rc == 1 and data["uncertainty"]["rotation_error_deg"] == 1.0
    rc, data = _listed(capsys, rects, "--rotation-error", "0", "--shape-tolerance", "0.05")
    assert rc == 1 and data["uncertainty"]["rotation_error_deg"] == 0.0
    assert len(data["apart_only_on_the_ideal_model"]) == 1
    base = ("changeover", "compile", "x", "--mix", "r10,r11", "--tolerance", "0.5")
    flags = ("--rotation-error", "0", "--shape-tolerance", "0.05", "--catalog", rects)
    rc, _, err = run(capsys, *base, *flags)
    assert rc == 1 and "cannot tell these apart" in err
    rc, data = _listed(capsys, rects)
    assert rc == 0 and set(data["uncertainty"].values()) == {0.0}


def test_the_json_states_the_whole_uncertainty(rects, capsys):
    flags = ("--rotation-error", "0.5", "--shape-tolerance", "0.05", "--com-tolerance", "0.02")
    _rc, data = _listed(capsys, rects, *flags)
    assert data["uncertainty"] == {
        "rotation_error_deg": 0.5,
        "shape_tolerance_mm": 0.05,
        "com_tolerance_mm": 0.02,
    }


def test_the_summary_and_the_result_name_the_tolerances(rects, capsys):
    args = ("catalog", "analyze", "--tolerance", "0.5", "--shape-tolerance", "0.05")
    rc, out, err = run(capsys, *args, "--catalog", rects)
    assert rc == 1
    assert "only under the rotation error ±1 deg, a shape tolerance of 0.05 mm" in err
    assert "tighter shape and COM tolerances" in err
    assert "shape tolerance of 0.05 mm" in " ".join(out.split())


@pytest.mark.parametrize(
    ("flags", "words"),
    [
        (("--shape-tolerance", "-1"), "shape tolerance must be a finite nonnegative"),
        (("--shape-tolerance", "inf"), "(--shape-tolerance)"),
        (("--com-tolerance", "nan"), "COM tolerance must be a finite nonnegative"),
        (("--com-tolerance", "x"), "Invalid value for '--com-tolerance'"),
        (("--rotation-error", "90", "--shape-tolerance", "0.1"), "(--rotation-error)"),
        (("--shape-tolerance", "6"), "r10: shape tolerance 6 mm must be below half the"),
        (("--com-tolerance", "6"), "r10: COM tolerance 6 mm must be below"),
    ],
)
def test_bad_uncertainty_flags_are_one_line(rects, capsys, flags, words):
    """The words ``plan`` and ``changeover compile`` say, a tolerance too large for every
    part naming the first and the flag; exit 2."""
    args = ["catalog", "analyze", "--tolerance", "0.5", *flags, "--catalog", rects]
    err = one_line_error(capsys, args)
    assert words in err
    if "r10:" in words:
        assert f"({flags[0]})" in err


def test_reading_pairs_under_a_shape_tolerance():
    """Rotation error alone keeps the nominal pairs; a shape tolerance adds the pairs whose
    physical states' diameter intervals may read alike (not those chained through a third:
    c reads alike a only), and keeps the nominal ones."""
    from feederkit.mechanics.push import push_function
    from feederkit.mix.strongpairs import reading_pairs
    from feederkit.outline import make_outline
    from feederkit.part import make_part
    from feederkit.sensors import ToleranceSensor
    from feederkit.uncertainty import Uncertainty

    def rect(name: str, length: float, width: float):
        ring = [(0, 0), (length, 0), (length, width), (0, width)]
        return push_function(make_part(make_outline(name, ring)))

    pfs = [rect("a", 40, 10), rect("b", 41.1, 11.1), rect("c", 39.5, 20), rect("d", 60, 30)]
    sensor = ToleranceSensor(0.5)
    nominal = reading_pairs(pfs, sensor)
    assert nominal == {(0, 2)} == reading_pairs(pfs, sensor, Uncertainty(1.0))
    assert reading_pairs(pfs, sensor, Uncertainty(1.0, 0.05)) == {(0, 1), (0, 2)}
    assert reading_pairs(pfs, sensor, Uncertainty(0.0, 0.04, 0.01)) == {(0, 1), (0, 2)}
    assert reading_pairs(pfs, sensor, Uncertainty(1.0, 0.0, 0.05)) == {(0, 2)}


def test_a_member_no_strong_plan_orients_alone_is_listed_once_not_in_every_pair(tmp_path, capsys):
    """The 2 x 1 mm rectangle under a shape tolerance of 0.05 mm has no strong plan even
    alone (compile says so): the analysis lists it as such and checks none of its pairs, where
    each pair with it used to be listed as a pair no strong plan tells apart."""
    path = str(tmp_path / "c.db")
    assert run(capsys, "catalog", "init", "--catalog", path)[0] == 0
    for name in ("rectangle-2x1", "t-clip", "l-bracket"):
        assert (
            run(capsys, "catalog", "add", str(CATALOG / f"{name}.json"), "--catalog", path)[0] == 0
        )
    flags = ("--tolerance", "0.5", "--rotation-error", "1", "--shape-tolerance", "0.05")
    rc, out, err = run(capsys, "catalog", "analyze", *flags, "--json", "--catalog", path)
    data = json.loads(out)
    assert rc == 1 and "no strong plan orients even alone" in err
    alone = {x["part"]: x["states"] for x in data["no_strong_plan_alone"]}
    assert set(alone) == {"rectangle-2x1/up", "rectangle-2x1/down"}
    assert all(alone.values())
    assert data["counts"]["no_strong_plan_alone"] == 2
    listed = {n for w in data["apart_only_on_the_ideal_model"] for n in (w["part_a"], w["part_b"])}
    assert not any(n.startswith("rectangle-2x1") for n in listed)
    # compile agrees: the rectangle alone has no strong plan; the other two have one
    compile_ = ("changeover", "compile", "x", "--catalog", path, *flags)
    rc, _, err = run(capsys, *compile_, "--mix", "rectangle-2x1")
    assert rc == 1 and "no strong plan" in err
    rc, _, _ = run(capsys, *compile_, "--mix", "t-clip")
    assert rc == 0
    rc, out, _ = run(capsys, "catalog", "analyze", *flags, "--catalog", path)
    assert "no strong plan orients these even alone" in out and "rectangle-2x1/up" in out
    # without a sensor no pair is listed (section 8.6), and the members are still checked
    blind = ("--sensorless", "--rotation-error", "1", "--shape-tolerance", "0.05", "--json")
    rc, out, _ = run(capsys, "catalog", "analyze", *blind, "--catalog", path)
    names = {x["part"] for x in json.loads(out)["no_strong_plan_alone"]}
    assert rc == 1 and {"rectangle-2x1/up", "rectangle-2x1/down"} <= names


def test_check_alone_agrees_with_plan():
    """check_alone says "no strong plan" exactly where plan does (a brute check of the
    library's verdict against the planner's): the sample parts and a near-square trapezoid
    whose every pair of states has a strong plan while the whole set has none, at two shape
    tolerances, with a sensor and without."""
    from feederkit.errors import PlanningError
    from feederkit.mechanics.push import push_function
    from feederkit.mix.strongpairs import check_alone
    from feederkit.outline import load_outline_json, make_outline
    from feederkit.part import make_part
    from feederkit.plans.make import make_plan
    from feederkit.sensors import NoSensor, ToleranceSensor
    from feederkit.uncertainty import Uncertainty

    square = [(12.40, -10.92), (12.42, 12.31), (-12.42, 12.31), (-12.40, -10.92)]
    pfs = [push_function(make_part(load_outline_json(p))) for p in sorted(CATALOG.glob("*.json"))]
    pfs.append(push_function(make_part(make_outline("nsq", square, com=(0.0, -0.97)))))
    disagree: list[tuple[str, float, str, bool]] = []
    seen: set[bool] = set()
    for pf in pfs:
        for sensor in (ToleranceSensor(0.5), ToleranceSensor(1.0), NoSensor()):
            for shape in (0.0, 0.05):
                unc = Uncertainty(1.0, shape)
                verdict = check_alone(pf, sensor, unc)
                assert verdict.decided
                try:
                    make_plan([pf], sensor, uncertainty=unc, certify=False)
                    planned = True
                except PlanningError as exc:
                    assert "no strong plan" in str(exc)
                    planned = False
                    assert verdict.states  # the states to blame are named
                seen.add(planned)
                if planned != verdict.orients:
                    disagree.append((pf.part.name, shape, type(sensor).__name__, planned))
    assert not disagree and seen == {True, False}


def test_two_landings_of_one_part_get_their_own_advice(tmp_path, capsys):
    """A pair that is one part's two sides cannot be kept out of one mix: the line says to
    plan one landing or reject the others."""
    path = str(tmp_path / "c.db")
    assert run(capsys, "catalog", "init", "--catalog", path)[0] == 0
    for name in ("rectangle-2x1", "l-bracket"):
        assert (
            run(capsys, "catalog", "add", str(CATALOG / f"{name}.json"), "--catalog", path)[0] == 0
        )
    rc, _, err = run(capsys, "catalog", "analyze", "--tolerance", "1", "--catalog", path)
    assert rc == 1 and "rectangle-2x1/up & rectangle-2x1/down" in err
    assert "1 of them two landings of one part" in err and "--landings" in err
    assert "only under" not in err  # the ideal model's pair: no rotation error declared


def test_a_member_beyond_the_set_budget_is_undecided_and_its_pairs_still_checked(
    db, capsys, monkeypatch
):
    """check_alone explores at most ALONE_SETS sets per search (a screen must not hang on one
    member): beyond it the member is undecided, counted, and its pairs are checked as
    before, so the near-duplicate bracket is still listed."""
    import feederkit.mix.strongpairs as strongpairs

    monkeypatch.setattr(strongpairs, "ALONE_SETS", 1)
    args = ("catalog", "analyze", "--tolerance", "0.5", "--rotation-error", "1", "--json")
    rc, out, _ = run(capsys, *args, "--catalog", db)
    data = json.loads(out)
    assert data["counts"]["undecided_alone"] >= 1
    assert data["no_strong_plan_alone"] == []
    found = {(w["part_a"], w["part_b"]) for w in data["apart_only_on_the_ideal_model"]}
    assert ("l-bracket/up", "l-bracket-near/up") in found


def test_reading_pairs_under_rotation_error_span_the_states_vibration_merges():
    """Under rotation error alone a near-round 64-gon's facets are one physical state a
    breath of vibration carries across, reading anything between their diameters: a
    12-gon whose one diameter falls between two of theirs, further from each than the
    sensor reaches, is never told apart from it. The nominal diameters miss that pair; the
    physical states' intervals find it."""
    import math
    import random

    from feederkit.mechanics.push import push_function
    from feederkit.mechanics.uncertain import uncertain_mechanics
    from feederkit.mix.strongpairs import check_strong_pair, reading_pairs
    from feederkit.outline import make_outline
    from feederkit.part import make_part
    from feederkit.sensors import ToleranceSensor
    from feederkit.uncertainty import Uncertainty

    rng = random.Random(0)
    ring = []
    for k in range(64):
        a, f = 2 * math.pi * k / 64, 13.0 * (1 + rng.uniform(-0.001, 0.001))
        ring.append((f * math.cos(a), f * math.sin(a)))
    round_ = push_function(make_part(make_outline("round", ring)))
    rotation = Uncertainty(1.0)
    assert uncertain_mechanics(round_.part, rotation).n < round_.n  # facets merged
    ds = sorted(s.diameter for s in round_.states)
    gap, mid = max((b - a, (a + b) / 2.0) for a, b in zip(ds, ds[1:], strict=False))
    sensor = ToleranceSensor(0.0004)
    assert gap / 2.0 > 2.0 * 0.0004  # no nominal diameter of the round part reads as mid
    r = mid / 2.0 / math.cos(math.pi / 12)
    ring12 = [(r * math.cos(k * math.pi / 6), r * math.sin(k * math.pi / 6)) for k in range(12)]
    dodecagon = push_function(make_part(make_outline("dodecagon", ring12)))
    pfs = [round_, dodecagon]
    assert reading_pairs(pfs, sensor) == set()
    assert reading_pairs(pfs, sensor, rotation) == {(0, 1)}
    # A pair the screen must not miss: no strong plan tells the two apart.
    assert check_strong_pair(round_, dodecagon, sensor, rotation).witness is not None
