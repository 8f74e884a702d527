"""Helpers several test files use: a plan file's part entry, and the one-line CLI error check."""

from __future__ import annotations

from feederkit.mechanics.push import push_function
from feederkit.part import Part


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


def one_line_error(capsys, args: list[str], code: int = 2) -> str:
    """Run ``feederkit args``: it exits ``code`` with one line on stderr, no traceback."""
    from feederkit.cli.app import main

    rc = main(args)
    err = capsys.readouterr().err
    assert rc == code, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    return err
