"""Benchmark: ``design sensor`` tables (critical tolerances and every length step).

Targets: the whole sensor design table (every pair's exact critical tolerance, the mix's,
and the optimal plan length's steps with all their breakpoints up to the critical
tolerance, each step's plan verified) for a 20-part mix in under 10 s, for a 50-part mix in
under 60 s. Two families of mixes: random convex 6- to 10-gons on one 60 x 40 mm ellipse
(as benchmarks/bench_planners.py: similar parts, small critical tolerances) and random
convex 3- to 10-gons of 20-100 mm (as benchmarks/bench_mix.py: varied sizes, larger
critical tolerances, so longer plans to prove).

Each case reports wall and CPU seconds (the machine is shared: CPU time is the steadier
figure). Each design runs as ``design sensor`` does (``partial=True``) with a time limit of
``CAP`` times its target: one cut there prints the pairs' critical tolerance, "table cut at
the limit" and the CPU seconds the pairs took. ``--baseline`` also builds each table with
every search question answered by a whole plan (``planning.api.plan``, tie-breaks and all,
as the table was first built) instead of the planner's length oracle alone, in the same
run, and prints the ratio.

Run: ``python benchmarks/bench_design.py [--quick] [--baseline]``
"""

from __future__ import annotations

import argparse
import math
import random
import resource
import signal
import sys
import time

import numpy as np

from feederkit.design import sensor as design_sensor
from feederkit.design.limit import PAIRS
from feederkit.design.sensor import design_tolerance
from feederkit.design.steps import LengthOracle, length_steps, mix_breakpoints, optimal_length
from feederkit.design.strong import StrongLengthOracle, machine_breakpoints, strong_length_steps
from feederkit.errors import InputError
from feederkit.machine.build import build_machine
from feederkit.mechanics.push import push_function
from feederkit.outline import make_outline
from feederkit.part import make_part
from feederkit.planning.api import plan
from feederkit.planning.solvable import NoStrongPlan
from feederkit.sensors import NoSensor, ToleranceSensor
from feederkit.uncertainty import Uncertainty


def ellipse_part(n: int, seed: int, name: str):
    """Random angles on a 60 x 40 mm ellipse: every point is a hull vertex."""
    rng = random.Random(seed)
    angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
    pts = [(30 * math.cos(t), 20 * math.sin(t)) for t in angles]
    return push_function(make_part(make_outline(name, pts)))


def ellipse_mix(count: int):
    return [
        ellipse_part(random.Random(s).randint(6, 10), 100 + s, f"mix-{s}") for s in range(count)
    ]


def varied_part(rng: np.random.Generator, name: str):
    """A random convex polygon (3-10 vertices, 20-100 mm) with a random COM inside."""
    while True:
        k = int(rng.integers(3, 11))
        size = float(rng.uniform(20.0, 100.0))
        ang = np.sort(rng.uniform(0.0, 2.0 * math.pi, k))
        r = rng.uniform(0.6, 1.0, k) * size / 2.0
        pts = np.c_[r * np.cos(ang), r * np.sin(ang)]
        try:
            part = make_part(make_outline(name, pts.tolist()))
            hull = np.asarray(part.hull)
            w = rng.dirichlet(np.ones(len(hull)))
            com = 0.5 * (w @ hull) + 0.5 * hull.mean(axis=0)
            return push_function(make_part(part.outline, (float(com[0]), float(com[1]))))
        except InputError:
            continue


def varied_mix(count: int, seed: int = 1):
    rng = np.random.default_rng(seed)
    return [varied_part(rng, f"p{i}") for i in range(count)]


class WholePlanOracle(LengthOracle):
    """The baseline: every question of the search answered by a whole plan."""

    def __init__(self, pfs) -> None:
        super().__init__(pfs)
        self.pfs = list(pfs)

    def length(self, tolerance: float) -> int:
        return optimal_length(self.pfs, tolerance)

    def within(self, tolerance: float, length: int) -> bool:
        return self.length(tolerance) <= length


class WholeStrongPlanOracle(StrongLengthOracle):
    """The baseline under uncertainty: every question answered by a whole strong plan."""

    def length(self, tolerance: float) -> int | None:
        machine = build_machine(self.mix.pfs, ToleranceSensor(tolerance), self.mix.uncertainty)
        try:
            return plan(machine).length
        except NoStrongPlan:
            return None

    def within(self, tolerance: float, length: int) -> bool:
        got = self.length(tolerance)
        return got is not None and got <= length


def whole_plan_design(pfs, uncertainty: Uncertainty):
    """``design_tolerance`` with every length question answered by a whole plan."""
    original, strong = design_sensor.length_steps, design_sensor.strong_length_steps

    def steps(pfs_, up_to, critical=None, clock=None):
        oracle = WholePlanOracle(pfs_)
        return length_steps(pfs_, up_to, oracle=oracle, critical=critical, clock=clock)

    def strong_steps(mix, up_to, critical, clock=None):
        oracle = WholeStrongPlanOracle(mix)
        return strong_length_steps(mix, up_to, critical, oracle=oracle, clock=clock)

    design_sensor.length_steps = steps
    design_sensor.strong_length_steps = strong_steps
    try:
        return design_tolerance(pfs, uncertainty=uncertainty)
    finally:
        design_sensor.length_steps = original
        design_sensor.strong_length_steps = strong


