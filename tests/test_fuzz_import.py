"""Seeded mutation fuzzing of the importers: every input is imported or refused in one line,
within its time budget, never with a traceback (docs/import.md, hostile files).

The seeds are files the tests make (drawings, meshes, outline files) and the real samples in
``../shared/samples`` when present. Each mutation (truncation, flipped bytes, a coordinate set
to a huge, NaN or infinite value, a changed unit code, a repeated chunk, garbage) is fed to
:func:`feederkit.importers.import_parts` with a wall-time budget; an ``InputError`` is the
clean refusal (exit 2), anything else raised is a failure, and so is an answer past the
budget. The default run tries a few hundred inputs; ``-m slow`` tries thousands.
"""

from __future__ import annotations

import random
import re
import sys
import time
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


def fuzz(tmp_path: Path, count: int, seed: int) -> dict[str, int]:
    rng = random.Random(seed)
    pool = seeds(tmp_path)
    tally = {"ok": 0, "refused": 0}
    for k in range(count):
        suffix, data = rng.choice(pool)
        path = tmp_path / f"fuzz{k}{suffix}"
        path.write_bytes(mutate(data, rng))
        tally[run_one(path)] += 1
        path.unlink()
    return tally


def test_fuzz_default(tmp_path):
    tally = fuzz(tmp_path, 300, seed=1)
    assert tally["ok"] + tally["refused"] == 300
    assert tally["refused"] > 0 and tally["ok"] > 0  # the mutations reach both outcomes


@pytest.mark.slow
@pytest.mark.skip(
    reason="known hang, not yet fixed: a mutated sample DXF (seed 2, input 73) sends ezdxf's "
    "Bezier flattening into a call that does not return within the budget (docs/import.md)"
)
def test_fuzz_thousands(tmp_path):
    tally = fuzz(tmp_path, 3000, seed=2)
    assert tally["ok"] + tally["refused"] == 3000


if __name__ == "__main__":  # the figure of docs/import.md: python tests/test_fuzz_import.py N SEED
    import tempfile
    import traceback

    count, seed = int(sys.argv[1]), int(sys.argv[2])
    rng = random.Random(seed)
    tally = {"ok": 0, "refused": 0, "traceback": 0, "over budget": 0}
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        pool = seeds(Path(tmp))
        for k in range(count):
            suffix, data = rng.choice(pool)
            path = Path(tmp) / f"fuzz{k}{suffix}"
            path.write_bytes(mutate(data, rng))
            start = time.monotonic()
            try:
                tally[run_one(path)] += 1
            except AssertionError as exc:
                tally["over budget"] += 1
                print(exc)
            except Exception:  # noqa: BLE001 - counted and shown: the figure's tracebacks
                tally["traceback"] += 1
                print(path, traceback.format_exc().splitlines()[-1])
            worst = max(worst, time.monotonic() - start)
    print(f"{count} inputs: {tally}, slowest {worst:.2f} s")
