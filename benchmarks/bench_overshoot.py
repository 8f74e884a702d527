"""Pushes coming down a basin in the physics check: when they go over the far hilltop.

    python benchmarks/bench_overshoot.py                    # the parts below, a few minutes
    python benchmarks/bench_overshoot.py --quick            # fewer starts and frictions
    python benchmarks/bench_overshoot.py PART_OR_FILE[@SIZE] ...   # any SOURCEs, scaled

The default parts: the notched tab (``benchmarks/parts/tab-notch.json``, 10 mm, simulated at
20 mm) and its outline scaled to 30, 40 and 60 mm, the 20 mm 12-gon of
``tests/test_overshoot.py`` (``benchmarks/parts/rnd1-12gon.json``), the catalog and the
wrench, angle block and sliding-base samples (in ``../shared/samples`` when present).

For each part (up to two landings) and each hilltop (divergent orientation) of its push
function, MuJoCo pushes (``feederkit.sim.pushalign.PushAligner``, the model's vibration
breathing on the part) start 0.1, 0.25, 0.5, 1, 1.5, 2, 3, 4 and 6 degrees on either side of
the hilltop (``--quick``: 0.1, 0.5, 1.5, 3, 6), each with ``--frictions`` (4; 2) belt and
fence frictions drawn from the simulator's default ranges (belt 0.4-0.6, fence 0.1-0.3; seed
0), as ``bench_push_bands.py`` does. Each settled push is
filed under the basin it came down: the start's own, or, when it was carried back over its
hilltop (the push band), the neighbour's, come down from the hilltop. A push *went over* when
it settled beyond that basin's state, past the hilltop on the far side of its normal.

Printed per basin (a state and the direction it was come down) that a push went over, or
every basin with ``--all``, the geometry at the simulated size: ``down`` the angle from the
start hilltop to the normal and ``H mm`` the height come down from it (the radius function's
drop), ``over`` the far hilltop's angle past the normal and ``h mm`` its height above the well,
``h/H``; the pushes filed under it, how many ``went`` over, how many of those the model's
outcome sets ``miss`` (``mechanics.outcomes.fence_outcomes`` for the start, rotation error 1
degree), the farthest ``start`` (degrees from its hilltop, 0 when carried back over it) that
went over and the ``most`` hilltops one push went over. The overshoot rules
(``mechanics.uncertain.OVERSHOOT_DEG_MM``, ``OVERSHOOT_BAND_DEG``, docs/uncertainty.md,
"Overshoot") are read from these rows; the model claims no misses (exit 1 when there are).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from feederkit.angles import norm360
from feederkit.landing.model import landings_of_outline
from feederkit.mechanics.outcomes import fence_outcomes
from feederkit.mechanics.push import PushFunction, radius
from feederkit.outline import make_outline
from feederkit.part import Part, make_part
from feederkit.sim.pushalign import size_scale
from feederkit.sources import load_part

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_push_bands import (  # noqa: E402
    ROOT,
    SAMPLES,
    drawn_frictions,
    landing_models,
    settled_state,
)

TAB = str(ROOT / "benchmarks" / "parts" / "tab-notch.json")
OFFSETS = (0.1, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0)
QUICK_OFFSETS = (0.1, 0.5, 1.5, 3.0, 6.0)


def default_sources() -> list[str]:
    files = [TAB, f"{TAB}@30", f"{TAB}@40", f"{TAB}@60"]
    files.append(str(ROOT / "benchmarks" / "parts" / "rnd1-12gon.json"))
    files += [str(p) for p in sorted((ROOT / "catalog").glob("*.json"))]
    for name in ("trimesh__wrench.dxf", "trimesh__angle_block.STL", "trimesh__sliding-base.dxf"):
        if (SAMPLES / name).is_file():
            files.append(str(SAMPLES / name))
    return files


def scaled(part: Part, size_mm: float) -> Part:
    """``part`` scaled about its frame's origin to ``size_mm`` (COM scaled with it)."""
    s = size_mm / part.size
    o = part.outline
    outline = make_outline(
        f"{part.name}@{size_mm:g}",
        [(x * s, y * s) for x, y in o.vertices],
        [[(x * s, y * s) for x, y in hole] for hole in o.holes],
        com=(part.com[0] * s, part.com[1] * s),
    )
    return make_part(outline)


def load(spec: str) -> Part:
    """A SOURCE, or ``SOURCE@SIZE`` for a copy scaled to ``SIZE`` mm."""
    path, _, size = spec.rpartition("@") if "@" in spec else (spec, "", "")
    part = load_part(path)
    return scaled(part, float(size)) if size else part


@dataclass(frozen=True)
class Basin:
    """A state come down in one direction (``way`` +1: CCW, increasing theta), at the
    simulated size: from the start hilltop ``down_deg`` before the normal, ``drop_mm`` above
    the well, to the far hilltop ``over_deg`` past it, ``climb_mm`` above the well."""

    part: str
    size_mm: float
    state: int
    way: int
    down_deg: float
    drop_mm: float
    over_deg: float
    climb_mm: float


