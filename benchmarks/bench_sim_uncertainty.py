"""Strong plans in the physics check, at the declared uncertainty (docs/simulation.md).

Run: ``python benchmarks/bench_sim_uncertainty.py [--trials N] [--only NAME,...] [--landings]
[--sensorless] [--creep]``.

Plans every part of ``catalog/`` and every drawing of ``../shared/samples/`` that can be
oriented (rotation error 1 degree, a tolerance sensor of 1 % of the part's size) and the
demo's changeovers (the demo's mixes and its look-alike pair, a sensor of 1 % of the largest
part), then simulates each plan for ``--trials`` trials (default 200) sampling the declared
uncertainty and the default friction ranges (belt 0.4:0.6, fence 0.1:0.3). Prints per plan the
success rate with its 95 % Wilson interval and the failures by cause, model errors (outcomes
the plan's model did not predict) counted apart. A part with no strong plan at 1 degree is
listed as such. The target is 99.5 % success; exit 1 when a plan misses it.

``--sensorless`` plans every part without a sensor instead (the demo's changeovers left out):
sensorless plans rotate more, and more often near a hilltop.

``--landings`` plans every catalog part over its landings instead (design.md, "Landings": a
flat part lands ``up`` or ``down``), the next station taking only its first landing, and counts
per plan the trials whose part was rightly rejected and the wrong accepts (a part ending in an
accepting leaf that does not name its landing and state), members drawn by their shares.

``--creep`` measures instead how far a settled part drifts (turns, slides along the fence)
over 5 simulated seconds under the contact settings MuJoCo offers against its soft-contact
creep (elliptic cones with a higher ``impratio``, ``noslip_iterations``).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = Path(__file__).resolve().parents[2] / "shared" / "samples"

from feederkit.demo import add_lookalike, compile_demo_changeover, demo_mixes  # noqa: E402
from feederkit.errors import InputError, PlanningError  # noqa: E402
from feederkit.loading import load_parts  # noqa: E402
from feederkit.mechanics.push import PushFunction  # noqa: E402
from feederkit.plans.make import make_plan  # noqa: E402
from feederkit.sensors import NoSensor, ToleranceSensor  # noqa: E402
from feederkit.sim import PushAligner, SceneConfig, simulate_plan  # noqa: E402
from feederkit.sim.summary import wilson  # noqa: E402
from feederkit.uncertainty import Uncertainty  # noqa: E402

TARGET = 0.995
UNCERTAINTY = Uncertainty(1.0, 0.0, 0.0)
SENSOR_PERCENT = 1.0


def sensor_for(pfs: list[PushFunction]) -> ToleranceSensor:
    """A tolerance of 1 % of the largest part's size (3 digits, as the demo rounds it)."""
    size = max(pf.part.size for pf in pfs)
    return ToleranceSensor(float(f"{size * SENSOR_PERCENT / 100.0:.3g}"))


def load(sources: list[str]) -> tuple[list[PushFunction], list[str]]:
    """The orientable parts of ``sources`` and the names left out (not orientable)."""
    out, left = [], []
    for source in sources:
        try:
            loaded = load_parts([source], leave_out_not_orientable=True)
        except InputError as exc:
            left.append(f"{Path(source).name}: {exc}")
            continue
        if not loaded.push_functions:
            left.append(f"{Path(source).name}: not orientable by pushing")
        out += list(loaded.push_functions)
    return out, left


def jobs(only: set[str] | None) -> tuple[list[tuple[str, list[PushFunction]]], list[str]]:
    """(name, parts) of every part to plan on its own: the catalog's, then the samples'."""
    catalog = sorted(str(p) for p in (ROOT / "catalog").glob("*.json"))
    samples = sorted(str(p) for p in SAMPLES.iterdir() if p.suffix.lower() != ".md")
    cat_pfs, left = load(catalog)
    sample_pfs, left2 = load(samples)
    out = [(pf.part.name, [pf]) for pf in cat_pfs + sample_pfs]
    if only:
        out = [(n, p) for n, p in out if n in only]
    return out, left + left2


