"""The lumping warning's rotation-error hint names the largest rotation error at which a strong
plan tells the lumped pairs apart (a figure a robot must keep), not a thousandth of the
declared one, and says so plainly when only one finer than a robot turns would do
(``plans.advice.smaller_error_words``)."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
from shared import run_cli

from feederkit.cli.common import with_flags
from feederkit.machine import PushAlignMachine
from feederkit.machine.build import build_machine
from feederkit.mechanics import push_function
from feederkit.outline import load_outline_json
from feederkit.part import make_part
from feederkit.planning.lumping import unresolvable_pairs
from feederkit.planning.problem import Problem
from feederkit.plans import advice
from feederkit.plans.advice import largest_helping_error, smaller_error_words
from feederkit.sensors import NoSensor
from feederkit.uncertainty import Uncertainty

CATALOG = Path(__file__).resolve().parent.parent / "catalog"
QUAD = str(CATALOG / "quadrilateral.json")
SENSORLESS_ANY = ("--sensorless", "--landings", "up", "--lumping", "any")


def _hint(err: str) -> str:
    (line,) = [ln for ln in err.splitlines() if "results list states together" in ln]
    return line[line.index("; a smaller rotation error") :]


def test_the_hint_names_the_largest_rotation_error_that_tells_the_pairs_apart(capsys):
    """The sensorless quadrilateral at ±30 deg lumps all its states; ±19 deg has a strong plan
    that tells them apart and ±20 deg none (the hint once said ±0.03 deg, a thousandth)."""
    code, _, err = run_cli(capsys, "plan", QUAD, *SENSORLESS_ANY, "--rotation-error", "30")
    assert code == 0
    hint = _hint(err)
    assert hint.startswith(
        "; a smaller rotation error helps: up to ±19 deg a strong plan tells each pair apart"
    )
    assert "--rotation-error" in hint and "0.03" not in hint
    code, _, err = run_cli(capsys, "plan", QUAD, *SENSORLESS_ANY, "--rotation-error", "19")
    assert code == 0 and "results list states together" not in err
    code, _, err = run_cli(capsys, "plan", QUAD, *SENSORLESS_ANY, "--rotation-error", "20")
    assert code == 1 or "results list states together" in err


def test_the_hint_names_the_largest_error_for_the_pairs_it_helps(tmp_path: Path, capsys):
    """In a mix of the quadrilateral and a rectangle whose COM sits 0.02 mm off centre, a
    smaller rotation error helps the quadrilateral's pairs (up to ±16 deg) but not the
    rectangle's (the vibration keeps them)."""
    rect = tmp_path / "rect.json"
    vertices = [[0, 0], [5, 0], [5, 2.5], [0, 2.5]]
    rect.write_text(json.dumps({"name": "rect", "vertices": vertices, "com": [2.52, 1.25]}))
    args = ("--landings", "up", "--lumping", "any", "--rotation-error", "30")
    code, _, err = run_cli(capsys, "plan", QUAD, str(rect), *args)
    hint = _hint(err)
    assert hint.startswith(
        "; a smaller rotation error helps 10 pairs only (up to ±16 deg a strong plan tells them "
        "apart): at ±0.03 deg 2 of the 12 are still not told apart: the feeder's vibration"
    )


def test_a_rotation_error_finer_than_a_robot_turns_is_named_as_out_of_reach(
    capsys, monkeypatch: pytest.MonkeyPatch
):
    """With the practical floor above ±19 deg, the quadrilateral's pairs are told apart only
    below it: the words say so, and name no --rotation-error to try."""
    monkeypatch.setattr(advice, "PRACTICAL_ROTATION_ERROR_DEG", 25.0)
    code, _, err = run_cli(capsys, "plan", QUAD, *SENSORLESS_ANY, "--rotation-error", "30")
    assert code == 0
    hint = _hint(err)
    assert hint.startswith(
        "; a smaller rotation error helps only below ±25 deg, finer than a robot turns: at "
        "±0.03 deg a strong plan tells each pair apart"
    )
    assert "--rotation-error" not in hint


def test_a_flag_is_not_named_for_a_rotation_error_finer_than_a_robot_turns() -> None:
    words = "a smaller rotation error helps only below ±0.01 deg, finer than a robot turns"
    assert with_flags(words) == words
    helps = "a smaller rotation error helps: up to ±19 deg"
    assert with_flags(helps) == f"{helps} (--rotation-error)"


@pytest.mark.parametrize(
    ("threshold", "expected", "practical"),
    [(0.37, 0.37, True), (7.3, 7.3, True), (0.01, 0.01, True), (0.004, 0.001, False)],
)
def test_the_search_finds_the_largest_two_digit_error_or_says_none_is_practical(
    threshold: float, expected: float, practical: bool
) -> None:
    """A predicate that holds up to ``threshold`` (monotone, as telling apart is): the search
    answers the largest figure of two digits at or below it, or, below the practical floor,
    that none a robot keeps would do, in a few looks."""
    looks: list[float] = []

    def helps(deg: float) -> bool:
        looks.append(deg)
        return deg <= threshold

    found = largest_helping_error(helps, 0.001, 1.0 if threshold < 1.0 else 30.0)
    assert found.deg == pytest.approx(expected) and found.practical is practical
    assert found.decided and len(looks) <= 12


def test_the_search_keeps_what_it_proved_when_time_runs_out() -> None:
    answers = iter([True, True, None])
    found = largest_helping_error(lambda _deg: next(answers), 0.001, 1.0)
    assert not found.decided and found.practical and 0.01 < found.deg < 1.0


def _quadrilateral_at(u: Uncertainty) -> PushAlignMachine:
    pf = push_function(make_part(load_outline_json(QUAD)))
    return build_machine([pf], NoSensor(), u)


def test_the_words_keep_their_time_bound_and_say_what_was_not_decided() -> None:
    """Each machine build takes 0.3 s here: within 1 s the thousandth and a few figures are
    looked at, then the words say a larger rotation error was not decided; the time bound
    holds (give or take the one build under way)."""
    declared = Uncertainty(30.0)
    machine = _quadrilateral_at(declared)
    pairs = unresolvable_pairs(Problem(machine, "exact", 0.0))
    assert pairs

    def slow(u: Uncertainty) -> PushAlignMachine:
        time.sleep(0.3)
        return _quadrilateral_at(u)

    started = time.monotonic()
    words = smaller_error_words(slow, declared, machine, pairs, 1.0)
    assert time.monotonic() - started < 1.0 + 0.3 + 0.5
    assert words.startswith("; a smaller rotation error helps: at ±")
    assert words.endswith(
        "a strong plan tells each pair apart (whether a larger rotation error does was not "
        "decided in time)"
    )
    assert "not decided: they may or may not" in smaller_error_words(
        slow, declared, machine, pairs, 0.0
    )
