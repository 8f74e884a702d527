"""Helpers several test files use: a plan file's part entry, the one-line CLI error check, and
the planners' random mix (also benchmarks/dump_plans.py's)."""

from __future__ import annotations

import math
import random

from feederkit.mechanics.push import PushFunction, push_function
from feederkit.outline import make_outline
from feederkit.part import Part, make_part


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


def one_line_error(capsys, args: list[str], code: int = 2) -> str:
    """Run ``feederkit args``: it exits ``code`` with one line on stderr, no traceback."""
    from feederkit.cli.app import main

    rc = main(args)
    err = capsys.readouterr().err
    assert rc == code, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    return err
