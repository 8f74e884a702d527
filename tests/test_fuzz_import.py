"""Seeded mutation fuzzing of the importers: every input is imported or refused in one line,
within its time budget, never with a traceback (docs/import.md, hostile files).

The seeds are files the tests make (drawings, meshes, outline files) and the real samples in
``../shared/samples`` when present. Each mutation (truncation, flipped bytes, a coordinate set
to a huge, NaN or infinite value, a changed unit code, a repeated chunk, garbage) is fed to
:func:`feederkit.importers.import_parts` with a wall-time budget, in a forked child; an
``InputError`` is the clean refusal (exit 2), anything else raised is a failure, and so are
an answer past the budget and a child that never answers (killed: a hang fails the run, it
does not stop it).
The default run tries a hundred inputs (the mutations reach every importer); ``-m slow``
tries thousands.
"""

from __future__ import annotations

import json
import os
import random
import re
import select
import signal
import sys
import time
import traceback
from pathlib import Path

import fixtures_cad as fx
import pytest
import trimesh

from feederkit.errors import InputError
from feederkit.importers import ImportOptions, import_parts
from feederkit.importers.budget import ImportLimits

SAMPLES = Path(__file__).resolve().parents[1].parent / "shared" / "samples"
SMALL_SAMPLES = ("cadquery__vslot-2020_1.dxf", "trimesh__sliding-base.dxf",
                 "trimesh__1002_tray_bottom.DXF", "trimesh__apu-mount.DXF",
                 "trimesh__angle_block.STL")  # fmt: skip

BUDGET_S = 3.0
"""The importer's own wall-time budget per input in this test."""

SLACK_S = 3.0
"""What a single uninterruptible step may add to the budget before the test fails."""

NUMBER = re.compile(rb"-?\d+\.\d+")
HOSTILE_VALUES = (b"1e20", b"1e300", b"1.8e308", b"1e400", b"inf", b"nan", b"-1e308", b"0")


def seeds(directory: Path) -> list[tuple[str, bytes]]:
    """(suffix, content) of the seed files: made here, plus the small real samples."""
    made = [
        fx.write_plate(directory / "plate.dxf"),
        fx.write_plate(directory / "plate12.dxf", version="R12"),
        fx.write_framed(directory / "framed.dxf"),
        fx.write_cut_sheet(directory / "sheet.dxf"),
        fx.write_gap_spline(directory / "gap.dxf", 0.1),
        fx.write_nested_mirrored(directory / "nested.dxf"),
        fx.write_gear(directory / "gear.dxf", teeth=8),
        fx.write_minsert(directory / "grid.dxf", 3, 3),
        fx.write_mesh(trimesh.creation.box((10, 20, 30)), directory / "box.stl"),
        fx.write_mesh(trimesh.creation.box((10, 20, 30)), directory / "box.obj"),
        fx.write_mesh(trimesh.creation.box((10, 20, 30)), directory / "box.ply"),
        fx.write_mesh(fx.hollow_box(20, 6, (4, 0, 0)), directory / "hollow.stl"),
    ]
    outline = directory / "part.json"
    outline.write_text(
        '{"name": "part", "units": "mm", "vertices": [[0, 0], [40, 0], [40, 20], [0, 20]],'
        ' "holes": [[[5, 5], [10, 5], [10, 10]]], "com": [20.5, 10.0]}'
    )
    made.append(outline)
    out = [(p.suffix, p.read_bytes()) for p in made]
    if SAMPLES.is_dir():
        out += [(Path(n).suffix, (SAMPLES / n).read_bytes()) for n in SMALL_SAMPLES]
    return out


def mutate(data: bytes, rng: random.Random) -> bytes:
    """One random mutation of ``data`` (the kinds a tester of a CAD importer tries)."""
    kind = rng.randrange(7)
    if kind == 0 and data:  # truncated
        return data[: rng.randrange(len(data))]
    if kind == 1 and data:  # bytes flipped
        buf = bytearray(data)
        for _ in range(rng.randint(1, 20)):
            buf[rng.randrange(len(buf))] = rng.randrange(256)
        return bytes(buf)
    if kind == 2:  # coordinates set to hostile values
        numbers = list(NUMBER.finditer(data))
        if numbers:
            buf = bytearray(data)
            for m in sorted(rng.sample(numbers, min(len(numbers), rng.randint(1, 5))),
                            key=lambda m: -m.start()):  # fmt: skip
                buf[m.start() : m.end()] = rng.choice(HOSTILE_VALUES)
            return bytes(buf)
    if kind == 3:  # units changed
        code = str(rng.choice([0, 1, 2, 3, 6, 7, 13, 99, -1])).encode()
        return re.sub(rb"(\$INSUNITS\r?\n\s*70\r?\n\s*)-?\d+", rb"\g<1>" + code, data)
    if kind == 4 and data:  # a chunk repeated
        a = rng.randrange(len(data))
        b = min(len(data), a + rng.randint(1, 4000))
        return data[:b] + data[a:b] * rng.randint(2, 50) + data[b:]
    if kind == 5:  # garbage
        return bytes(rng.randrange(256) for _ in range(rng.randint(0, 3000)))
    return data.replace(b"\n", b"\r\n") if rng.random() < 0.5 else data[::-1]


