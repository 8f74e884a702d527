"""The report of a plan whose result names a resting state made of several stable states
(the d-washer's arc facets, shallow wells a breath of vibration crosses: one physical state
over 28 degrees) says what ``plan`` says, "oriented only that far", and not that no plan
can tell the poses apart and the part is not oriented (the README's own changeover report
said so of the d-washer)."""

from __future__ import annotations

from pathlib import Path

import pytest

from feederkit.cli.app import main

CATALOG = Path(__file__).resolve().parents[1] / "catalog"


@pytest.fixture(scope="module")
def page(tmp_path_factory) -> str:
    folder = tmp_path_factory.mktemp("dw")
    plan, html = folder / "dw.json", folder / "dw.html"
    args = ["plan", str(CATALOG / "d-washer.json"), "--tolerance", "0.3"]
    assert main([*args, "-o", str(plan), "--report", str(html)]) == 0
    return " ".join(html.read_text().split())


def test_the_banner_says_oriented_only_that_far(page):
    assert 'id="spread">Warning: some results name a resting state made of several' in page
    assert "d-washer states 1, 2, 3, 4, 5, 6, 7, 8 over 28 degrees" in page
    assert 'id="unoriented"' not in page


def test_the_tree_and_the_lookalike_section_say_it_too(page):
    assert "resting anywhere over 8 poses (one resting state" in page
    assert 'id="merged-poses"' in page
    assert 'id="unoriented-poses"' not in page


def test_an_ideal_plan_lists_the_facets_as_poses_no_plan_tells_apart(tmp_path):
    """On the ideal model nothing merges: the facets are states of their own."""
    plan, html = tmp_path / "dw0.json", tmp_path / "dw0.html"
    args = ["plan", str(CATALOG / "d-washer.json"), "--tolerance", "0.3", "--rotation-error"]
    assert main([*args, "0", "-o", str(plan), "--report", str(html)]) in (0, 1)
    text = html.read_text()
    assert 'id="spread"' not in text and 'id="merged-poses"' not in text
