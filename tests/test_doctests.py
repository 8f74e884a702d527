"""The ``>>>`` examples in the package's docstrings run and give what they show.

Every module under ``feederkit`` whose source has an example is collected (the main entry
points have one: ``push_function``, ``plan``, ``distinguishable``), so a new example is
tested without being listed here.
"""

from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "feederkit"


def modules_with_examples() -> list[str]:
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if ">>>" not in path.read_text(encoding="utf-8"):
            continue
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        out.append(".".join(rel.parts).removesuffix(".__init__"))
    return out


def test_the_main_entry_points_have_examples() -> None:
    found = set(modules_with_examples())
    assert {"feederkit.mechanics.push", "feederkit.planning.api", "feederkit.mix.pairs"} <= found


@pytest.mark.parametrize("name", modules_with_examples())
def test_examples(name: str) -> None:
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, verbose=False)
    assert result.attempted > 0, f"{name} has '>>>' but no example ran"
    assert result.failed == 0
