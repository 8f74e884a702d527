"""The report in a real browser: headless Chromium (Debian's ``chromium``) with the network off.

Chromium opens the file in a fresh profile, inside an empty network namespace when
``unshare -rn`` works here, and always with a dead proxy and a resolver that finds nothing.
``--dump-dom`` gives the DOM after parsing, ``--screenshot`` what a laptop screen shows, and
``--print-to-pdf`` the A4 print. Skipped, saying why, only when Chromium is not installed.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from test_report import (
    NASTY,
    count_final_poses,
    count_nodes,
    parse,
    rectangle_plan,
    triangle_plan,
    twin_plan,
)

from feederkit.reports import render_report, write_report

CHROMIUM = next(
    (p for p in map(shutil.which, ("chromium", "chromium-browser")) if p is not None), None
)

pytestmark = pytest.mark.skipif(
    CHROMIUM is None,
    reason="Chromium is not installed; on Debian: apt-get update && apt-get install -y chromium",
)

FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-extensions",
    "--hide-scrollbars",
    "--proxy-server=http://127.0.0.1:9",
    "--host-resolver-rules=MAP * ~NOTFOUND",
)

WINDOW = (1280, 1600)
"""A laptop screen, tall enough to hold the whole plan tree of the test plans."""

PLANS = {"rectangle": rectangle_plan, "triangle": triangle_plan, "twins": twin_plan}


@cache
def no_network_prefix() -> tuple[str, ...]:
    """``unshare -rn`` (a namespace without network) when this machine allows it."""
    unshare = shutil.which("unshare")
    if unshare is None:
        return ()
    ok = subprocess.run([unshare, "-rn", "true"], capture_output=True, timeout=30).returncode == 0
    return (unshare, "-rn") if ok else ()


def chromium(tmp_path: Path, page: Path, *args: str) -> subprocess.CompletedProcess[str]:
    profile = tmp_path / f"profile-{len(list(tmp_path.iterdir()))}"
    profile.mkdir()
    cmd = [
        *no_network_prefix(),
        CHROMIUM,
        *FLAGS,
        f"--user-data-dir={profile}",
        *args,
        page.resolve().as_uri(),
    ]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stderr[-2000:]
    return done


@pytest.fixture(scope="module", params=sorted(PLANS))
def report(request, tmp_path_factory):
    plan = PLANS[request.param]()
    out = tmp_path_factory.mktemp(request.param) / "report.html"
    write_report(out, render_report(plan, seconds_per_op=4.0))
    return plan, out


def test_dom_has_one_tree_node_per_plan_node_and_one_leaf_per_final_pose(report, tmp_path):
    plan, page = report
    dom = parse(chromium(tmp_path, page, "--dump-dom").stdout)
    nodes = dom.with_class("tree-node")
    assert len(nodes) == count_nodes(plan["root"])
    assert len(dom.with_class("result")) == sum(1 for n in nodes if "result" in n["class"])
    assert len(dom.with_class("final-pose")) == count_final_poses(plan["root"])
    tree = [a for _, a in dom.tags if a.get("id") == "plan-tree"]
    assert tree and tree[0]["data-nodes"] == str(count_nodes(plan["root"]))
    # every pose is drawn: an inline SVG per state in the tree and per row of the state tables
    svgs = [a for t, a in dom.tags if t == "svg" and "pose" in a.get("class", "").split()]
    n_states = sum(len(p["stable_states"]) for p in plan["parts"])
    assert len(svgs) == len(dom.with_class("state")) + count_final_poses(plan["root"]) + n_states


def test_part_names_render_as_text_in_the_browser(tmp_path):
    page = tmp_path / "nasty.html"
    write_report(page, render_report(triangle_plan(NASTY)))
    dom = parse(chromium(tmp_path, page, "--dump-dom").stdout)
    assert not [t for t, _ in dom.tags if t in ("b", "script")]
    text = "".join(dom.text)
    assert f"Plan report: {NASTY}" in text
    assert {f["data-part"] for f in dom.with_class("final-pose")} == {NASTY}


LEAF_BACKGROUNDS = ((0xEA, 0xF6, 0xEE), (0xEE, 0xF3, 0xFB), (0xFB, 0xEE, 0xEE))
"""Fill of the tree's leaf boxes (known, up to symmetry, confused): found only in the tree."""

SILHOUETTE = tuple(round(0.85 * c + 0.15 * 255) for c in (0x00, 0x72, 0xB2))
"""The first part's colour at the silhouettes' opacity on white."""


def near(img: np.ndarray, colour: tuple[int, ...], tol: int) -> np.ndarray:
    return (np.abs(img.astype(int) - np.array(colour)) <= tol).all(axis=-1)


def test_screenshot_shows_the_tree(report, tmp_path):
    _, page = report
    shot = tmp_path / "shot.png"
    chromium(tmp_path, page, f"--window-size={WINDOW[0]},{WINDOW[1]}", f"--screenshot={shot}")
    with Image.open(shot) as im:
        rgb = im.convert("RGB")
    colours = rgb.getcolors(maxcolors=1 << 24)
    assert colours is not None and len(colours) > 30, "too few colours: nothing drawn"
    img = np.asarray(rgb)
    assert img.shape[:2] == (WINDOW[1], WINDOW[0])
    assert (img.min(axis=-1) < 235).mean() > 0.03, "the page looks blank"
    leaf = np.zeros(img.shape[:2], dtype=bool)
    for colour in LEAF_BACKGROUNDS:
        leaf |= near(img, colour, 3)
    assert leaf.sum() > 5000, "no leaf boxes of the plan tree painted"
    rows, cols = np.nonzero(leaf)
    tree_area = img[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1]
    assert near(tree_area, SILHOUETTE, 14).sum() > 300, "no final poses drawn in the leaves"


def test_prints_on_a4(report, tmp_path):
    _, page = report
    pdf = tmp_path / "report.pdf"
    chromium(tmp_path, page, "--no-pdf-header-footer", f"--print-to-pdf={pdf}")
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF")
    boxes = {
        tuple(round(float(v)) for v in box.split())
        for box in re.findall(rb"/MediaBox\s*\[([^\]]*)\]", data)
    }
    assert boxes == {(0, 0, 595, 842)}, boxes  # A4 in points
