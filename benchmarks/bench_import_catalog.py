"""Benchmarks of issue 4: DXF import and catalog speed, measured against the issue's targets.

Run: python benchmarks/bench_import_catalog.py [--parts 10000] [--teeth 30 --flank-lines 199]

* a 12,000-entity DXF (a fine gear: tip and root arcs, involute flanks as lines) imports in
  under 2 s (read, explode, flatten, loops, hull simplification, orientability);
* a 10,000-part catalog lists in under 1 s (library call, and ``catalog list`` / ``--json``);
* ``catalog show NAME`` answers in under 50 ms (library call; the command in a running
  process; and ``main()``, which also rebuilds typer's tree of every command on each call).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import ezdxf
import typer

from feederkit.catalog import get_revision, list_parts, open_catalog
from feederkit.catalog.schema import transaction
from feederkit.catalog.store import write_revision
from feederkit.cli.app import app, main
from feederkit.importers import ImportedOutline, ImportOptions, build_part, import_parts
from feederkit.importers.budget import ImportLimits
from feederkit.outline import make_outline


def fine_gear(path: Path, teeth: int, flank_lines: int = 19) -> int:
    """Write a gear of ``teeth`` teeth (module 1) with 2 + 2 * flank_lines entities per tooth."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    r_pitch = teeth / 2.0
    r_tip, r_root = r_pitch + 1.0, r_pitch - 1.25
    r_base = r_pitch * math.cos(math.radians(20))
    pitch = 2 * math.pi / teeth

    def involute(t: float) -> tuple[float, float]:
        return r_base * (math.cos(t) + t * math.sin(t)), r_base * (math.sin(t) - t * math.cos(t))

    t_tip = math.sqrt((r_tip / r_base) ** 2 - 1)
    t_root = math.sqrt(max((max(r_root, r_base) / r_base) ** 2 - 1, 0.0))
    ts = [t_root + (t_tip - t_root) * k / flank_lines for k in range(flank_lines + 1)]
    flank = [involute(t) for t in ts]
    half = pitch / 4 + (math.tan(math.radians(20)) - math.radians(20))
    start = [(math.hypot(x, y), math.atan2(y, x)) for x, y in flank]

    def pt(r: float, a: float) -> tuple[float, float]:
        return (r * math.cos(a), r * math.sin(a))

    count = 0
    for k in range(teeth):
        c = k * pitch
        right = [pt(r, c - half + a) for r, a in start]
        left = [pt(r, c + half - a) for r, a in start]
        for p, q in zip(right, right[1:], strict=False):
            msp.add_line(p, q)
        for p, q in zip(left, left[1:], strict=False):
            msp.add_line(p, q)
        a_tip = math.degrees(math.atan2(right[-1][1], right[-1][0]))
        b_tip = math.degrees(math.atan2(left[-1][1], left[-1][0]))
        msp.add_arc((0, 0), r_tip, a_tip, b_tip)
        a_root = math.degrees(c + half - start[0][1])
        b_root = math.degrees(c + pitch - half + start[0][1])
        msp.add_arc((0, 0), math.hypot(*left[0]), a_root, b_root)
        count += 2 * flank_lines + 2
    doc.saveas(path)
    return count


def timed(fn, repeat: int) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), result


def quiet_main(args: list[str]) -> int:
    with contextlib.redirect_stdout(io.StringIO()):
        return main(args)


def prebuilt_command():
    """The click command of the app, built once (as a long-running process keeps it)."""
    command = typer.main.get_command(app)

    def call(args: list[str]) -> None:
        with contextlib.redirect_stdout(io.StringIO()):
            command.main(args=args, prog_name="feederkit", standalone_mode=False)

    return call


