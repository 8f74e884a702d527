"""The terminal sessions docs/plans.md prints are what the command prints today.

Each checked block is run in a folder holding the sample catalog, in the page's order (the
``run`` example reads the plan file the first example writes), with the console 120 columns
wide; its lines are compared up to the page's ``...`` or the statistics table (whose width
follows the terminal). The look-alike and edited-plan examples need files the page makes by
hand, so they are not run here (tests/test_plans.py and tests/test_mix_*.py cover them).
"""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest

import feederkit.cli.common as cli_common
from feederkit.cli.app import main

ROOT = Path(__file__).resolve().parents[1]
CHECKED = (
    "feederkit plan catalog/isosceles-right-triangle.json --tolerance 0.01 -o irt.plan.json",
    "feederkit plan catalog/isosceles-right-triangle.json",
    "feederkit run irt.plan.json --start-deg 200",
)


def sessions(text: str) -> dict[str, list[str]]:
    """Each ``$ feederkit ...`` block of a page: its command and the lines it shows."""
    out: dict[str, list[str]] = {}
    lines = text.split("\n")
    for k, line in enumerate(lines):
        if line.startswith("    $ feederkit "):
            shown = []
            for x in lines[k + 1 :]:
                if not x.startswith("    ") or x.strip() == "..." or x.strip() == "statistics":
                    break
                shown.append(x[4:].rstrip())
            out[line[6:]] = shown
    return out


def test_the_checked_sessions_are_on_the_page():
    assert set(CHECKED) <= set(sessions((ROOT / "docs" / "plans.md").read_text("utf-8")))


def test_the_plans_page_prints_what_the_commands_print(tmp_path, monkeypatch, capsys):
    pages = sessions((ROOT / "docs" / "plans.md").read_text("utf-8"))
    (tmp_path / "catalog").symlink_to(ROOT / "catalog")
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)
    monkeypatch.setattr(cli_common.console, "width", 120)
    for command in CHECKED:
        assert main(shlex.split(command)[1:]) == 0, command
        cap = capsys.readouterr()
        got = [x.rstrip() for x in cap.out.split("\n")]
        want = pages[command]
        assert want, command
        assert got[: len(want)] == want, (command, got[: len(want)], want)


@pytest.mark.parametrize("line", ["    $ feederkit a\n    one\n    ...\n    two", ""])
def test_a_session_stops_at_its_ellipsis(line):
    assert sessions(line) == ({"feederkit a": ["one"]} if line else {})
