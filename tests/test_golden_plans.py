"""Refactoring changes no output: the plans made today for the sample catalog, field for field.

``tests/golden/`` holds the plan files the library wrote for every part of ``catalog/``
(sensorless, and with a tolerance sensor of 1 % of the part's size), one LED array case and
the demo's changeovers; ``tests/golden/make_golden.py`` (run by hand) wrote them. Each case is
regenerated through the library on the ideal model (zero uncertainty, default planning
options) and must give the same file: every key, string, integer and list length equal,
and every float equal to ``FLOAT_REL`` (the last bits of a float differ between machines:
numpy's vectorised trigonometry rounds differently with AVX-512 than without, and a plan
must not). When the files were moved to plan file version 2 they were compared with the
pre-refactor ones: every field but ``version`` and the new ``uncertainty`` and
``stats.certificate`` was unchanged.
"""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import pytest

GOLDEN = Path(__file__).resolve().parent / "golden"


def _generator():
    spec = importlib.util.spec_from_file_location("make_golden", GOLDEN / "make_golden.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


make_golden = _generator()


@pytest.fixture(scope="module")
def generated(tmp_path_factory) -> dict[str, str]:
    """Every golden case's plan file text as the library writes it now."""
    db = make_golden.imported_catalog(tmp_path_factory.mktemp("golden"))
    return {name: make() for name, make in make_golden.cases(db)}


def test_every_golden_file_is_a_case(generated):
    on_disk = {p.name for p in GOLDEN.glob("*.json")}
    assert on_disk == set(generated)
    assert len(on_disk) >= 2 * 10 + 1 + 3  # ten parts twice, one LED case, three changeovers


FLOAT_REL = 1e-9
"""Floats of a regenerated plan file must equal the golden ones to this relative tolerance
(and 1e-9 absolute near zero); the plan's choices themselves must not move."""


def _differences(got: object, want: object, where: str = "") -> list[str]:
    """Where two parsed plan files differ beyond float rounding (empty when they agree)."""
    if isinstance(want, dict) and isinstance(got, dict):
        if got.keys() != want.keys():
            return [f"{where}: keys {sorted(got.keys() ^ want.keys())}"]
        return [d for k in want for d in _differences(got[k], want[k], f"{where}.{k}")]
    if isinstance(want, list) and isinstance(got, list):
        if len(got) != len(want):
            return [f"{where}: {len(got)} items, not {len(want)}"]
        return [
            d
            for i, (g, w) in enumerate(zip(got, want, strict=True))
            for d in _differences(g, w, f"{where}[{i}]")
        ]
    if isinstance(want, float) or isinstance(got, float):
        ok = (
            isinstance(got, int | float)
            and not isinstance(got, bool)
            and math.isclose(got, want, rel_tol=FLOAT_REL, abs_tol=FLOAT_REL)
        )
        return [] if ok else [f"{where}: {got!r}, not {want!r}"]
    return [] if got == want else [f"{where}: {got!r}, not {want!r}"]


def test_differences_see_a_moved_choice_but_not_rounding():
    assert _differences({"a": [1.0, 22.50000000000154]}, {"a": [1.0, 22.500000000001535]}) == []
    assert _differences({"a": 74.9226812537651}, {"a": 285.07731874623494}) == [
        ".a: 74.9226812537651, not 285.07731874623494"
    ]
    assert _differences({"s": 1}, {"s": 8}) == [".s: 1, not 8"]
    assert _differences({"a": [1]}, {"a": [1, 2]}) == [".a: 1 items, not 2"]


@pytest.mark.parametrize("name", sorted(p.name for p in GOLDEN.glob("*.json")))
def test_plan_file_is_unchanged(generated, name):
    want = json.loads((GOLDEN / name).read_text(encoding="utf-8"))
    got = json.loads(generated[name])
    diffs = _differences(got, want)
    assert not diffs, f"{name}: the plan file changed: " + "; ".join(diffs[:5])