def basins(pf: PushFunction, part: Part, scale: float) -> dict[tuple[int, int], Basin]:
    """Every (range k, way) of the push function: range k lies between hilltops k and k+1."""
    div = np.asarray(pf.divergent_deg, float)
    m = len(div)
    out = {}
    for k in range(m):
        s = pf.range_state[k]
        n = pf.states[s].normal_deg
        well = float(radius(part, n))
        lo, hi = div[k], div[(k + 1) % m]
        a_lo, a_hi = norm360(n - lo), norm360(hi - n)
        p_lo, p_hi = (float(x) for x in radius(part, np.asarray([lo, hi])))
        size = part.size * scale
        # way +1: come down from hilltop k (below the normal), towards hilltop k+1.
        out[(k, 1)] = Basin(
            part.name, size, s, 1, a_lo, (p_lo - well) * scale, a_hi, (p_hi - well) * scale
        )
        out[(k, -1)] = Basin(
            part.name, size, s, -1, a_hi, (p_hi - well) * scale, a_lo, (p_lo - well) * scale
        )
    return out


def file_push(
    div: np.ndarray, hill: int, side: int, off: float, turned: float
) -> tuple[tuple[int, int], int, float]:
    """The basin (range, way) a push from ``off`` degrees beside hilltop ``hill`` on ``side``
    came down, how many hilltops past that basin's state it went over, and the degrees its
    start lay below the hilltop, negated (0 when carried back over it)."""
    m = len(div)
    start = div[hill] + side * off
    end = start + turned
    lo, hi = min(start, end), max(start, end)
    crossed = sum(
        int(np.floor((hi - d) / 360.0) - np.ceil((lo - d) / 360.0) + 1) for d in div
    )  # hilltops (unwrapped) strictly between start and end
    if turned * side >= 0.0:
        return ((hill if side > 0 else (hill - 1) % m), side), crossed, -off
    back = ((hill - 1) % m if side > 0 else hill, -side)
    return back, max(crossed - 1, 0), 0.0


def sweep(spec: str, offsets: tuple[float, ...], frictions: int) -> list[dict]:
    """One row per basin come down: the pushes filed under it, how many went over, how many
    of those the model's outcome sets miss, the farthest start (deg from its hilltop) that went
    over and the most hilltops one push went over."""
    drawn = drawn_frictions(frictions)
    rows = []
    for landing in landings_of_outline(load(spec))[:2]:
        part = landing.part
        pf, mech, aligner, normals = landing_models(part)
        scale = size_scale(part)
        div = np.asarray(pf.divergent_deg, float)
        geo = basins(pf, part, scale)
        tally: dict[tuple[int, int], dict] = {}
        for hill, top in enumerate(div):
            for side in (1, -1):
                for off in offsets:
                    start = float(top + side * off)
                    allowed = fence_outcomes(mech, start, start)
                    for belt, fence in drawn:
                        aligner.set_friction(belt, fence)
                        out = aligner.align(start)
                        if not out.settled:
                            continue
                        key, over, less = file_push(div, hill, side, off, out.turned_deg)
                        state = settled_state(mech, normals, out.theta_end_deg)
                        t = tally.setdefault(
                            key,
                            {
                                "pushes": 0,
                                "over": 0,
                                "missed": 0,
                                "start": 0.0,
                                "most": 0,
                            },
                        )
                        t["pushes"] += 1
                        if over > 0:
                            t["over"] += 1
                            t["missed"] += int(state is None or state not in allowed)
                            t["start"] = max(t["start"], -less)
                            t["most"] = max(t["most"], over)
        for key, t in sorted(tally.items()):
            b = geo[key]
            rows.append({"landing": landing.name, "basin": b, **t})
    return rows


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sources", nargs="*")
    ap.add_argument("--quick", action="store_true", help="5 offsets, 2 frictions")
    ap.add_argument("--frictions", type=int, default=None)
    ap.add_argument("--all", action="store_true", help="print basins never gone over too")
    ap.add_argument("--json", metavar="FILE", help="write every basin's row to FILE")
    args = ap.parse_args(argv)
    offsets = QUICK_OFFSETS if args.quick else OFFSETS
    frictions = args.frictions or (2 if args.quick else 4)
    t0 = time.process_time()
    head = (
        f"{'part':28} {'landing':7} {'size':>5} {'state':>5} {'way':>3} {'down':>6} {'H mm':>7} "
        f"{'over':>6} {'h mm':>7} {'h/H':>5} {'pushes':>6} {'went':>5} {'miss':>5} "
        f"{'start':>5} {'most':>4}"
    )
    print(head)
    found: list[tuple[Basin, int]] = []
    for spec in args.sources or default_sources():
        for r in sweep(spec, offsets, frictions):
            b: Basin = r["basin"]
            found.append((b, {k: v for k, v in r.items() if k != "basin"}))
            if r["over"] or args.all:
                print(
                    f"{b.part[:28]:28} {r['landing']:7} {b.size_mm:5.1f} {b.state:5d} "
                    f"{'+' if b.way > 0 else '-':>3} {b.down_deg:6.2f} {b.drop_mm:7.3f} "
                    f"{b.over_deg:6.2f} {b.climb_mm:7.3f} {b.climb_mm / b.drop_mm:5.2f} "
                    f"{r['pushes']:6d} {r['over']:5d} {r['missed']:5d} {r['start']:5.2f} "
                    f"{r['most']:4d}",
                    flush=True,
                )
    if args.json:
        Path(args.json).write_text(json.dumps([{**asdict(b), **r} for b, r in found]))
    missed = sum(r["missed"] for _, r in found)
    print(
        f"{len(found)} basins, {sum(1 for _, r in found if r['over'])} gone over, "
        f"{missed} pushes over a hilltop missed by the model; "
        f"{time.process_time() - t0:.0f} CPU s"
    )
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
