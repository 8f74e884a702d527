"""Benchmark: ``feederkit plan ... --time-limit T`` answers within the limit, end to end.

    python benchmarks/bench_command_deadline.py               # T = 10 s, every case
    python benchmarks/bench_command_deadline.py 25 mix        # T = 25 s, cases whose name has "mix"

``bench_deadline.py`` times the planner alone; a user times the command: Python's start,
reading the outlines, the planner, the plan file, its verification on mechanics rebuilt
from the file, the certificate, the ideal length, writing the file and drawing the plan in
the terminal. Each case writes its parts as outline files (as a user would have them), runs
the command in a fresh process and reads the plan file back. Per case: the limit, the
command's wall seconds from process start and the overshoot (wall - T), peak memory, the
plan's length and proven bound, whether the certificate was cut (its figures are then the
declared values, and a warning says so), and the plan's nodes as the file reads back
(each operation once, each result per place: ``Plan.walk``).

The baseline in the same run is Python's start with feederkit's command line imported
(``feederkit --help``): the command counts its limit from its process's start
(docs/planning.md, "The command's limit"), so that start is inside the limit, not past it.
Exit code 1 when an overshoot exceeds ``MAX_OVERSHOOT_S``, or a case crashes.
"""

from __future__ import annotations

import json
import math
import random
import subprocess
import sys
import tempfile
from pathlib import Path

from feederkit.plans.readplan import read_plan

MAX_OVERSHOOT_S = 2.5
"""The command may end this many seconds past its limit (counted from its process's start)."""

# name -> (parts, tolerance in % of the largest part's size, extra options)
CASES: dict[str, tuple[str, float, tuple[str, ...]]] = {
    "5-part mix, 3%": ("mix(5)", 3.0, ("--landings", "up")),
    "20-part mix, 1%": ("mix(20)", 1.0, ("--landings", "up")),
    "20-part mix, 5%": ("mix(20)", 5.0, ("--landings", "up")),
    "20-part mix, 5%, both landings": ("mix(20)", 5.0, ()),
    "50-part mix, 1%": ("mix(50)", 1.0, ("--landings", "up")),
    "50-part mix, 3%": ("mix(50)", 3.0, ("--landings", "up")),
    "50-part mix, 5%": ("mix(50)", 5.0, ("--landings", "up")),
    "100-part mix, 0.5%": ("mix(100)", 0.5, ("--landings", "up")),
    "random 1000-point outline, 3%, ideal": (
        "[random_outline(1000, 1)]",
        3.0,
        ("--rotation-error", "0"),
    ),
    "random 200-point outline, 1%": ("[random_outline(200, 4)]", 1.0, ()),
    # Both landings of a near-round part whose diameters read alike: a sensorless problem.
    "near-round 64-gon 1%, 3%, ideal": ("[near_round(64, 0.01)]", 3.0, ("--rotation-error", "0")),
}


def mix(count: int) -> list[dict]:
    """bench_planners.mix as outline files' objects: random convex 6-10-gons, 60 x 40 mm."""
    out = []
    for s in range(count):
        n = random.Random(s).randint(6, 10)
        rng = random.Random(100 + s)
        angles = sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n))
        pts = [[30 * math.cos(t), 20 * math.sin(t)] for t in angles]
        out.append({"name": f"mix-{s}", "units": "mm", "vertices": pts})
    return out


def random_outline(n: int, seed: int) -> dict:
    """bench_deadline.random_outline: the hull of n points at random radii 21-30 mm."""
    rng = random.Random(seed)
    pts = []
    for t in sorted(rng.uniform(0.0, 2 * math.pi) for _ in range(n)):
        f = 30.0 * rng.uniform(0.7, 1.0)
        pts.append([f * math.cos(t), f * math.sin(t)])
    return {"name": f"rand-{n}-{seed}", "units": "mm", "vertices": pts}


def near_round(n: int, noise: float, seed: int = 0, r: float = 10.0) -> dict:
    """bench_planners.near_round: a regular n-gon of radius r mm with radial noise."""
    rng = random.Random(seed)
    pts = []
    for k in range(n):
        a, f = 2 * math.pi * k / n, 1 + rng.uniform(-noise, noise)
        pts.append([r * f * math.cos(a), r * f * math.sin(a)])
    return {"name": f"round-{n}", "units": "mm", "vertices": pts}


def size_of(outline: dict) -> float:
    """The larger side of an outline's bounding box (mm)."""
    xs = [p[0] for p in outline["vertices"]]
    ys = [p[1] for p in outline["vertices"]]
    return max(max(xs) - min(xs), max(ys) - min(ys))


def feederkit() -> list[str]:
    """The command, from this checkout's environment."""
    exe = Path(sys.executable).with_name("feederkit")
    return (
        [str(exe)]
        if exe.exists()
        else [sys.executable, "-c", "from feederkit.cli.app import run; run()"]
    )


