"""The plan file's text (``plan_json``) against a plain recursive writer of the same layout:
indented JSON, two spaces a level, a list of plain values and an object of up to four plain
values (or none) on one line, written as ``json.dumps`` writes them, no NaN or infinity."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from feederkit.plans import plan_json, read_plan

GOLDEN = Path(__file__).resolve().parent / "golden"


def _flat(value: object) -> str | None:
    if isinstance(value, dict):
        plain = all(not isinstance(v, dict | list) for v in value.values())
        return (
            json.dumps(value, allow_nan=False) if (plain and len(value) <= 4) or not value else None
        )
    if isinstance(value, list | tuple):
        plain = all(not isinstance(v, dict | list | tuple) for v in value)
        return json.dumps(value, allow_nan=False) if plain else None
    return json.dumps(value, allow_nan=False)


def reference(value: object, indent: int = 0) -> str:
    """The layout written out by recursion (a plan's depth is small here)."""
    flat = _flat(value)
    if flat is not None:
        return flat
    pad, end = "  " * (indent + 1), "\n" + "  " * indent
    if isinstance(value, dict):
        items = [f"{pad}{json.dumps(k)}: {reference(v, indent + 1)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + end + "}"
    assert isinstance(value, list | tuple)
    return "[\n" + ",\n".join(pad + reference(v, indent + 1) for v in value) + end + "]"


scalars = (
    st.none()
    | st.booleans()
    | st.integers(-(10**20), 10**20)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=6)
)
values = st.recursive(
    scalars,
    lambda inner: (
        st.lists(inner, max_size=6)
        | st.lists(inner, max_size=4).map(tuple)
        | st.dictionaries(st.text(max_size=4), inner, max_size=6)
    ),
    max_leaves=40,
)


@settings(max_examples=300, deadline=None)
@given(values)
def test_any_json_value_is_written_as_the_plain_writer_writes_it(value):
    assert plan_json(value) == reference(value) + "\n"
    assert json.loads(plan_json(value)) == json.loads(json.dumps(value))


@pytest.mark.parametrize("path", sorted(GOLDEN.glob("*.json")), ids=lambda p: p.name)
def test_plan_files_are_written_as_the_plain_writer_writes_them(path):
    # Every golden file was written by the writer of the time: the same bytes again.
    text = path.read_text(encoding="utf-8")
    data = json.loads(text)
    assert plan_json(data) == reference(data) + "\n" == text
    if data.get("format") == "feederkit-plan":
        plan = read_plan(path)
        assert plan_json(plan) == reference(json.loads(plan_json(plan))) + "\n"


def test_a_value_that_refers_to_itself_is_a_value_error():
    d: dict = {}
    d["a"] = (d,)
    with pytest.raises(ValueError, match="Circular reference"):
        plan_json(d)
    assert plan_json({"a": [1.5]}) == '{\n  "a": [1.5]\n}\n'  # the next value is not marked


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("where", ["alone", "in a list", "in a result", "in a step", "deep"])
def test_a_nan_or_an_infinity_is_json_s_own_value_error_wherever_it_is(bad, where):
    value = {
        "alone": bad,
        "in a list": [1.0, bad],
        "in a result": {"part": "a", "state": 0, "pose_deg": bad},
        "in a step": {"action_deg": bad, "margin_deg": 1.0, "branches": [{"next": {}}]},
        "deep": {"branches": [{"reading": [1.0, 2.0], "next": {"x": [bad], "y": [[1]]}}]},
    }[where]
    with pytest.raises(ValueError) as caught:
        json.dumps(value, allow_nan=False)
    with pytest.raises(ValueError) as ours:
        plan_json(value)
    assert str(ours.value) == str(caught.value)
