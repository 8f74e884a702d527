"""``changeover compile`` over every landing by default (design.md, "Landings";
docs/changeovers.md, docs/landings.md): parts and pairs named ``PART/LANDING``, the sides of a
chiral part no plan tells apart reported like an indistinguishable pair (exit 1, the rule
``plan`` follows), ``--landings up`` as the plan of the parts face up, reject results for the
landings not accepted, and changeovers stored before landings still shown, exported and
reported as they were."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from shared import made_as_drawn, one_line_error

import feederkit.catalog as cat
from feederkit.cli.app import main
from feederkit.loading import load_parts
from feederkit.mix.changeover import (
    accepted_lumps,
    compile_changeover,
    load_changeover,
    plan_mix,
    rejected_members,
    reported_pairs,
)
from feederkit.mix.pairs import PairWitness
from feederkit.outline import make_outline
from feederkit.plans.fileformat import plan_json
from feederkit.plans.readplan import plan_from_dict
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import IDEAL

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
ELL_RING = [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)]
ELL_HOLE = [(30, 3), (34, 3), (34, 7), (30, 7)]
BAR = [(0, 0), (30, 0), (30, 10), (0, 10)]


@pytest.fixture()
def db(tmp_path) -> Path:
    """A catalog with a chiral L (unequal legs, an off-centre hole) and a symmetric bar."""
    path = tmp_path / "parts.db"
    cat.add_outline(path, make_outline("ell", ELL_RING, [ELL_HOLE]))
    cat.add_outline(path, make_outline("bar", BAR))
    return path


def cli(capsys, args: list[str], code: int = 0):
    rc = main(args)
    captured = capsys.readouterr()
    assert rc == code, captured.err
    return captured


def words(text: str) -> str:
    """Terminal output with its line wrapping undone."""
    return " ".join(text.split())


def entries(plan: dict) -> list[tuple[bool, set[tuple[str, str | None]]]]:
    """Each result leaf: whether it rejects, and the (part, landing) pairs it lists."""
    return [
        (leaf.reject, {(e.part, e.landing) for e in leaf.results})
        for leaf in plan_from_dict(plan).leaves()
    ]


def test_compile_covers_both_sides_of_a_chiral_part_by_default(db, tmp_path, capsys):
    out = tmp_path / "line.json"
    args = ["changeover", "compile", "line", "--mix", "ell,bar", "--tolerance", "0.5"]
    args += ["--rotation-error", "0"]
    cap = cli(capsys, [*args, "-o", str(out), "--json", "--catalog", str(db)])
    shown = json.loads(cap.out)
    plan = json.loads(out.read_text())
    assert [(p["name"], p["landing"]) for p in plan["parts"]] == [
        ("ell", "up"),
        ("ell", "down"),
        ("bar", "up"),
    ]
    assert [(r["part"], r["landing"], r["accept"]) for r in shown["landings"]] == [
        ("ell", "up", True),
        ("ell", "down", True),
        ("bar", "up", True),
    ]
    assert [r["share"] for r in shown["landings"]] == pytest.approx([0.25, 0.25, 0.5])
    assert [p["share"] for p in shown["parts"]] == pytest.approx([0.5, 0.5])
    assert shown["unrecognizable_pairs"] == []
    seen = set()
    for reject, listed in entries(plan):
        assert not reject and len(listed) == 1  # every result names its part and side
        seen |= listed
    assert seen == {("ell", "up"), ("ell", "down"), ("bar", "up")}
    assert "down" in cli(capsys, ["run", str(out), "--all"]).out
    # The stored changeover is rebuilt from the landings: show, export and report agree.
    stored = load_changeover(db, "line")
    assert [pf.part.name for pf in stored.parts] == ["ell/up", "ell/down", "bar/up"]
    assert stored.plan == plan and stored.witnesses() == []
    exported = tmp_path / "exported.json"
    cli(capsys, ["changeover", "export", "line", "-o", str(exported), "--catalog", str(db)])
    assert exported.read_bytes() == out.read_bytes()
    text = cli(capsys, ["changeover", "show", "line", "--catalog", str(db)]).out
    assert "ell/down 25 %, bar/up 50 %; every landing accepted" in words(text)


def test_landings_up_is_the_plan_of_the_parts_face_up(db):
    up = compile_changeover(
        db, "up", ["ell", "bar"], ToleranceSensor(0.5), uncertainty=IDEAL, landings=("up",)
    )
    assert [pf.part.name for pf in up.parts] == ["ell/up", "bar/up"]
    # Before landings, compile planned the stored outlines: the same tree and figures.
    loaded = load_parts(["ell", "bar"], catalog=db)
    old, _ = plan_mix(list(loaded.push_functions), ToleranceSensor(0.5), uncertainty=IDEAL)
    assert up.plan["root"] == old.plan["root"]  # its entries name "up", as the old ones do
    for key in ("length", "expected_length", "min_margin_deg", "lower_bound"):
        assert up.plan["stats"][key] == pytest.approx(old.plan["stats"][key], rel=1e-12)
    assert [(p["name"], p["landing"]) for p in up.plan["parts"]] == [("ell", "up"), ("bar", "up")]
    assert {k: v for k, v in up.plan["parts"][0].items() if k not in ("landing", "share")} == (
        old.plan["parts"][0]
    )


def test_mirror_symmetric_parts_plan_exactly_as_before(db):
    bar = compile_changeover(db, "bar", ["bar"], ToleranceSensor(0.5))
    loaded = load_parts(["bar"], catalog=db)
    old, _ = plan_mix(list(loaded.push_functions), ToleranceSensor(0.5))
    assert plan_json(bar.plan) == plan_json(old.plan)
    assert made_as_drawn(plan_json(bar.plan))


def test_sides_no_plan_tells_apart_exit_1_named_part_slash_landing(db, tmp_path, capsys):
    out = tmp_path / "blind.json"
    args = ["changeover", "compile", "blind", "--mix", "ell", "--sensorless"]
    cap = cli(capsys, [*args, "--rotation-error", "0", "-o", str(out), "--catalog", str(db)], 1)
    assert "recognizes ell but not which side is up: ell/up & ell/down" in cap.err
    assert "ell is not oriented" in cap.err and "orients" not in cap.err
    assert "ell/up" in cap.out and "ell/down" in cap.out  # the pairs table
    # The plan is still written and stored; a result lists both sides, each with its pose.
    plan = json.loads(out.read_text())
    assert any(listed == {("ell", "up"), ("ell", "down")} for _, listed in entries(plan))
    assert accepted_lumps(plan) == [("ell/up", "ell/down")]
    stored = load_changeover(db, "blind")
    assert [(w.part_a, w.part_b) for w in stored.witnesses()] == [("ell/up", "ell/down")]


def test_accept_ends_the_other_side_in_reject_results(db, tmp_path, capsys):
    out = tmp_path / "up.json"
    args = ["changeover", "compile", "up", "--mix", "ell,bar", "--tolerance", "0.5"]
    args += ["--rotation-error", "0"]
    cap = cli(capsys, [*args, "--accept", "up", "-o", str(out), "--catalog", str(db)])
    assert "ell/down 25 % rejected" in words(cap.out)
    assert "1 rejected (25 % of the parts end in a reject result" in words(cap.out)
    plan = json.loads(out.read_text())
    for reject, listed in entries(plan):
        assert reject == (listed == {("ell", "down")})
    assert rejected_members(plan) == {"ell/down"}
    assert "reject" in cli(capsys, ["run", str(out), "--all"]).out
    shown = json.loads(
        cli(capsys, ["changeover", "show", "up", "--json", "--catalog", str(db)]).out
    )
    assert [r["accept"] for r in shown["landings"]] == [True, False, True]


def test_accepting_a_side_no_plan_tells_from_the_other_is_one_line_exit_1(db, capsys):
    args = ["changeover", "compile", "x", "--mix", "ell", "--sensorless", "--rotation-error", "0"]
    err = one_line_error(capsys, [*args, "--accept", "up", "--catalog", str(db)], code=1)
    assert "ell (up) is accepted and ell (down) rejected" in err and "--accept" in err
    assert cat.list_changeovers(db) == []


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--landings", "pose-7"], "ell has no landing pose-7"),
        (["--landings", "pose-7"], "name the ones the next station takes with --accept"),
        (["--landings", "down"], "bar has no landing down (it is the same shape as up)"),
        (["--landings", "sideways"], "--landings: invalid landing"),
        (["--accept", "pose-1"], "no landing pose-1 to accept"),
    ],
)
def test_bad_landing_options_are_one_line_and_exit_2(db, capsys, args, words):
    base = ["changeover", "compile", "x", "--mix", "ell,bar", "--tolerance", "0.5"]
    err = one_line_error(capsys, [*base, *args, "--catalog", str(db)])
    assert words in err
    assert cat.list_changeovers(db) == []


def test_two_rejected_landings_need_not_be_told_apart():
    def pair(a, b):
        return PairWitness(a, b, (0,), (0,), "alike", "test")

    pairs = [pair("a/up", "b/up"), pair("a/down", "b/down"), pair("a/up", "a/down")]
    kept = reported_pairs(pairs, {"a/down", "b/down"})
    assert [(w.part_a, w.part_b) for w in kept] == [("a/up", "b/up"), ("a/up", "a/down")]
    assert reported_pairs(pairs) == pairs


def test_a_lookalike_on_either_side_with_the_down_sides_rejected(tmp_path):
    # The quadrilateral and its push-diameter look-alike: no plan tells them apart on either
    # side; with only "up" accepted the down pair ends in a reject result and is no pair.
    from feederkit.mix.lookalike import build_lookalike
    from feederkit.sources import load_part

    db = tmp_path / "twins.db"
    quad = load_part(str(CATALOG / "quadrilateral.json"))
    cat.add_outline(db, quad.outline, name="quad")
    cat.add_outline(db, build_lookalike(quad, "push-diameter", 0).part.outline, name="twin")
    sensor = ToleranceSensor(0.03)
    every = compile_changeover(db, "all", ["quad", "twin"], sensor, uncertainty=IDEAL)
    assert [(w.part_a, w.part_b) for w in every.witnesses] == [
        ("quad/up", "twin/up"),
        ("quad/down", "twin/down"),
    ]
    assert every.lumped == [("quad/up", "twin/up"), ("quad/down", "twin/down")]
    up = compile_changeover(db, "up", ["quad", "twin"], sensor, uncertainty=IDEAL, accept={"up"})
    assert [(w.part_a, w.part_b) for w in up.witnesses] == [("quad/up", "twin/up")]
    assert up.lumped == [("quad/up", "twin/up")]
    assert up.rejected == {"quad/down", "twin/down"}
    assert any(r and s == {("quad", "down"), ("twin", "down")} for r, s in entries(up.plan))
    stored = load_changeover(db, "up")
    assert stored.rejected == up.rejected
    assert [(w.part_a, w.part_b) for w in stored.witnesses()] == [("quad/up", "twin/up")]


def test_a_changeover_stored_before_landings_still_shows_exports_and_reports(
    tmp_path, capsys, monkeypatch
):
    # What compile stored before landings: the plan of the parts' stored outlines.
    folder = tmp_path / "parts"
    folder.mkdir()
    for name in ("quadrilateral", "rectangle-2x1"):
        shutil.copy(CATALOG / f"{name}.json", folder)
    db = tmp_path / "old.db"
    cli(capsys, ["catalog", "init", "--catalog", str(db)])
    cli(capsys, ["catalog", "import", str(folder), "--catalog", str(db)])
    loaded = load_parts(["quadrilateral", "rectangle-2x1"], catalog=db)
    old, _ = plan_mix(list(loaded.push_functions), ToleranceSensor(0.03), uncertainty=IDEAL)
    text = plan_json(old.plan)
    assert made_as_drawn(text)
    cat.save_changeover(db, "old", loaded.revisions, ToleranceSensor(0.03).to_dict(), text)

    shown = json.loads(
        cli(capsys, ["changeover", "show", "old", "--json", "--catalog", str(db)]).out
    )
    assert shown["plan"] == old.plan and shown["landings"] == []
    assert [p["share"] for p in shown["parts"]] == pytest.approx([0.5, 0.5])
    out = cli(capsys, ["changeover", "show", "old", "--catalog", str(db)]).out
    assert "quadrilateral@1 (50 %)" in out and "landings (share)" not in out
    exported = tmp_path / "old.json"
    cli(capsys, ["changeover", "export", "old", "-o", str(exported), "--catalog", str(db)])
    assert exported.read_text() == text
    cli(capsys, ["run", str(exported), "--all"])
    listed = json.loads(cli(capsys, ["changeover", "list", "--json", "--catalog", str(db)]).out)
    assert [c["name"] for c in listed] == ["old"]

    import feederkit.reports

    def fake_report(plan, *, unrecognizable, outlines, **_other):
        return f"<p>{len(unrecognizable)} {sorted(outlines)}</p>"

    monkeypatch.setattr(feederkit.reports, "render_report", fake_report)
    html = tmp_path / "old.html"
    cli(capsys, ["changeover", "report", "old", "-o", str(html), "--catalog", str(db)])
    assert html.read_text() == "<p>0 ['quadrilateral', 'rectangle-2x1']</p>"


def test_a_no_sensor_accept_list_of_every_landing_changes_nothing_but_the_keys(db):
    # Accepting every landing by name is the default: no reject result, the same plan.
    every = compile_changeover(db, "a", ["ell"], NoSensor(), uncertainty=IDEAL)
    named = compile_changeover(
        db, "b", ["ell"], NoSensor(), uncertainty=IDEAL, accept={"up", "down"}
    )
    assert named.plan == every.plan and named.rejected == frozenset()
    assert every.witnesses and every.lumped == [("ell/up", "ell/down")]


def test_plan_and_changeover_compile_follow_one_rule(db):
    # feederkit plan's library path and compile's give the same plan and the same pairs.
    from feederkit.landing.plan import plan_landings

    landings = cat.get_revision(db, "ell", None).landings
    planned = plan_landings(landings, NoSensor(), uncertainty=IDEAL)
    compiled = compile_changeover(db, "ell", ["ell"], NoSensor(), uncertainty=IDEAL)
    assert compiled.plan == planned.made.plan
    assert [(p.a.label, p.b.label) for p in planned.indistinguishable] == [
        (w.part_a, w.part_b) for w in compiled.witnesses
    ]
    assert planned.lumped == compiled.lumped == [("ell/up", "ell/down")]
