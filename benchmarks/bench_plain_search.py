"""The planner against the plain search, with a sensor, on the deadline benchmark's cases.

    python benchmarks/bench_plain_search.py            # T = 60 s (plan's default limit)
    python benchmarks/bench_plain_search.py 10 mix     # T = 10 s, cases whose name has "mix"
    python benchmarks/bench_plain_search.py 60 "20-part mix, 5%" --plain-limit 1800

Issue 12 asks for sensor-based planning well ahead of the plain search, and for every case
of its own to keep its ratio against the plain search. ``bench_planners.py`` does so on its
small cases; this script does it on ``bench_deadline.py``'s cases (mixes of 5-200 random
6-10-gons at 0.5-5 %, random 50-1000-point outlines at 1-3 %, near-round 64- and 200-gons,
a 360-facet circle with a flat cut), each on the ideal model (the paper's section 6.1
search assumes it, so a case of the default 1 degree rotation error is planned here
without it; cases differing only in the model run once).

Each case runs in a fresh process (machine built first, not timed): ``plan`` with
``PlanningOptions(time_limit_s=T)``, its CPU seconds, length and whether it is proven
optimal; then ``bench_planners.baseline_length`` (iterative deepening over sets, every
overlap range, exact reading branching, a memo and nothing else) on a fresh copy of the
machine, which gives up after ``BASELINE_LIMIT_S`` of wall time (``--plain-limit S``: after
``S``), and its CPU seconds and length. The ratio is the plain search's CPU over the plan's,
``>`` when the plain search gave up. Both processes are capped at ``MEMORY_MB`` of address
space: a search that runs out says so. Exit code 1 when two finished searches disagree on a
length the planner proved optimal (a wrong answer on one side), or a case crashes.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from bench_deadline import CASES, run_child
from bench_planners import BASELINE_LIMIT_S

MEMORY_MB = 6000
"""Address-space cap of each case's process."""

CHILD = r"""
import json, resource, sys, time
sys.path.insert(0, sys.argv[3])
cap = int(float(sys.argv[4]) * 2**20)
resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
from bench_planners import GaveUp, baseline_length, fresh
from bench_planners import circle_cut, mix, near_round, random_outline
from feederkit.errors import PlanningError
from feederkit.machine import build_machine
from feederkit.planning.api import plan
from feederkit.planning.options import PlanningOptions
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL

expr, tol = sys.argv[1].split("|")[:2]
limit = float(sys.argv[2])
pfs = eval(expr)
size = max(pf.part.size for pf in pfs)
mm = float(tol[:-1]) / 100.0 * size if tol.endswith("%") else float(tol)
machine = build_machine(pfs, ToleranceSensor(mm), IDEAL)
out = {"states": machine.n, "mm": mm}
c0 = time.process_time()
try:
    r = plan(fresh(machine), PlanningOptions(time_limit_s=limit))
    out.update(length=r.length, lower=r.lower_bound, optimal=r.optimal)
except PlanningError as e:
    out["error"] = str(e)
except MemoryError:
    out["error"] = "out of memory"
out["cpu"] = time.process_time() - c0
c0 = time.process_time()
try:
    out["base_length"] = baseline_length(fresh(machine), float(sys.argv[5]))
except GaveUp:
    out["base_gave_up"] = True
except MemoryError:
    out["base_gave_up"] = True
    out["base_memory"] = True
out["base_cpu"] = time.process_time() - c0
print(json.dumps(out))
"""


def ideal_cases() -> dict[str, str]:
    """``bench_deadline.CASES`` on the ideal model: name -> "parts|tolerance", each once."""
    out: dict[str, str] = {}
    for name, (_table, spec, _quick) in CASES.items():
        expr, tol, _model = spec.split("|")
        key = f"{expr}|{tol}"
        if key not in out.values():
            out[name.removesuffix(", ideal")] = key
    return out


def run_case(spec: str, limit: float, here: str, plain_s: float = BASELINE_LIMIT_S) -> dict:
    """One case in a fresh process: its JSON line, or ``{"missed": why}``."""
    hard = 3 * limit + plain_s + 60
    return run_child(CHILD, [spec, str(limit), here, str(MEMORY_MB), str(plain_s)], hard)


def cells(name: str, r: dict, plain_s: float = BASELINE_LIMIT_S) -> list[str]:
    """The markdown cells of one case: name, states, plan CPU, length, optimal, plain CPU,
    its length, ratio."""
    if "missed" in r:
        return [name, "-", "-", "-", "-", "-", "-", r["missed"]]
    planned = "error" not in r
    length = str(r["length"]) if planned else "none"
    proven = ("yes" if r["optimal"] else f"no (bound {r['lower']})") if planned else r["error"][:40]
    if r.get("base_gave_up"):
        why = "out of memory" if r.get("base_memory") else f"gave up at {plain_s:.0f} s"
        base, blen = f"> {r['base_cpu']:.1f}", why
        ratio = f"> {r['base_cpu'] / max(r['cpu'], 1e-9):.0f}x" if planned else "-"
    else:
        base, blen = f"{r['base_cpu']:.3f}", str(r["base_length"])
        x = r["base_cpu"] / max(r["cpu"], 1e-9)
        ratio = (f"{x:.2f}x" if x < 10 else f"{x:.0f}x") if planned else "-"
    return [name, str(r["states"]), f"{r['cpu']:.3f}", length, proven, base, blen, ratio]


HEAD = ("case", "states", "plan cpu s", "length", "optimal", "plain cpu s", "plain length", "ratio")


def main(argv: list[str]) -> int:
    limit, plain_s = 60.0, BASELINE_LIMIT_S
    if "--plain-limit" in argv:
        at = argv.index("--plain-limit")
        plain_s = float(argv[at + 1])
        argv = argv[:at] + argv[at + 2 :]
    if argv and argv[0].replace(".", "", 1).isdigit():
        limit, argv = float(argv[0]), argv[1:]
    here = str(Path(__file__).resolve().parent)
    print(f"plan time limit {limit:g} s; the plain search gives up after {plain_s:g} s")
    rows, bad = [], 0
    began = time.perf_counter()
    for name, spec in ideal_cases().items():
        if argv and not any(w in name for w in argv):
            continue
        r = run_case(spec, limit, here, plain_s)
        row = cells(name, r, plain_s)
        rows.append(row)
        wrong = "base_length" in r and r.get("optimal") and r["base_length"] != r["length"]
        bad += "missed" in r or bool(wrong)
        flag = "  <-- LENGTHS DISAGREE" if wrong else ""
        print("  ".join(row) + flag, flush=True)
    print(f"\n{time.perf_counter() - began:.0f} s in all\n")
    print("| " + " | ".join(HEAD) + " |")
    print("| --- |" + " ---: |" * 3 + " --- |" + " ---: |" * 3)
    for row in rows:
        print("| " + " | ".join(row) + " |")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