def fill_catalog(db: Path, parts: int, seed: int = 1) -> None:
    """``parts`` random convex 6- to 10-gons, written in one transaction."""
    rng = random.Random(seed)
    options = ImportOptions()
    conn = open_catalog(db, create=True)
    try:
        with transaction(conn):
            for i in range(parts):
                n = rng.randint(6, 10)
                angles = sorted(rng.uniform(0, 2 * math.pi) for _ in range(n))
                r = rng.uniform(10, 60)
                verts = [(r * math.cos(a), r * math.sin(a)) for a in angles]
                outline = make_outline(f"part-{i:05d}", verts)
                try:
                    imported = build_part(
                        ImportedOutline(outline=outline, kind="outline", source_units="mm"), options
                    )
                except Exception:  # noqa: BLE001 - a random COM on the hull: skip that shape
                    continue
                write_revision(
                    conn,
                    imported,
                    source_path=f"/bench/part-{i:05d}.json",
                    sha256=f"{i:064x}",
                    options_key=options.as_key(),
                )
    finally:
        conn.close()


def report(label: str, seconds: float, target: float) -> bool:
    ok = seconds < target
    print(
        f"{label:<52} {seconds * 1000:9.1f} ms   target < {target * 1000:.0f} ms   "
        f"{'PASS' if ok else 'FAIL'}"
    )
    return ok


def run(parts: int, teeth: int, flank_lines: int) -> int:
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        tmpdir = Path(tmp)
        gear = tmpdir / "fine-gear.dxf"
        entities = fine_gear(gear, teeth, flank_lines)
        # The default import budget stops at 10,000 entities (--max-entities): the gear is
        # imported as a user would after raising it.
        options = ImportOptions(limits=ImportLimits(entities=2 * entities))
        seconds, result = timed(lambda: import_parts(gear, options), 3)
        ip = result[1][0]
        print(
            f"fine gear: {entities} entities, {len(ip.part.outline.vertices)} outline points, "
            f"hull {len(ip.part.hull)} vertices, {ip.orientability.useful_states} useful states"
        )
        ok &= report(f"import a {entities}-entity DXF", seconds, 2.0)

        db = tmpdir / "big.db"
        t = time.perf_counter()
        fill_catalog(db, parts)
        print(f"catalog of {len(list_parts(db))} parts filled in {time.perf_counter() - t:.1f} s")
        seconds, listed = timed(lambda: list_parts(db), 5)
        ok &= report(f"list_parts() of {len(listed)} parts", seconds, 1.0)
        seconds, _ = timed(
            lambda: quiet_main(["catalog", "list", "--json", "--catalog", str(db)]), 3
        )
        ok &= report("feederkit catalog list --json (in process)", seconds, 1.0)
        seconds, _ = timed(lambda: quiet_main(["catalog", "list", "--catalog", str(db)]), 3)
        ok &= report("feederkit catalog list (table, in process)", seconds, 1.0)
        name = listed[len(listed) // 2].name
        seconds, _ = timed(lambda: get_revision(db, name), 20)
        ok &= report("get_revision() (open catalog, read one part)", seconds, 0.05)
        call = prebuilt_command()
        show = ["catalog", "show", name, "--catalog", str(db)]
        seconds, _ = timed(lambda: call([*show, "--json"]), 20)
        ok &= report("catalog show NAME --json (command, running process)", seconds, 0.05)
        seconds, _ = timed(lambda: call(show), 20)
        ok &= report("catalog show NAME (table, running process)", seconds, 0.05)
        seconds, _ = timed(lambda: quiet_main([*show, "--json"]), 5)
        print(f"{'main(show --json), typer tree rebuilt per call':<52} {seconds * 1000:9.1f} ms")
        cmd = [sys.executable, "-c", "from feederkit.cli.app import run; run()"]
        seconds, _ = timed(lambda: subprocess.run([*cmd, *show, "--json"], capture_output=True), 3)
        print(f"{'cold process: feederkit catalog show NAME --json':<52} {seconds * 1000:9.1f} ms")
    print("all targets met" if ok else "some targets missed")
    return 0 if ok else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parts", type=int, default=10_000)
    parser.add_argument("--teeth", type=int, default=30)
    parser.add_argument("--flank-lines", type=int, default=199)
    args = parser.parse_args()
    print(f"load average before the run: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    sys.exit(run(args.parts, args.teeth, args.flank_lines))
