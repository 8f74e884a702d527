"""Benchmark: ``plan`` with a time limit answers within it, and how close its plans come to
their proven lower bounds (the anytime figures).

    python benchmarks/bench_deadline.py                # T = 10 s, every case
    python benchmarks/bench_deadline.py --quick        # T = 4 s, a subset (under 2 minutes)
    python benchmarks/bench_deadline.py 2 mix          # T = 2 s, cases whose name has "mix"
    python benchmarks/bench_deadline.py 10 --memory 300   # and a memory limit of 300 MB

Each case runs in a fresh process (its machine built first, not timed) and calls
``feederkit.planning.api.plan`` with ``PlanningOptions(time_limit_s=T)``; the parent kills
it after ``3 T + 30`` s. Per case: the limit, wall and CPU seconds of ``plan``, the overshoot
(wall - T), peak memory (the child's maximum resident set, machine included), and the
answer: length, proven lower bound, gap (length - bound: 0 means the plan meets its bound),
optimal or not, or the one-line PlanningError.

Two tables (docs/performance.md, "Deadline and memory"):

- *anytime*: the cases where time-limited plans should come within one operation of their
  bound: mixes of 5-50 random 6-10-gons (60 x 40 mm) at 1-5 %, a random 1000-point outline
  (the hull of points at random angles and radii 21-30 mm: 32 stable states),
  a 64-gon with 1 % radial noise at 0.3 mm;
- *hard*: near-round 64- and 200-gons (radius 10 mm, radial noise 0.1-1 %) at 0.5-3 %, a
  360-facet circle with a flat cut, random 50-1000-point outlines at 1-3 %, mixes of 20-200
  parts of one size at 0.5-5 %.

A tolerance in % is of the largest part's size (its hull's diameter, `Part.size`: about 60 mm
for the outlines and mixes, 20 mm for the near-round parts). The model is the default
uncertainty (rotation error 1 deg) unless the case says "ideal". The tables print as
markdown at the end. Exit code 1 when some case overshoots by more than
``MAX_OVERSHOOT_S`` or crashes.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

MAX_OVERSHOOT_S = 2.0
"""The constant of "within the limit plus a small constant" (docs/planning.md)."""

QUICK_LIMIT_S = 4.0

# name -> (table, "parts|tolerance|model", in the quick run?)
CASES: dict[str, tuple[str, str, bool]] = {
    # The cases, as a user plans them (the anytime figures).
    "5-part mix, 1%": ("anytime", "mix(5)|1%|unc", True),
    "5-part mix, 3%": ("anytime", "mix(5)|3%|unc", False),
    "20-part mix, 1%": ("anytime", "mix(20)|1%|unc", False),
    "20-part mix, 5%": ("anytime", "mix(20)|5%|unc", True),
    "50-part mix, 1%": ("anytime", "mix(50)|1%|unc", True),
    "50-part mix, 1%, ideal": ("anytime", "mix(50)|1%|ideal", True),
    "50-part mix, 3%": ("anytime", "mix(50)|3%|unc", False),
    "random 1000-point outline, 3%": ("anytime", "[random_outline(1000, 1)]|3%|unc", False),
    "random 1000-point outline, 3%, ideal": (
        "anytime",
        "[random_outline(1000, 1)]|3%|ideal",
        True,
    ),
    "near-round 64-gon 1%, 0.3 mm": ("anytime", "[near_round(64, 0.01)]|0.3|unc", True),
    "near-round 64-gon 1%, 0.3 mm, ideal": ("anytime", "[near_round(64, 0.01)]|0.3|ideal", False),
    # The hard cases.
    "near-round 64-gon 0.1%, 0.5%": ("hard", "[near_round(64, 0.001)]|0.5%|unc", False),
    "near-round 64-gon 0.1%, 0.5%, ideal": ("hard", "[near_round(64, 0.001)]|0.5%|ideal", True),
    "near-round 64-gon 1%, 3%": ("hard", "[near_round(64, 0.01)]|3%|unc", False),
    "near-round 200-gon 0.1%, 0.5%, ideal": ("hard", "[near_round(200, 0.001)]|0.5%|ideal", False),
    "near-round 200-gon 0.1%, 3%": ("hard", "[near_round(200, 0.001)]|3%|unc", False),
    "near-round 200-gon 1%, 0.5%": ("hard", "[near_round(200, 0.01)]|0.5%|unc", False),
    "near-round 200-gon 1%, 3%, ideal": ("hard", "[near_round(200, 0.01)]|3%|ideal", True),
    "360-facet circle, flat cut, 0.3 mm": ("hard", "[circle_cut()]|0.3|unc", False),
    "360-facet circle, flat cut, 0.3 mm, ideal": ("hard", "[circle_cut()]|0.3|ideal", True),
    "random 50-point outline, 1%": ("hard", "[random_outline(50, 2)]|1%|unc", False),
    "random 50-point outline, 3%": ("hard", "[random_outline(50, 2)]|3%|unc", True),
    "random 200-point outline, 1%": ("hard", "[random_outline(200, 4)]|1%|unc", False),
    "random 1000-point outline, 1%, ideal": (
        "hard",
        "[random_outline(1000, 1)]|1%|ideal",
        False,
    ),
    # At 1 % of its hull's diameter (0.599 mm) its 32 diameters (spread 1.197 mm) read alike and
    # backchaining answers at once; 0.9 % keeps the readings informative (the case as it was
    # when the size was the bounding box's side).
    "random 1000-point outline, 0.9%, ideal": (
        "hard",
        "[random_outline(1000, 1)]|0.9%|ideal",
        False,
    ),
    "20-part mix, 0.5%": ("hard", "mix(20)|0.5%|unc", False),
    "50-part mix, 5%": ("hard", "mix(50)|5%|unc", False),
    "100-part mix, 0.5%": ("hard", "mix(100)|0.5%|unc", True),
    "100-part mix, 5%": ("hard", "mix(100)|5%|unc", False),
    "200-part mix, 0.5%": ("hard", "mix(200)|0.5%|unc", False),
    "200-part mix, 1%, ideal": ("hard", "mix(200)|1%|ideal", False),
}

CHILD = r"""
import json, resource, sys, time
sys.path.insert(0, sys.argv[4])
from bench_planners import circle_cut, mix, near_round, random_outline
from feederkit.errors import PlanningError
from feederkit.machine import build_machine
from feederkit.planning.api import plan
from feederkit.planning.options import PlanningOptions
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL, Uncertainty

