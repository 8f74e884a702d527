"""Refactoring changes no output: the plans made today for the sample catalog, byte for byte.

``tests/golden/`` holds the plan files the library wrote for every part of ``catalog/``
(sensorless, and with a tolerance sensor of 1 % of the part's size), one LED array case and
the demo's changeovers; ``tests/golden/make_golden.py`` (run by hand) wrote them. Each case is
regenerated through the library on the ideal model (zero uncertainty, default planning
options) and must give the same bytes. When the files were moved to plan file version 2 they
were compared with the pre-refactor ones: every field but ``version`` and the new
``uncertainty`` and ``stats.certificate`` was unchanged.
"""

from __future__ import annotations

import importlib.util
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


@pytest.mark.parametrize("name", sorted(p.name for p in GOLDEN.glob("*.json")))
def test_plan_file_is_byte_identical(generated, name):
    want = (GOLDEN / name).read_text(encoding="utf-8")
    assert generated[name] == want, f"{name}: the plan file changed"