def demo_changeovers(folder: Path, only: set[str] | None) -> list[tuple[str, dict]]:
    """The demo's changeovers compiled as ``feederkit demo`` compiles them (its landings,
    accepted landings, sensor and look-alike), each as (name, plan file object)."""
    from feederkit.catalog import import_directory, open_catalog

    db = folder / "bench.db"
    open_catalog(db, create=True).close()
    import_directory(db, ROOT / "catalog")
    pfs = load_parts([str(p) for p in sorted((ROOT / "catalog").glob("*.json"))]).push_functions
    mixes = demo_mixes(list(pfs))
    twin = add_lookalike(db, list(pfs))
    if twin is not None:
        mixes.append(twin)
    out = []
    for mix in mixes:
        if only and mix.name not in only and f"changeover {mix.name}" not in only:
            continue
        c = compile_demo_changeover(db, mix, folder, 1.0, report=False)
        out.append((f"changeover {mix.name}", c.compiled.plan))
    return out


def _row(name: str, plan: dict, trials: int, totals: list[int]) -> bool:
    """Simulate ``plan`` and print its row; whether it met the target (no wrong accept)."""
    t0 = time.perf_counter()
    s = simulate_plan(plan, trials, seed=0)
    wall = time.perf_counter() - t0
    lo, hi = wilson(s.successes, s.trials)
    cert = plan["stats"].get("certificate") or {}
    causes = ", ".join(f"{c} {n}" for c, n in s.by_cause().items()) or "none"
    if s.model_errors:
        causes += f" (model errors {s.model_errors})"
    if s.rejects or s.wrong_accepts:
        causes += f"; rejected {s.rejects}, wrong accepts {s.wrong_accepts}"
    print(
        f"{name:34s} {plan['stats']['length']:3d} {cert.get('ideal_length', '-')!s:>5s} "
        f"{100 * s.success_rate:7.1f}% [{100 * lo:5.1f}, {100 * hi:5.1f}]%  {causes}"
        f"  ({wall:.1f} s)"
    )
    for r in s.went_wrong[:2]:
        print(f"    trial {r.index} step {r.step}: {r.cause}; {r.reason}")
    totals[0] += s.successes
    totals[1] += s.trials
    return s.success_rate >= TARGET and s.wrong_accepts == 0


def run(trials: int, only: set[str] | None, sensorless: bool = False) -> bool:
    work, left = jobs(only)
    sensing = "no sensor" if sensorless else f"sensor {SENSOR_PERCENT:g} % of size"
    print(
        f"strong plans at rotation error {UNCERTAINTY.rotation_error_deg:g} deg, {sensing}; "
        f"{trials} trials each, friction belt 0.4:0.6, fence 0.1:0.3, rotation errors uniform "
        "in +-1 deg per rotation"
    )
    header = f"{'plan':34s} {'len':>3s} {'ideal':>5s} {'success':>8s} {'95% Wilson':>15s}  failures"
    print(header)
    ok = True
    totals = [0, 0]
    for name, pfs in work:
        try:
            sensor = NoSensor() if sensorless else sensor_for(pfs)
            made = make_plan(pfs, sensor, uncertainty=UNCERTAINTY)
        except PlanningError as exc:
            print(f"{name:34s} no strong plan at 1 deg: {exc}")
            continue
        ok &= _row(name, made.plan, trials, totals)
    with tempfile.TemporaryDirectory(prefix="bench-sim-") as tmp:
        for name, plan in [] if sensorless else demo_changeovers(Path(tmp), only):
            ok &= _row(name, plan, trials, totals)
    if totals[1]:
        lo, hi = wilson(*totals)
        rate = totals[0] / totals[1]
        print(
            f"{'all plans':34s}         {100 * rate:7.2f}% [{100 * lo:5.2f}, {100 * hi:5.2f}]%"
            f"  ({totals[0]} of {totals[1]})"
        )
    for line in left:
        print(f"left out: {line}")
    print(f"target {100 * TARGET:g} % per plan: {'met' if ok else 'MISSED'}")
    return ok


