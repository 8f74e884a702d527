"""The changeover report of a large mix: time, page size and memory, stage by stage.

    python benchmarks/bench_report.py [N ...]     # mixes of N random 6-10-gons (default 20 50)

For each N: ``feederkit plan`` over the mix's outline files at a 1 mm sensor (``--time-limit
30``, both landings of each part: 2 N members), then ``feederkit report`` of that plan file
in a fresh process (wall seconds, its peak resident memory, the page's size), and inside
one process the report's stages: the verification and certificate check
(``verify_declared``), the tree (``tree_html``) and the part plots. The baseline is reading
and writing the plan file as JSON (``json.loads`` then ``json.dumps``), measured in the same
run: what any consumer of the file pays. docs/reports.md explains the limits on the tree's
drawn states (``TREE_FIGURES``) and the part plots (``PART_PLOTS``).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from bench_planners import mix  # noqa: E402

from feederkit.outline import save_outline_json  # noqa: E402

CLI = "import sys; from feederkit.cli.app import main; sys.exit(main(sys.argv[1:]))"

STAGES = r"""
import json, sys, time
from feederkit.plans import read_plan
from feederkit.plans.verify import verify_declared
from feederkit.reports.report import member_rings
from feederkit.reports.trace import places, trace_plan
from feederkit.reports.tree_html import drawing_for, tree_html
from feederkit.reports.parts_html import PART_PLOTS, part_section
plan = read_plan(sys.argv[1])
out = {}
t = time.perf_counter(); verify_declared(plan); out["verify"] = time.perf_counter() - t
numbered = places(plan); trace = trace_plan(plan, numbered)
draw = drawing_for(plan, member_rings(plan, None))
t = time.perf_counter()
tree_html(plan, numbered, trace, draw)
out["tree"] = time.perf_counter() - t
t = time.perf_counter()
for i, p in enumerate(plan.parts):
    part_section(i, p, draw, None)
out["plots"] = time.perf_counter() - t
out["plots_drawn"] = min(len(plan.parts), PART_PLOTS)
print(json.dumps(out))
"""


def run(args: list[str]) -> tuple[float, int]:
    """Wall seconds and peak memory (MB) of ``feederkit ARGS`` in a fresh process."""
    t = time.perf_counter()
    proc = subprocess.run(
        ["/usr/bin/time", "-f", "%M", sys.executable, "-c", CLI, *args],
        capture_output=True,
        text=True,
        check=False,
    )
    wall = time.perf_counter() - t
    if proc.returncode not in (0, 1):
        raise SystemExit(f"feederkit {' '.join(args)} failed: {proc.stderr.strip()[-500:]}")
    peak_kb = int(proc.stderr.strip().splitlines()[-1])
    return wall, peak_kb // 1024


def main(argv: list[str]) -> int:
    sizes = [int(a) for a in argv] or [20, 50]
    print(
        f"{'mix':>5} {'members':>7} {'nodes':>6} {'plan MB':>7} {'json s':>7} {'report s':>8} "
        f"{'ratio':>7} {'page MB':>7} {'peak MB':>7} {'verify':>7} {'tree':>6} {'plots':>6}"
    )
    for n in sizes:
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            files = []
            for i, pf in enumerate(mix(n)):
                path = folder / f"m{i:03d}.json"
                save_outline_json(pf.part.outline, path)
                files.append(str(path))
            plan_file = folder / "p.json"
            run(["plan", *files, "--tolerance", "1.0", "--time-limit", "30", "-o", str(plan_file)])
            text = plan_file.read_text()
            t = time.perf_counter()
            json.dumps(json.loads(text))
            baseline = time.perf_counter() - t
            data = json.loads(text)
            page = folder / "r.html"
            wall, peak = run(["report", str(plan_file), "-o", str(page)])
            stages = json.loads(
                subprocess.run(
                    [sys.executable, "-c", STAGES, str(plan_file)],
                    capture_output=True,
                    text=True,
                    check=True,
                ).stdout
            )
            print(
                f"{n:5d} {len(data['parts']):7d} {len(data.get('nodes', [])):6d} "
                f"{len(text) / 1e6:7.1f} {baseline:7.3f} {wall:8.1f} {wall / baseline:6.0f}x "
                f"{page.stat().st_size / 1e6:7.1f} {peak:7d} {stages['verify']:7.1f} "
                f"{stages['tree']:6.1f} {stages['plots']:6.1f}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
