"""What a plan says about parts it cannot tell apart: runs, simulation, the pair words, the
report's section and the rotation-error hint (a new user's review of product mixes)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from shared import run_cli

from feederkit.plans.execute import execute
from feederkit.plans.model import Leaf, ResultEntry, names_several
from feederkit.plans.readplan import read_plan
from feederkit.plans.verify import verify_declared
from feederkit.reports.sections import simulation_text

TRI = [[0, 0], [1, 0], [0, 1]]


def _outline(tmp_path: Path, name: str, vertices: list[list[float]]) -> str:
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps({"name": name, "vertices": vertices}))
    return str(path)


@pytest.fixture(params=["1", "0"], ids=["strong", "ideal"])
def twin_plan(request, tmp_path: Path, capsys) -> Path:
    """A plan for the triangle and a copy of it under another name: every result lists both."""
    a, b = _outline(tmp_path, "tri", TRI), _outline(tmp_path, "tri-copy", TRI)
    out = tmp_path / "twins.plan.json"
    args = ["plan", a, b, "--tolerance", "0.01", "--rotation-error", request.param]
    code, _, err = run_cli(capsys, *args, "-o", str(out))
    assert code == 1, err  # the pair is reported, the plan written
    return out


def test_a_result_naming_several_members_is_unrecognized_but_one_member_is_not() -> None:
    both = Leaf((ResultEntry("a", 0, 0.0), ResultEntry("b", 0, 0.0)))
    sides = Leaf((ResultEntry("a", 0, 0.0, "up"), ResultEntry("a", 1, 90.0, "down")))
    poses = Leaf((ResultEntry("a", 0, 0.0, "up"), ResultEntry("a", 2, 180.0, "up")))
    rejected = Leaf(both.results, reject=True)
    assert both.unrecognized and sides.unrecognized
    assert not poses.unrecognized and not rejected.unrecognized
    assert names_several([("a", "up"), ("a", "up")]) is False


def test_a_run_ending_unrecognized_names_the_candidates_never_oriented(twin_plan, capsys):
    code, out, _ = run_cli(capsys, "run", str(twin_plan), "--start-deg", "200")
    assert code == 0  # a correct answer by the plan's contract
    lines = [ln for ln in out.splitlines() if "from theta 200 deg" in ln]
    assert len(lines) == 2
    for line in lines:
        assert "oriented" not in line
        assert "ends after" in line and "at a result that lists tri state" in line
        assert "and tri-copy state" in line and "the plan cannot tell them apart" in line
    trace = execute(read_plan(twin_plan), 0, 200.0)
    assert trace.success and trace.unrecognized and trace.to_dict()["unrecognized"] is True


def test_run_all_counts_the_unrecognized_paths(twin_plan, capsys):
    code, out, _ = run_cli(capsys, "run", str(twin_plan), "--all")
    assert code == 0
    report = verify_declared(read_plan(twin_plan))
    assert report.ok and report.unrecognized == report.paths > 0
    assert f"{report.paths} of them unrecognized (a result listing several parts" in out
    assert "unrecognized" in out.split("verification")[1]  # the table's column
    code, out, _ = run_cli(capsys, "run", str(twin_plan), "--all", "--json")
    data = json.loads(out)
    assert data["unrecognized"] == data["paths"]
    assert all(p["unrecognized"] == p["paths"] for p in data["parts"])


def test_a_plan_that_recognizes_every_part_counts_none(tmp_path: Path, capsys):
    out = tmp_path / "tri.plan.json"
    src = _outline(tmp_path, "tri", TRI)
    assert run_cli(capsys, "plan", src, "--tolerance", "0.01", "-o", str(out))[0] == 0
    code, text, _ = run_cli(capsys, "run", str(out), "--all")
    assert code == 0 and "unrecognized" not in text
    assert verify_declared(read_plan(out)).unrecognized == 0
    code, text, _ = run_cli(capsys, "run", str(out), "--start-deg", "200")
    assert "oriented in" in text and "cannot tell" not in text


def test_the_report_counts_unrecognized_successes_apart() -> None:
    text = simulation_text({"trials": 10, "successes": 10, "rejects": 2, "unrecognized": 3})
    assert "5 oriented correctly" in text and "3 unrecognized (a result listing" in text
    alone = simulation_text({"trials": 4, "successes": 4, "unrecognized": 4})
    assert "oriented correctly" not in alone.replace("0 oriented correctly", "")


needs_mujoco = pytest.mark.skipif(
    not __import__("feederkit.sim", fromlist=["mujoco_available"]).mujoco_available(),
    reason="needs MuJoCo (feederkit[sim])",
)


@needs_mujoco
def test_simulate_counts_the_unrecognized_successes(twin_plan, capsys):
    code, out, _ = run_cli(capsys, "simulate", str(twin_plan), "--trials", "3", "--json")
    data = json.loads(out)
    assert data["unrecognized"] == data["successes"] > 0  # every result lists both parts
    assert data["success_rate"] == data["successes"] / data["trials"]
    assert all(t["unrecognized"] is False for t in data["went_wrong"])
    code, out, _ = run_cli(capsys, "simulate", str(twin_plan), "--trials", "3")
    assert f"{data['unrecognized']} unrecognized (a result listing" in " ".join(out.split())


ELL_RING = [(0, 0), (40, 0), (40, 10), (10, 10), (10, 25), (0, 25)]


def test_two_sides_no_plan_tells_apart_are_never_called_oriented(tmp_path: Path, capsys):
    """``plan`` and ``changeover compile`` say it in one wording: the part is recognized,
    not its side, so it is not oriented."""
    src = _outline(tmp_path, "ell", [list(p) for p in ELL_RING])
    blind = ("--sensorless", "--rotation-error", "0")
    code, _, planned = run_cli(capsys, "plan", src, *blind)
    assert code == 1
    db = str(tmp_path / "parts.db")
    assert run_cli(capsys, "catalog", "init", "--catalog", db)[0] == 0
    assert run_cli(capsys, "catalog", "add", src, "--catalog", db)[0] == 0
    code, _, compiled = run_cli(
        capsys, "changeover", "compile", "blind", "--mix", "ell", *blind, "--catalog", db
    )
    assert code == 1
    words = "recognizes ell but not which side is up: ell/up & ell/down ("
    for err in (planned, compiled):
        line = " ".join(err.split())
        assert words in line and "ell is not oriented" in line
        assert "orients" not in line
    tail = planned.split("recognizes ell", 1)[1]
    assert " ".join(tail.split()) == " ".join(compiled.split("recognizes ell", 1)[1].split())


def test_pairs_words_name_pairs_of_parts_and_sides_apart() -> None:
    from feederkit.plans.model import pairs_words

    parts = pairs_words("the plan", [(("a", None), ("b", None), "same")])
    assert parts == (
        "the plan cannot tell these apart: a & b (same); its results list each candidate with "
        "its pose"
    )
    both = pairs_words(
        "the plan",
        [(("a", "up"), ("a", "down"), "w0"), (("a", "up"), ("b", "up"), "w1")],
    )
    # a's side pairs with b too: a is not even recognized, so the words do not say it is
    assert "cannot tell these apart: a/up & b/up (w1)" in both
    assert "cannot tell which side of a is up: a/up & a/down (w0): a is not oriented" in both
    assert "recognizes a" not in both
    mesh = pairs_words("the plan", [(("m", "pose-0"), ("m", "pose-2"), "w")])
    assert "recognizes m but not which pose it lies in: m/pose-0 & m/pose-2 (w)" in mesh


def _section(html: str, ident: str) -> str:
    """The text of the element with ``id=ident`` up to the next section (tags dropped)."""
    import re
    from html import unescape

    start = html.index(f'id="{ident}"')
    end = html.find("<section", start + 1)
    bare = re.sub(r"<[^>]+>", " ", html[start : end if end > 0 else None])
    return " ".join(unescape(bare).split())


def test_report_of_a_plan_file_gives_each_pairs_reason_as_compile_does(tmp_path, capsys):
    """``feederkit report PLAN.json`` decides the pairs as ``changeover report`` does: the
    reason, the full witness, a banner in the words of ``plan``."""
    a, b = _outline(tmp_path, "tri", TRI), _outline(tmp_path, "tri-copy", TRI)
    plan, made = tmp_path / "p.json", tmp_path / "made.html"
    args = ["plan", a, b, "--tolerance", "0.01", "-o", str(plan), "--report", str(made)]
    assert run_cli(capsys, *args)[0] == 1
    page = tmp_path / "page.html"
    assert run_cli(capsys, "report", str(plan), "-o", str(page))[0] == 0
    html, compiled = page.read_text(), made.read_text()
    text = _section(html, "lookalikes")
    assert text == _section(compiled, "lookalikes")
    assert "same push-diameter function (Lemma 8)" in text
    assert "tri s0 ~ tri-copy s0, tri s1 ~ tri-copy s1, tri s2 ~ tri-copy s2" in text
    assert "behave alike under every push-align operation" not in text
    banner = _section(html, "unrecognized")
    assert "this plan cannot tell these apart: tri & tri-copy (same push-diameter" in banner


def test_report_names_a_pair_only_a_strong_plan_lists_together() -> None:
    from feederkit.reports.sections import PairRow

    row = PairRow(("a", None), ("b", None), "plan", listed=["a s0 ~ b s0"])
    plan = read_plan_of_triangle()
    assert row.reason(plan).startswith("told apart on the ideal model, but this plan, strong")
    assert row.states == "listed together: a s0 ~ b s0"
    row.why.append("same push-diameter function")
    assert row.reason(plan) == "same push-diameter function"


def read_plan_of_triangle():
    from feederkit.mechanics.push import push_function
    from feederkit.outline import make_outline
    from feederkit.part import make_part
    from feederkit.plans.make import make_plan
    from feederkit.plans.readplan import plan_from_dict
    from feederkit.sensors import ToleranceSensor

    pf = push_function(make_part(make_outline("tri", TRI)))
    return plan_from_dict(make_plan([pf], ToleranceSensor(0.01)).plan)


def test_the_tree_says_two_sides_of_one_part_are_recognized_not_oriented(tmp_path, capsys):
    src = _outline(tmp_path, "ell", [list(p) for p in ELL_RING])
    page = tmp_path / "ell.html"
    args = ["plan", src, "--sensorless", "--rotation-error", "0", "--report", str(page)]
    assert run_cli(capsys, *args)[0] == 1
    html = page.read_text()
    assert "not oriented: ell recognized, but not which side is up (2 landings)" in html
    assert "not recognized" not in html
    assert "recognizes ell but not which side is up" in _section(html, "unrecognized")
    assert "Two landings of one part: the part is known" in _section(html, "lookalikes")


CATALOG = Path(__file__).resolve().parent.parent / "catalog"


def _lumping_warning(err: str) -> str:
    (line,) = [ln for ln in err.splitlines() if "results list states together" in ln]
    return line


def test_the_lumping_warning_says_no_smaller_rotation_error_helps_when_none_does(
    tmp_path: Path, capsys
):
    """The near-symmetric rectangle's poses stay together at a thousandth of the rotation
    error: the feeder's vibration keeps them, so the warning points to the ideal model and
    never to a smaller --rotation-error."""
    near = tmp_path / "near.json"
    rect = [[0, 0], [5, 0], [5, 2.5], [0, 2.5]]
    near.write_text(json.dumps({"name": "near", "vertices": rect, "com": [2.508, 1.25]}))
    for error in ("1", "0.001"):
        code, _, err = run_cli(
            capsys, "plan", str(near), "--sensorless", "--landings", "up", "--rotation-error", error
        )
        assert code == 0
        line = _lumping_warning(err)
        assert "no smaller rotation error helps: at ±" in line
        assert "the feeder's vibration" in line and "the ideal model (no uncertainty" in line
        assert "--rotation-error" not in line


def test_the_lumping_warning_names_the_shape_tolerance_when_it_keeps_pairs_together(capsys):
    """The chamfered plate at 2 mm with a 0.2 mm shape tolerance: its sides stay together at
    a thousandth of the rotation error but not without the tolerance (at 0.01 mm a plan
    orients both sides): the tolerance is named, not the vibration, nor a rotation error of
    0 as the ideal model (with a shape tolerance declared it is none)."""
    src = str(CATALOG / "chamfered-plate.json")
    for error in ("1", "0"):
        args = ["--tolerance", "2", "--shape-tolerance", "0.2", "--rotation-error", error]
        code, _, err = run_cli(capsys, "plan", src, *args)
        assert code == 1
        line = _lumping_warning(err)
        assert "the declared shape and COM tolerances keep them together" in line
        assert "--shape-tolerance" in line and "vibration" not in line
        assert ("no smaller rotation error helps: at ±0.001 deg" in line) == (error == "1")
    code, _, _ = run_cli(capsys, "plan", src, "--tolerance", "2", "--shape-tolerance", "0.01")
    assert code == 0


def test_the_lumping_warning_points_to_a_smaller_rotation_error_when_it_helps(capsys):
    src = str(CATALOG / "quadrilateral.json")
    args = ["--sensorless", "--landings", "up", "--rotation-error", "30", "--lumping", "any"]
    code, _, err = run_cli(capsys, "plan", src, *args)
    assert code == 0
    line = _lumping_warning(err)
    assert "a smaller rotation error helps: up to ±19 deg a strong plan tells each pair" in line
    assert "--rotation-error" in line and "vibration" not in line


def test_a_flag_is_not_named_for_a_term_the_message_says_does_not_help() -> None:
    from feederkit.cli.common import with_flags

    assert with_flags("no smaller rotation error helps") == "no smaller rotation error helps"
    assert with_flags("no rotation error helps, not even 0").endswith("even 0")
    assert with_flags("a smaller rotation error helps").endswith("(--rotation-error)")
    # A tolerance declared 0 cannot be made smaller: its flag is not offered.
    declared = "no strong plan (rotation error 1 deg, shape tolerance 0 mm, COM tolerance 0 mm)"
    out = with_flags(declared + "; lumping 'any'")
    assert out == f"{declared}; lumping 'any' (--rotation-error, --lumping)"
    loose = "no strong plan (rotation error 1 deg, shape tolerance 0.05 mm, COM tolerance 0 mm)"
    assert with_flags(loose) == f"{loose} (--rotation-error, --shape-tolerance)"
