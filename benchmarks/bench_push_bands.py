"""Pushes near hilltops in the physics check against the model's outcome sets (the push bands).

    python benchmarks/bench_push_bands.py                  # catalog/ and ../shared/samples
    python benchmarks/bench_push_bands.py PART_OR_FILE ... # any SOURCEs
    python benchmarks/bench_push_bands.py --step 0.5 --reach 4 --frictions 2   # quicker

For each part (up to two landings) and each divergent orientation (hilltop) of its push
function, MuJoCo pushes (``feederkit.sim.pushalign.PushAligner``, the model's vibration
breathing on the part) start at ``--step``, 2 ``--step``, ... up to ``--reach`` degrees on
either side of the hilltop, each with ``--frictions`` belt and fence frictions drawn from the
simulator's default ranges (belt 0.4-0.6, fence 0.1-0.3; seed 0). A push *misses* when the
state it settles in is not in the model's outcome set for its start
(``mechanics.outcomes.fence_outcomes`` under rotation error 1 degree, no shape or COM
tolerance: the push bands, the depth rule, the overshoot rule). Printed per part: pushes
settled, misses, and the hilltops missed with the farthest start missed (degrees from the
hilltop). The model claims no misses (docs/uncertainty.md, "Push bands"); exit 1 when there
are some. Plans keep their rotations a margin away from band ends, so a miss is a push a plan
may or may not make: ``bench_sim_uncertainty.py`` simulates the plans themselves.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from feederkit.landing.model import landings_of_outline
from feederkit.mechanics.outcomes import fence_outcomes
from feederkit.mechanics.push import push_function
from feederkit.mechanics.uncertain import UncertainMechanics, uncertain_mechanics
from feederkit.sim.pushalign import PushAligner, size_scale
from feederkit.sources import load_part
from feederkit.uncertainty import Uncertainty

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT.parent / "shared" / "samples"
UNCERTAINTY = Uncertainty(1.0, 0.0, 0.0)


def drawn_frictions(count: int) -> list[tuple[float, float]]:
    """``count`` (belt, fence) frictions from the simulator's default ranges (belt 0.4-0.6,
    fence 0.1-0.3), seed 0: the same draws in every push benchmark."""
    rng = np.random.default_rng(0)
    return [(rng.uniform(0.4, 0.6), rng.uniform(0.1, 0.3)) for _ in range(count)]


def settled_state(
    mech: UncertainMechanics, normals: np.ndarray, theta_end_deg: float
) -> int | None:
    """The model's physical state a push settled in: that of the ideal state whose normal
    lies nearest its end orientation (None: a state the model merged away)."""
    off_normal = np.abs((normals - theta_end_deg + 180.0) % 360.0 - 180.0)
    return mech.state_of[int(np.argmin(off_normal))]


def landing_models(part) -> tuple:
    """What a push sweep over one landing needs: its push function, its mechanics at the
    declared uncertainty, a simulator of its pushes (the mechanics' vibration) and its
    states' normals."""
    pf = push_function(part)
    mech = uncertain_mechanics(part, UNCERTAINTY)
    aligner = PushAligner(part, None, None, vibration_mm=mech.vibration_mm)
    return pf, mech, aligner, np.array([s.normal_deg for s in pf.states])


def default_sources() -> list[str]:
    files = sorted((ROOT / "catalog").glob("*.json"))
    if SAMPLES.is_dir():
        files += sorted(p for p in SAMPLES.iterdir() if p.suffix.lower() in (".dxf", ".stl"))
    return [str(p) for p in files]


def sweep(source: str, step: float, reach: float, frictions: int) -> list[dict]:
    """One row per landing: pushes settled, misses, and per missed (hilltop, side) the
    farthest start missed."""
    drawn = drawn_frictions(frictions)
    rows = []
    for landing in landings_of_outline(load_part(source))[:2]:
        part = landing.part
        pf, mech, aligner, normals = landing_models(part)
        settled, missed, farthest = 0, 0, {}
        for hill in pf.divergent_deg:
            for side in (1, -1):
                for off in np.arange(step, reach + 1e-9, step):
                    start = hill + side * off
                    allowed = fence_outcomes(mech, start, start)
                    for belt, fence in drawn:
                        aligner.set_friction(belt, fence)
                        out = aligner.align(start)
                        if not out.settled:
                            continue
                        settled += 1
                        state = settled_state(mech, normals, out.theta_end_deg)
                        if state is None or state not in allowed:
                            missed += 1
                            key = (round(float(hill), 2), side)
                            farthest[key] = max(farthest.get(key, 0.0), float(off))
        rows.append(
            {
                "part": part.name,
                "size": part.size,
                "scale": size_scale(part),
                "settled": settled,
                "missed": missed,
                "farthest": farthest,
            }
        )
    return rows


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sources", nargs="*")
    ap.add_argument("--step", type=float, default=0.25)
    ap.add_argument("--reach", type=float, default=5.0)
    ap.add_argument("--frictions", type=int, default=4)
    args = ap.parse_args(argv)
    sources = args.sources or default_sources()
    t0 = time.process_time()
    total_settled = total_missed = 0
    print(f"{'part':36} {'size mm':>8} {'sim x':>6} {'pushes':>7} {'missed':>7}  hilltops missed")
    for source in sources:
        for r in sweep(source, args.step, args.reach, args.frictions):
            total_settled += r["settled"]
            total_missed += r["missed"]
            where = ", ".join(
                f"{h:g}{'+' if s > 0 else '-'} to {f:g} deg" for (h, s), f in r["farthest"].items()
            )
            print(
                f"{r['part']:36} {r['size']:8.2f} {r['scale']:6.2f} {r['settled']:7d} "
                f"{r['missed']:7d}  {where or '-'}",
                flush=True,
            )
    print(
        f"{total_missed} of {total_settled} settled pushes missed the model's outcome sets; "
        f"{time.process_time() - t0:.0f} CPU s"
    )
    return 1 if total_missed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