expr, tol, unc = sys.argv[1].split("|")
limit = float(sys.argv[2])
memory = None if sys.argv[3] == "none" else float(sys.argv[3])
model = IDEAL if unc == "ideal" else Uncertainty()
t0 = time.perf_counter()
pfs = eval(expr)
size = max(pf.part.size for pf in pfs)
mm = float(tol[:-1]) / 100.0 * size if tol.endswith("%") else float(tol)
machine = build_machine(pfs, ToleranceSensor(mm), model)
built = time.perf_counter() - t0
t0, c0 = time.perf_counter(), time.process_time()
try:
    r = plan(machine, PlanningOptions(time_limit_s=limit, memory_limit_mb=memory))
    out = {"length": r.length, "lower": r.lower_bound, "optimal": r.optimal}
except PlanningError as e:
    out = {"error": str(e)}
out.update(states=machine.n, wall=time.perf_counter() - t0, cpu=time.process_time() - c0,
           peak_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, mm=mm, built=built)
print(json.dumps(out))
"""


def run_case(spec: str, limit: float, memory: str, here: str) -> dict:
    """One case in a fresh process: its JSON line, or ``{"missed": why}``."""
    return run_child(CHILD, [spec, str(limit), memory, here], 3 * limit + 30)


def run_child(code: str, args: list[str], hard: float) -> dict:
    """``code`` run by a fresh Python with ``args``, killed after ``hard`` seconds: the JSON
    of its last line on stdout, or ``{"missed": why}``."""
    try:
        p = subprocess.run(
            [sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=hard
        )
    except subprocess.TimeoutExpired:
        return {"missed": f"killed after {hard:.0f} s"}
    lines = p.stdout.strip().splitlines()
    if p.returncode != 0 or not lines:
        tail = (p.stderr.strip().splitlines() or ["?"])[-1]
        return {"missed": f"crashed: {tail}"}
    return json.loads(lines[-1])


def _answer(r: dict) -> str:
    if "missed" in r:
        return r["missed"]
    if "error" in r:
        return r["error"]
    return ""


def row(name: str, limit: float, r: dict) -> list[str]:
    """The markdown cells of one case."""
    if "missed" in r:
        return [name, "-", f"{limit:g}", "-", "-", "-", "-", "-", "-", "-", "-", r["missed"]]
    over = r["wall"] - limit
    cells = [
        name,
        str(r["states"]),
        f"{limit:g}",
        f"{r['wall']:.2f}",
        f"{over:+.2f}",
        f"{r['cpu']:.2f}",
        f"{r['peak_mb']:.0f}",
    ]
    if "error" in r:
        note = r["error"]
        bound = _bound_in(note)
        return cells + ["-", bound, "-", "no", _short(note)]
    gap = r["length"] - r["lower"]
    return cells + [
        str(r["length"]),
        str(r["lower"]),
        str(gap),
        "yes" if r["optimal"] else "no",
        "" if gap <= 1 else "gap > 1",
    ]


def _bound_in(message: str) -> str:
    """The lower bound a 'no plan found' message names, or '-'."""
    key = "needs at least "
    if key in message:
        return message.split(key, 1)[1].split()[0]
    return "-"


def _short(message: str) -> str:
    """A PlanningError in a few words for a table cell."""
    if "inseparable" in message:
        return "no plan (ran out in the goal fixpoint)"
    if "no plan found within" in message:
        return "no plan in time"
    if "no strong plan" in message:
        return "no strong plan exists" if "exists" in message else "no strong plan found"
    return message[:60]


HEAD = (
    "case",
    "states",
    "limit s",
    "wall s",
    "over s",
    "cpu s",
    "peak MB",
    "length",
    "bound",
    "gap",
    "optimal",
    "note",
)


def markdown(rows: list[list[str]]) -> str:
    out = ["| " + " | ".join(HEAD) + " |", "| --- |" + " ---: |" * (len(HEAD) - 3) + " --- | --- |"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def main(argv: list[str]) -> int:
    memory = "none"
    if "--memory" in argv:
        k = argv.index("--memory")
        memory = argv[k + 1]
        argv = argv[:k] + argv[k + 2 :]
    quick = "--quick" in argv
    argv = [a for a in argv if a != "--quick"]
    if argv and argv[0].replace(".", "", 1).isdigit():
        limit = float(argv[0])
        wanted = argv[1:]
    else:
        limit = QUICK_LIMIT_S if quick else 10.0
        wanted = argv
    here = str(Path(__file__).resolve().parent)
    print(f"time limit {limit:g} s, memory limit {memory} MB{' (quick)' if quick else ''}")
    print(
        f"{'case':42} {'states':>6} {'wall s':>7} {'cpu s':>7} {'over s':>7} {'peak MB':>8}  answer"
    )
    tables: dict[str, list[list[str]]] = {"anytime": [], "hard": []}
    bad, worst, plans, near = 0, -1e9, 0, 0
    began = time.perf_counter()
    for name, (table, spec, in_quick) in CASES.items():
        if (quick and not in_quick) or (wanted and not any(w in name for w in wanted)):
            continue
        start = time.perf_counter()
        r = run_case(spec, limit, memory, here)
        tables[table].append(row(name, limit, r))
        if "missed" in r:
            print(f"{name:42} {r['missed']}  <-- MISSED", flush=True)
            bad += 1
            continue
        over = r["wall"] - limit
        worst = max(worst, over)
        if "error" in r:
            answer = "PlanningError: " + r["error"][:70]
        else:
            plans += 1
            near += r["length"] - r["lower"] <= 1
            answer = f"length {r['length']}, bound {r['lower']}, optimal {r['optimal']}"
        flag = "  <-- MISSED" if over > MAX_OVERSHOOT_S else ""
        bad += bool(flag)
        print(
            f"{name:42} {r['states']:6d} {r['wall']:7.2f} {r['cpu']:7.2f} {over:7.2f} "
            f"{r['peak_mb']:8.0f}  {answer}{flag}  (tolerance {r['mm']:.3g} mm, built in "
            f"{r['built']:.1f} s, {time.perf_counter() - start:.0f} s in all)",
            flush=True,
        )
    print(
        f"\nlargest overshoot {worst:.2f} s (allowed {MAX_OVERSHOOT_S:g} s); {plans} plans, "
        f"{near} within one operation of their bound; {time.perf_counter() - began:.0f} s"
    )
    for table, rows in tables.items():
        if rows:
            print(f"\n{table} cases, time limit {limit:g} s\n")
            print(markdown(rows))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
