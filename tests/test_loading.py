"""``feederkit.loading.load_parts``: the one load-and-check of the parts to plan for."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from feederkit.catalog import add_file, open_catalog
from feederkit.errors import InputError
from feederkit.loading import load_parts

CATALOG = Path(__file__).resolve().parents[1] / "catalog"
TRI = [[0, 0], [1, 0], [0, 1]]


def outline(tmp_path: Path, name: str, vertices) -> str:
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps({"name": name, "units": "mm", "vertices": vertices}))
    return str(path)


def disk(tmp_path: Path) -> str:
    ring = [[10 * math.cos(math.radians(k)), 10 * math.sin(math.radians(k))] for k in range(360)]
    return outline(tmp_path, "disk", ring)


def test_files_give_push_functions_in_order(tmp_path):
    a = outline(tmp_path, "tri", TRI)
    b = outline(tmp_path, "rect", [[-1, -0.5], [1, -0.5], [1, 0.5], [-1, 0.5]])
    loaded = load_parts([b, a])
    assert loaded.names == ["rect", "tri"]
    assert [pf.n for pf in loaded.push_functions] == [4, 3]
    assert loaded.left_out == ()


def test_a_part_not_orientable_is_refused_or_left_out(tmp_path):
    tri, round_part = outline(tmp_path, "tri", TRI), disk(tmp_path)
    with pytest.raises(InputError, match="not orientable by pushing"):
        load_parts([tri, round_part])
    loaded = load_parts([tri, round_part], leave_out_not_orientable=True)
    assert loaded.names == ["tri"]
    assert len(loaded.left_out) == 1 and "disk" in loaded.left_out[0]


def test_a_part_named_twice_is_refused(tmp_path):
    tri = outline(tmp_path, "tri", TRI)
    with pytest.raises(InputError, match="named twice"):
        load_parts([tri, tri])
    with pytest.raises(InputError, match="no parts"):
        load_parts([])


def test_catalog_names_carry_exact_revisions_files_do_not(tmp_path):
    db = tmp_path / "parts.db"
    open_catalog(db, create=True).close()
    add_file(db, CATALOG / "octagon.json")
    loaded = load_parts(["octagon"], catalog=db)
    assert loaded.revisions == [("octagon", 1)]
    pinned = load_parts(["octagon@1"], catalog=db)
    assert pinned.revisions == [("octagon", 1)]
    with pytest.raises(InputError):
        load_parts(["octagon@7"], catalog=db)
    from_file = load_parts([outline(tmp_path, "tri", TRI)])
    with pytest.raises(InputError, match="not a catalog part"):
        from_file.revisions  # noqa: B018 - the property refuses


def test_fragile_states_are_warned_about():
    # The d-washer's arc facets leave states whose barrier is below the fragile threshold.
    loaded = load_parts([str(CATALOG / "d-washer.json")])
    assert any("fragile states" in w for w in loaded.warnings)