def landings(trials: int, only: set[str] | None) -> bool:
    """Every catalog part planned over its landings, only the first landing accepted."""
    from feederkit.landing.plan import load_landings, plan_landings

    print(
        f"plans over landings at rotation error {UNCERTAINTY.rotation_error_deg:g} deg, sensor "
        f"{SENSOR_PERCENT:g} % of size, the first landing accepted; {trials} trials each, "
        "members drawn by their shares"
    )
    print(
        f"{'part':26s} {'landings':18s} {'len':>3s} {'success':>8s} {'95% Wilson':>15s} "
        f"{'rejected':>8s} {'wrong acc':>9s}"
    )
    ok = True
    totals = [0, 0, 0]
    for source in sorted(str(p) for p in (ROOT / "catalog").glob("*.json")):
        name = Path(source).stem
        if only and name not in only:
            continue
        lands = load_landings([source]).all
        accept = {lands[0].name}
        sensor = ToleranceSensor(float(f"{max(x.part.size for x in lands) / 100.0:.3g}"))
        names = "/".join(x.name for x in lands)
        try:
            made = plan_landings(lands, sensor, uncertainty=UNCERTAINTY, accept=accept).made
        except (PlanningError, InputError) as exc:
            print(f"{name:26s} {names:18s} no plan: {exc}")
            continue
        s = simulate_plan(made.plan, trials, seed=0)
        lo, hi = wilson(s.successes, s.trials)
        print(
            f"{name:26s} {names:18s} {made.plan['stats']['length']:3d} "
            f"{100 * s.success_rate:7.1f}% [{100 * lo:5.1f}, {100 * hi:5.1f}]% "
            f"{s.rejects:8d} {s.wrong_accepts:9d}  {s.by_cause() or ''}"
        )
        totals[0] += s.successes
        totals[1] += s.trials
        totals[2] += s.wrong_accepts
        ok &= s.success_rate >= TARGET and s.wrong_accepts == 0
    if totals[1]:
        lo, hi = wilson(totals[0], totals[1])
        print(
            f"{'all':26s} {'':18s}     {100 * totals[0] / totals[1]:7.2f}% "
            f"[{100 * lo:5.2f}, {100 * hi:5.2f}]%  ({totals[0]} of {totals[1]}; wrong accepts "
            f"{totals[2]})"
        )
    return ok


CREEP_SETTINGS = {
    "elliptic, impratio 1 (chosen)": SceneConfig(),
    "elliptic, impratio 10": SceneConfig(impratio=10.0),
    "elliptic, impratio 100": SceneConfig(impratio=100.0),
    "elliptic, noslip_iterations 10": SceneConfig(noslip_iterations=10),
    "pyramidal, noslip_iterations 10": SceneConfig(cone="pyramidal", noslip_iterations=10),
}
CREEP_PARTS = ("rectangle-2x1", "t-clip", "l-bracket", "octagon")
CREEP_SECONDS = 5.0


def creep() -> None:
    print(
        f"drift of a settled part over {CREEP_SECONDS:g} simulated s (belt running), worst over "
        "its states with a resting range of 10 deg or more"
    )
    print(f"{'part':15s} {'contact settings':33s} {'turn deg':>9s} {'slide mm':>9s} {'cpu s':>6s}")
    for name in CREEP_PARTS:
        pf = load([str(ROOT / "catalog" / f"{name}.json")])[0][0]
        states = [s for s in pf.states if s.resting_range_deg[1] - s.resting_range_deg[0] >= 10.0]
        for label, cfg in CREEP_SETTINGS.items():
            aligner = PushAligner(pf.part, cfg)
            c0 = time.process_time()
            rows = [aligner.resting_drift(s.normal_deg, CREEP_SECONDS) for s in states]
            cpu = time.process_time() - c0
            turn = max(r[0] for r in rows)
            slide = max(r[1] for r in rows)
            print(f"{name:15s} {label:33s} {turn:9.3f} {slide:9.3f} {cpu:6.2f}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=200)
    ap.add_argument("--only", default="", help="comma-separated plan names")
    ap.add_argument("--creep", action="store_true", help="measure contact creep instead")
    ap.add_argument("--landings", action="store_true", help="plan over landings instead")
    ap.add_argument("--sensorless", action="store_true", help="plan without a sensor")
    args = ap.parse_args()
    if args.creep:
        creep()
        return 0
    only = {s.strip() for s in args.only.split(",") if s.strip()} or None
    if args.landings:
        return 0 if landings(args.trials, only) else 1
    return 0 if run(args.trials, only, args.sensorless) else 1


if __name__ == "__main__":
    sys.exit(main())
