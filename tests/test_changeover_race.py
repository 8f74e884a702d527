"""A changeover is stored against the revisions its plan was made from (docs/changeovers.md):
a revision removed and added again under its number while the plan is made is refused at
store time, not stored against a plan made for other contents (a review raced ``changeover
compile`` against ``catalog remove`` and ``catalog add --revise``)."""

from __future__ import annotations

from pathlib import Path

import pytest

import feederkit.catalog as cat
from feederkit.errors import InputError
from feederkit.mix.changeover import compile_changeover
from feederkit.outline import make_outline
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL

QUAD = [(0.0, 0.0), (3.0, 0.0), (2.5, 2.0), (0.5, 1.6)]
QUAD_NEW = [(0.0, 0.0), (3.0, 0.0), (2.0, 2.3), (0.5, 1.6)]
BAR = [(0.0, 0.0), (3.0, 0.0), (3.0, 1.0), (0.0, 1.0)]


@pytest.fixture()
def db(tmp_path) -> Path:
    path = tmp_path / "parts.db"
    cat.add_outline(path, make_outline("quad", QUAD))
    cat.add_outline(path, make_outline("bar", BAR))
    return path


def test_a_revision_replaced_while_the_plan_is_made_is_not_stored(db, tmp_path):
    def replace_quad(_made) -> None:  # another process, while this one plans
        cat.remove_part(db, "quad", revision=1)
        cat.add_outline(db, make_outline("quad", QUAD_NEW))

    with pytest.raises(InputError, match=r"quad@1 replaced in the catalog while the plan"):
        compile_changeover(
            db, "line", ["quad", "bar"], ToleranceSensor(0.1), uncertainty=IDEAL,
            prepare=replace_quad,
        )  # fmt: skip
    assert cat.list_changeovers(db) == []


def test_an_unchanged_catalog_stores_the_changeover(db):
    compiled = compile_changeover(
        db, "line", ["quad", "bar"], ToleranceSensor(0.1), uncertainty=IDEAL
    )
    assert [c.name for c in cat.list_changeovers(db)] == ["line"]
    assert compiled.revisions == (("quad", 1), ("bar", 1))
