"""A mesh carries no units: read as mm, its import says the size it then has and, when that is
small, what inches would give (the angle block sample, 1.35 x 1 x 1.34 units; its resting
outline's hull diameter, the size the plan uses: 1.94 mm as mm, 49 mm in inches), so a part
modelled in inches is not planned 25.4 times too small silently."""

from __future__ import annotations

from pathlib import Path

import pytest
from shared import run_cli

SAMPLES = Path(__file__).resolve().parents[1].parent / "shared" / "samples"
BLOCK = SAMPLES / "trimesh__angle_block.STL"


@pytest.mark.skipif(not BLOCK.is_file(), reason="needs ../shared/samples")
def test_a_small_unitless_mesh_names_its_size_in_inches(capsys):
    rc, _, err = run_cli(capsys, "part", "analyze", str(BLOCK))
    assert rc == 0
    line = " ".join(err.split())
    assert "the file carries no units: read as mm, the part is 1.937 mm across" in line
    assert "in inches it would be 49.19 mm: use --units in if so" in line
    rc, _, err = run_cli(capsys, "part", "analyze", str(BLOCK), "--units", "in")
    assert rc == 0 and "carries no units" not in err


def test_a_tiny_unitless_mesh_says_it_carries_no_units(tmp_path, capsys):
    import trimesh

    path = tmp_path / "tiny.stl"
    trimesh.creation.box((0.5, 0.4, 0.3)).export(path)
    rc, _, err = run_cli(capsys, "part", "analyze", str(path))
    line = " ".join(err.split())
    assert rc == 0 and "read in mm as the file carries no units" in line
    assert (
        "from the file" not in line and "16.26 mm in in" in line
    )  # its 0.5 x 0.4 mm face: 0.64 mm across