def run_one(path: Path) -> str:
    """``ok`` or ``refused``; fails on any other exception or an answer past the budget."""
    options = ImportOptions(limits=ImportLimits(seconds=BUDGET_S))
    start = time.monotonic()
    try:
        import_parts(path, options)
        outcome = "ok"
    except InputError as exc:
        message = str(exc)
        assert message and "\n" not in message.strip(), f"{path}: not one line: {message!r}"
        assert "Traceback" not in message
        outcome = "refused"
    elapsed = time.monotonic() - start
    assert elapsed < BUDGET_S + SLACK_S, f"{path}: answered after {elapsed:.1f} s"
    return outcome


HANG_S = BUDGET_S + SLACK_S + 30.0
"""A child that has not answered after this long is killed and its input counted as a hang."""


def run_isolated(path: Path) -> tuple[str, str]:
    """(outcome, detail) of :func:`run_one` in a forked child, killed after :data:`HANG_S`.

    Outcomes: ``ok``, ``refused``, ``traceback`` (any other exception), ``over budget``
    (answered past the budget or not in one line) and ``hang``: an uninterruptible call that
    never returns fails the run instead of stopping it. Without ``os.fork`` it runs here.
    """
    if not hasattr(os, "fork"):  # pragma: no cover - Windows
        return _outcome(path)
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: answer through the pipe, then leave without cleanup
        os.close(read)
        try:
            os.write(write, json.dumps(_outcome(path)).encode())
        finally:
            os._exit(0)
    os.close(write)
    try:
        ready, _, _ = select.select([read], [], [], HANG_S)
        if not ready:
            os.kill(pid, signal.SIGKILL)
            return "hang", f"{path}: no answer after {HANG_S:g} s"
        data = b""
        while chunk := os.read(read, 65536):
            data += chunk
    finally:
        os.close(read)
        os.waitpid(pid, 0)
    if not data:
        return "traceback", f"{path}: the importer died"
    outcome, detail = json.loads(data)
    return outcome, detail


def _outcome(path: Path) -> tuple[str, str]:
    try:
        return run_one(path), ""
    except AssertionError as exc:
        return "over budget", str(exc)
    except Exception:  # noqa: BLE001 - counted and shown: what the test exists to find
        return "traceback", f"{path}: {traceback.format_exc().splitlines()[-1]}"


def fuzz(directory: Path, count: int, seed: int) -> tuple[dict[str, int], list[str], float]:
    """Tally of ``count`` mutated inputs, what went wrong (inputs kept), and the slowest time."""
    rng = random.Random(seed)
    pool = seeds(directory)
    tally = dict.fromkeys(("ok", "refused", "traceback", "over budget", "hang"), 0)
    failures: list[str] = []
    slowest = 0.0
    for k in range(count):
        suffix, data = rng.choice(pool)
        path = directory / f"fuzz{k}{suffix}"
        path.write_bytes(mutate(data, rng))
        start = time.monotonic()
        outcome, detail = run_isolated(path)
        slowest = max(slowest, time.monotonic() - start)
        tally[outcome] += 1
        if outcome in ("ok", "refused"):
            path.unlink()
        else:  # kept in the test's directory to reproduce
            failures.append(f"input {k} ({outcome}): {detail}")
    return tally, failures, slowest


def test_fuzz_default(tmp_path):
    tally, failures, _ = fuzz(tmp_path, 100, seed=1)
    assert not failures, failures[:5]
    assert tally["ok"] + tally["refused"] == 100
    assert tally["refused"] > 0 and tally["ok"] > 0  # the mutations reach both outcomes


@pytest.mark.slow
def test_fuzz_thousands(tmp_path):
    tally, failures, slowest = fuzz(tmp_path, 3000, seed=2)
    print(f"3000 inputs: {tally}, slowest {slowest:.2f} s")  # the figure, with pytest -s
    assert not failures, failures[:5]
    assert tally["ok"] + tally["refused"] == 3000


if __name__ == "__main__":  # the figure of docs/import.md: python tests/test_fuzz_import.py N SEED
    import tempfile

    count, seed = int(sys.argv[1]), int(sys.argv[2])
    with tempfile.TemporaryDirectory() as tmp:
        tally, failures, slowest = fuzz(Path(tmp), count, seed)
    for line in failures:
        print(line)
    print(f"{count} inputs: {tally}, slowest {slowest:.2f} s")
