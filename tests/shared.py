"""Helpers several test files use: a plan file's part entry, the one-line CLI error check, the
command-line tests' clean working folder, the planners' random mix (also
benchmarks/dump_plans.py's) and exhaustive lengths, a catalog's snapshot."""

from __future__ import annotations

import functools
import math
import random
import sqlite3
from collections.abc import Sequence
from pathlib import Path

import pytest

from feederkit.machine import OutcomeRange, PushAlignMachine, is_goal, search_space
from feederkit.mechanics.push import PushFunction, push_function
from feederkit.outline import make_outline
from feederkit.part import Part, make_part
from feederkit.planning.budget import Deadline, Timeout


@pytest.fixture(autouse=True)
def no_stray_profile(tmp_path, monkeypatch):
    """No ./feederkit.toml of the working tree, no catalog from the environment (autouse in
    the command-line test files that import it)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("FEEDERKIT_CATALOG", raising=False)


def small_mix(count: int, seed: int = 100) -> list[PushFunction]:
    """Random convex 6-10-gons on a 60 x 40 mm ellipse."""
    out = []
    for s in range(count):
        rng = random.Random(seed + s)
        n = rng.randint(6, 10)
        angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
        pts = [(30 * math.cos(t), 20 * math.sin(t)) for t in angles]
        out.append(push_function(make_part(make_outline(f"mix-{s}", pts))))
    return out


def plan_part_entry(part: Part, revision: str | None = None) -> dict:
    """The plan file's entry for a part (design.md): name, revision, COM, hull, stable states."""
    return {
        "name": part.name,
        "revision": revision,
        "com": list(part.com),
        "hull": [list(p) for p in part.hull],
        "stable_states": [
            {
                "id": s.id,
                "edge": s.edge,
                "normal_deg": s.normal_deg,
                "resting_range_deg": list(s.resting_range_deg),
                "diameter": s.diameter,
                "pose_deg": s.pose_deg,
            }
            for s in push_function(part).states
        ],
    }


def run_cli(capsys, *args: str) -> tuple[int, str, str]:
    """Run the command line in process: exit code, stdout, stderr."""
    from feederkit.cli.app import main

    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def cli_ok(capsys, args: list[str], code: int = 0):
    """Run ``feederkit args``, which must exit ``code``; the captured output."""
    from feederkit.cli.app import main

    rc = main(args)
    captured = capsys.readouterr()
    assert rc == code, captured.err
    return captured


def one_line_error(capsys, args: list[str], code: int = 2) -> str:
    """Run ``feederkit args``: it exits ``code`` with one line on stderr, no traceback."""
    from feederkit.cli.app import main

    rc = main(args)
    err = capsys.readouterr().err
    assert rc == code, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    return err


def rotation_mids(machine: PushAlignMachine) -> list[float]:
    """One rotation per cell of all the machine's action-range boundaries (the cells' middles,
    deg): what the brute-force models of the tests try, looked up here, not in the library."""
    bounds = sorted({r.lo % 360 for rs in machine.action_maps for r in rs})
    return [(a + b) / 2 for a, b in zip(bounds, bounds[1:] + [bounds[0] + 360], strict=True)]


def outcome_mask(machine: PushAlignMachine, i: int, a: float) -> int:
    """The states (a mask) state ``i`` can settle in after rotating by ``a`` degrees, read
    from its action ranges by the tests' own lookup."""
    for r in machine.action_maps[i]:
        if 0 < (a - r.lo) % 360 < r.hi - r.lo:
            return r.targets if isinstance(r, OutcomeRange) else 1 << r.target
    raise AssertionError("no range holds the rotation")


def read_alike_sets(intervals: dict[int, tuple[float, float]]) -> list[int]:
    """The sets of states (masks, ascending) that can give one reading, from each state's
    open reading interval: between consecutive interval ends the states that can read there
    are fixed, so one probe per gap finds every such set (the tests' own reading model)."""
    ends = sorted({x for iv in intervals.values() for x in iv})
    found = set()
    for a, b in zip(ends, ends[1:], strict=False):
        x = (a + b) / 2.0
        m = sum(1 << i for i, (lo, hi) in intervals.items() if lo < x < hi)
        if m:
            found.add(m)
    return sorted(found)


def brute_lengths(machine: PushAlignMachine, tol: float):
    """The minimum worst-case length of a set under a tolerance sensor of ``tol`` on the
    ideal model (the tests' own search, memoised; None when no plan of at most 6
    operations orients it), and a set's reading branches."""
    insep = search_space(machine).inseparable  # the goal relation, tested on its own
    mids = rotation_mids(machine)
    n = machine.n
    d = [s.sensed for s in machine.states]

    def children(mask: int) -> list[int]:
        # Ideal model: an exact diameter, read strictly within ``tol`` of it.
        iv = {i: (d[i] - tol, d[i] + tol) for i in range(n) if mask >> i & 1}
        return read_alike_sets(iv)

    @functools.cache
    def within(mask: int, k: int) -> bool:
        if is_goal(insep, mask):
            return True
        if k == 0:
            return False
        for a in mids:
            img = 0
            for i in range(n):
                if mask >> i & 1:
                    img |= outcome_mask(machine, i, a)
            if all(within(c, k - 1) for c in children(img)):
                return True
        return False

    def length(mask: int) -> int | None:
        return next((k for k in range(7) if within(mask, k)), None)

    return length, children


def catalog_snapshot(db: Path) -> list[str]:
    """Everything in a catalog file, as SQL text: equal snapshots, nothing written."""
    conn = sqlite3.connect(db)
    try:
        return list(conn.iterdump())
    finally:
        conn.close()


def catalog_with(tmp_path: Path, capsys, names: Sequence[str]) -> str:
    """A fresh catalog file holding the bundled ``catalog/`` parts ``names``, its path."""
    root = Path(__file__).resolve().parents[1] / "catalog"
    path = str(tmp_path / "c.db")
    assert run_cli(capsys, "catalog", "init", "--catalog", path)[0] == 0
    for name in names:
        assert (
            run_cli(capsys, "catalog", "add", str(root / f"{name}.json"), "--catalog", path)[0] == 0
        )
    return path


class PollsLeft(Deadline):
    """A deadline that passes after ``n`` more polls of any kind (``check``, or ``limits``,
    which calls it): where the work stops, not when."""

    def __init__(self, n: int) -> None:
        super().__init__()
        self.left = n

    def check(self) -> None:
        super().check()
        self.left -= 1
        if self.left < 0:
            raise Timeout("time")


def made_as_drawn(text_or_plan) -> bool:
    """Whether a plan file (its text or its object) is one not made over landings, as
    design.md writes it: no part entry names a landing or a share, and every result entry
    names the landing ``up`` (the part as given)."""
    import json

    data = json.loads(text_or_plan) if isinstance(text_or_plan, str) else text_or_plan
    from feederkit.plans.fileformat import result_nodes

    parts_plain = all("landing" not in p and "share" not in p for p in data["parts"])
    entries = [e for node in result_nodes(data) for e in node["result"]]
    return parts_plain and bool(entries) and all(e.get("landing") == "up" for e in entries)