class GaveUp(Exception):
    """A case ran past its cap."""


def _alarm(signum, frame):
    raise GaveUp


CAP = 3.0
"""A case is stopped after this many times its target in CPU seconds (and counts as slow)."""


def timed(run, pfs, cap: float):
    """``(design, wall s, CPU s)`` of ``run(pfs)``, or ``(None, ...)`` past ``cap`` CPU
    seconds (CPU, not wall: on a shared machine other processes' load must not stop a case)."""
    signal.signal(signal.SIGPROF, _alarm)
    signal.setitimer(signal.ITIMER_PROF, cap)
    wall, cpu = time.perf_counter(), time.process_time()
    try:
        design = run(pfs)
    except GaveUp:
        design = None
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0.0)
    return design, time.perf_counter() - wall, time.process_time() - cpu


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the 20-part mixes only")
    ap.add_argument(
        "--baseline", action="store_true", help="also answer every question by a whole plan"
    )
    ap.add_argument(
        "--rotation-error",
        type=float,
        default=1.0,
        metavar="DEG",
        help="the declared rotation error (default 1; 0: the ideal model)",
    )
    args = ap.parse_args()
    unc = Uncertainty(args.rotation_error)
    model = "ideal model" if unc.is_ideal else "strong plans"
    print(f"rotation error {unc.rotation_error_deg:g} deg ({model})")
    cases = [
        ("20-part mix, 6-10-gons on one ellipse", lambda: ellipse_mix(20), 10.0),
        ("20-part mix, 3-10-gons of 20-100 mm", lambda: varied_mix(20), 10.0),
    ]
    if not args.quick:
        cases += [
            ("50-part mix, 6-10-gons on one ellipse", lambda: ellipse_mix(50), 60.0),
            ("50-part mix, 3-10-gons of 20-100 mm", lambda: varied_mix(50), 60.0),
        ]
    extra = " baseline wall s | baseline CPU s | CPU ratio |" if args.baseline else ""
    print(
        "| case | states | breakpoints | critical mm | steps (length) | wall s | CPU s | target |"
        f"{extra} |\n"
        "| --- | ---: | ---: | ---: | --- | ---: | ---: | ---: |"
        f"{' ---: | ---: | ---: |' if args.baseline else ''} --- |"
    )
    failed = 0
    for name, build, target in cases:
        pfs = build()
        states = sum(pf.n for pf in pfs)
        if unc.is_ideal:
            breaks = len(mix_breakpoints(pfs))
        else:
            breaks = len(machine_breakpoints(build_machine(pfs, NoSensor(), unc)))
        pairs_at: list[float] = []
        start = time.process_time()

        def progress(what: str, done: int, total: int, seen=pairs_at, t0=start) -> None:
            if what == PAIRS and done == total and not seen:
                seen.append(time.process_time() - t0)

        def run(p, limit=CAP * target, told=progress):
            # As the command: past the limit (wall s) a design without its length table.
            return design_tolerance(
                p, uncertainty=unc, partial=True, time_limit_s=limit, progress=told
            )

        design, wall, cpu = timed(run, pfs, CAP * target + 30.0)
        if design is not None and not design.complete:
            failed += 1
            x = design.critical.critical_tolerance
            row = (
                f"| {name} | {states} | {breaks} | pairs: {'none' if x is None else f'{x:.4g}'} "
                f"| table cut at the limit | {wall:.1f} | {cpu:.1f} (pairs "
                f"{pairs_at[0] if pairs_at else float('nan'):.1f}) | {target:g} |"
            )
            verdict = "SLOW"
        elif design is None:
            failed += 1
            row = (
                f"| {name} | {states} | {breaks} | - | - | {wall:.1f} (gave up) | > {cpu:.0f} | "
                f"{target:g} |"
            )
            verdict = "SLOW"
        else:
            lengths = ",".join("-" if s.length is None else str(s.length) for s in design.steps)
            x = design.critical_tolerance
            ok = wall < target
            failed += not ok
            row = (
                f"| {name} | {states} | {breaks} | {'none' if x is None else f'{x:.4g}'} | "
                f"{len(design.steps)} ({lengths}) | {wall:.2f} | {cpu:.2f} | {target:g} |"
            )
            verdict = "ok" if ok else "SLOW"
        if args.baseline:
            base, bwall, bcpu = timed(lambda p: whole_plan_design(p, unc), pfs, 2 * CAP * target)
            if base is None:
                row += f" {bwall:.1f} (gave up) | > {bcpu:.0f} | - |"
            else:
                whole = design is not None and design.complete
                same = not whole or base.to_dict() == design.to_dict()
                ratio = f"{bcpu / max(cpu, 1e-9):.2f}" if whole else "-"
                row += f" {bwall:.2f} | {bcpu:.2f} | {ratio}{'' if same else ' (TABLES DIFFER)'} |"
                failed += not same
        print(f"{row} {verdict} |", flush=True)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"peak memory {peak:.0f} MB")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
