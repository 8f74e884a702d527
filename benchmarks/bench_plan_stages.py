"""Where one ``plan`` call spends its CPU seconds, stage by stage, and its peak memory.

    python benchmarks/bench_plan_stages.py                 # the 50-part mix at 3 %, ideal
    python benchmarks/bench_plan_stages.py "mix(20)|2%"    # any "parts|tolerance" case

A case is ``bench_planners.mix(N)`` (random 6-10-gons on a 60 x 40 mm ellipse) and a
tolerance in % of the largest part's size, on the ideal model (as ``bench_planners.py``);
``plan`` runs with default options (no time limit; the tie-breaking stages under their
work budget, docs/planning.md). Printed per stage: the goal relation (``goal_relation``),
the length proof (``longest_root``), the margin stage (``stage``), the tree with its
remaining tie-breaks (``_build``: the expected-operations choice, or, when that runs out,
the tree that follows the margin probes' plans), the result's statistics (``_result``);
then the whole call, its length, ``tie_breaks``, smallest margin (degrees) and the peak
resident memory of the process. Each case
runs in its own process so that the peaks do not mix.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
STAGES = ("goal_relation", "longest_root", "stage", "_build", "_result")
DEFAULT_CASES = ("mix(50)|3%",)

CHILD = r"""
import json, resource, sys, time
sys.path.insert(0, sys.argv[2])
import bench_planners as bp
import feederkit.planning.api as api
from feederkit.machine import build_machine
from feederkit.sensors import ToleranceSensor
from feederkit.uncertainty import IDEAL

spent = {}
for name in json.loads(sys.argv[3]):
    fn = getattr(api, name)
    def clocked(*a, _fn=fn, _name=name, **k):
        t = time.process_time()
        try:
            return _fn(*a, **k)
        finally:
            spent[_name] = spent.get(_name, 0.0) + time.process_time() - t
    setattr(api, name, clocked)
expr, tol = sys.argv[1].split("|")
pfs = eval(expr, {"mix": bp.mix})
size = max(pf.part.size for pf in pfs)
machine = build_machine(pfs, ToleranceSensor(float(tol.rstrip("%")) / 100.0 * size), IDEAL)
t = time.process_time()
r = api.plan(machine)
print(json.dumps({"states": machine.n, "cpu": time.process_time() - t, "stages": spent,
                  "length": r.length, "ties": r.tie_breaks, "margin": r.min_margin,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def main(argv: list[str]) -> int:
    cases = argv or list(DEFAULT_CASES)
    tail = " | plan CPU s | length | ties | margin | peak MB"
    print("case | states | " + " | ".join(STAGES) + tail)
    for case in cases:
        p = subprocess.run(
            [sys.executable, "-c", CHILD, case, str(HERE), json.dumps(STAGES)],
            capture_output=True,
            text=True,
        )
        if p.returncode != 0:
            print(f"{case}: failed: {(p.stderr.strip().splitlines() or ['?'])[-1]}")
            return 1
        r = json.loads(p.stdout.strip().splitlines()[-1])
        cells = " | ".join(f"{r['stages'].get(s, 0.0):.2f}" for s in STAGES)
        print(
            f"{case} | {r['states']} | {cells} | {r['cpu']:.2f} | {r['length']} | "
            f"{r['ties']} | {r['margin']:.6g} | {r['peak_mb']:.0f}",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