WRAP = r"""
import json, resource, subprocess, sys, time
start = time.perf_counter()
p = subprocess.run(sys.argv[2:], capture_output=True, text=True, timeout=float(sys.argv[1]))
wall = time.perf_counter() - start
peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
print(json.dumps({"wall": wall, "peak": peak, "code": p.returncode, "stderr": p.stderr}))
"""


def timed(args: list[str], timeout: float) -> tuple[float, float, int, str]:
    """Wall seconds, peak memory (MB), exit code and stderr of one command, measured by a
    small parent process of its own (so the peak is this command's alone)."""
    p = subprocess.run(
        [sys.executable, "-c", WRAP, str(timeout), *args],
        capture_output=True,
        text=True,
        timeout=timeout + 30,
    )
    if p.returncode != 0:
        raise subprocess.TimeoutExpired(args, timeout)
    r = json.loads(p.stdout)
    return r["wall"], r["peak"], r["code"], r["stderr"]


def file_nodes(path: Path) -> int:
    """The plan's nodes as the file reads back: each operation once (a shared one too), each
    result per place (``Plan.walk``)."""
    return sum(1 for _node in read_plan(path).walk())


def run_case(name: str, limit: float, folder: Path) -> dict:
    """One case: write its outlines, run the command, read the plan file."""
    expr, percent, extra = CASES[name]
    outlines = eval(expr)  # the module's own generators
    paths = []
    for k, o in enumerate(outlines):
        path = folder / f"{k:03d}-{o['name']}.json"
        path.write_text(json.dumps(o), encoding="utf-8")
        paths.append(str(path))
    tol = percent / 100.0 * max(size_of(o) for o in outlines)
    out = folder / "plan.json"
    out.unlink(missing_ok=True)
    args = feederkit() + ["plan", *paths, "--tolerance", f"{tol:.6g}", "--time-limit", f"{limit:g}"]
    args += [*extra, "-o", str(out)]
    try:
        wall, peak, code, stderr = timed(args, 3 * limit + 60)
    except subprocess.TimeoutExpired:
        return {"missed": "killed"}
    r: dict = {"wall": wall, "peak_mb": peak, "code": code, "mm": tol}
    if out.exists():
        plan = json.loads(out.read_text(encoding="utf-8"))
        stats = plan["stats"]
        r.update(length=stats["length"], lower=stats["lower_bound"], optimal=stats["optimal"])
        r["nodes"] = file_nodes(out)
        r["cut"] = "whole certificate" in stderr
    else:
        lines = [x for x in stderr.strip().splitlines() if not x.startswith("warning")]
        r["error"] = (lines or ["?"])[-1]
    return r


def main(argv: list[str]) -> int:
    if argv and argv[0].replace(".", "", 1).isdigit():
        limit, wanted = float(argv[0]), argv[1:]
    else:
        limit, wanted = 10.0, argv
    start_s = min(timed(feederkit() + ["--help"], 60)[0] for _ in range(3))
    print(f"time limit {limit:g} s; the command's start (feederkit --help): {start_s:.2f} s")
    head = f"{'case':40} {'wall s':>7} {'over s':>7} {'peak MB':>8} {'nodes':>6}  answer"
    print(head)
    rows, bad = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for name in CASES:
            if wanted and not any(w in name for w in wanted):
                continue
            folder = Path(tmp) / str(len(rows))
            folder.mkdir()
            r = run_case(name, limit, folder)
            if "missed" in r:
                print(f"{name:40} {r['missed']}  <-- MISSED", flush=True)
                bad += 1
                continue
            over = r["wall"] - limit
            flag = "  <-- MISSED" if over > MAX_OVERSHOOT_S else ""
            bad += bool(flag)
            if "error" in r:
                answer = r["error"][:70]
            else:
                answer = f"length {r['length']}, bound {r['lower']}"
                answer += ", optimal" if r["optimal"] else ""
                answer += ", certificate cut" if r["cut"] else ""
            nodes = r.get("nodes", "-")
            print(
                f"{name:40} {r['wall']:7.2f} {over:+7.2f} {r['peak_mb']:8.0f} {nodes:>6}  "
                f"{answer}{flag}",
                flush=True,
            )
            rows.append((name, r, over))
    print("\n| case | wall s | over s | peak MB | plan nodes | answer |")
    print("| --- |" + " ---: |" * 4 + " --- |")
    for name, r, over in rows:
        if "error" in r:
            answer = r["error"][:60]
        else:
            answer = f"{r['length']} / bound {r['lower']}" + (", cert. cut" if r["cut"] else "")
        print(
            f"| {name} | {r['wall']:.2f} | {over:+.2f} | {r['peak_mb']:.0f} | "
            f"{r.get('nodes', '-')} | {answer} |"
        )
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
