"""LED arrays: which beam pitches make a mix recognizable, evaluated one pitch at a time.

Beam grids of different pitches are not nested (beams at multiples of 0.3 mm are not a subset
of those at multiples of 0.2 mm), so recognizability and plan length need not be monotone in
the pitch: each pitch in the list is decided on its own with the exact pair test
(:func:`feederkit.mix.pairs.unrecognizable_pairs`) and, when the mix is recognizable, a
verified optimal plan (:func:`feederkit.plans.make.make_plan`). Under a declared uncertainty
each pitch is decided for strong plans (:func:`feederkit.design.strong.strong_pitch`: pairs
of parts with bisimilar states, then a verified strong plan, or "no strong plan").
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass, replace

from feederkit.design.critical import planned_machine, rejected_of
from feederkit.design.limit import PITCHES, DesignClock
from feederkit.design.strong import StrongMix, strong_pitch
from feederkit.errors import InputError
from feederkit.machine import PushAlignMachine, members
from feederkit.machine.inseparable import inseparable_masks
from feederkit.machine.widths import Offsets, widens
from feederkit.mechanics.modelerror import part_offsets
from feederkit.mechanics.push import PushFunction
from feederkit.mix.changeover import reported_pairs
from feederkit.mix.pairs import unrecognizable_pairs
from feederkit.plans.make import make_plan
from feederkit.plans.model import PlanMember
from feederkit.sensors import LedSensor
from feederkit.uncertainty import IDEAL


@dataclass(frozen=True)
class PitchRow:
    """One LED pitch (mm): whether the mix is recognizable with it and, if so, its plan.

    ``unrecognizable``: the pairs of parts (names) that this pitch cannot tell apart.
    ``no_plan``: why there is no plan although every pair reads apart (under a declared
    uncertainty: no strong plan exists at this pitch), else None.
    """

    pitch: float
    noise: float
    unrecognizable: tuple[tuple[str, str], ...]
    length: int | None = None
    expected: float | None = None
    no_plan: str | None = None

    @property
    def recognizable(self) -> bool:
        """Whether a (strong) plan recognizes the mix with this pitch."""
        return not self.unrecognizable and self.no_plan is None

    def to_dict(self) -> dict[str, object]:
        """``{"pitch_mm", "noise_mm", "recognizable", "length", "expected", "unrecognizable",
        "no_plan"}``."""
        return {
            "pitch_mm": self.pitch,
            "noise_mm": self.noise,
            "recognizable": self.recognizable,
            "length": self.length,
            "expected": self.expected,
            "unrecognizable": [list(p) for p in self.unrecognizable],
            "no_plan": self.no_plan,
        }


def pitch_row(
    pfs: Sequence[PushFunction],
    pitch: float,
    noise: float,
    mix: StrongMix | None = None,
    clock: DesignClock | None = None,
    members: Sequence[PlanMember] | None = None,
    widened: PushAlignMachine | None = None,
) -> PitchRow:
    """Decide one pitch: the exact pair test, then a verified plan when it recognizes the mix
    (for strong plans at ``mix``'s uncertainty when given, with ``mix``'s members), within
    ``clock``'s limit. ``members`` (the ideal model's) as
    :func:`~feederkit.plans.make.make_plan` takes them: two rejected members need not be
    told apart (:func:`~feederkit.mix.changeover.reported_pairs`). ``widened``: the ideal
    machine the planner plans on when it reads some part over its own widths
    (:func:`~feederkit.design.critical.planned_machine`); the pair test is then its
    (:func:`widened_pairs`)."""
    clock = clock or DesignClock()
    sensor = LedSensor(pitch, noise)
    if mix is not None:
        got = strong_pitch(mix, sensor, clock)
        if got.unrecognizable or got.no_plan is not None:
            return PitchRow(pitch, noise, got.unrecognizable, no_plan=got.no_plan)
        return PitchRow(pitch, noise, (), got.length, got.expected)
    rejected = rejected_of(members)
    if widened is not None:
        bad = widened_pairs(widened, sensor, rejected, clock)
    else:
        out = [pf.part.name for k, pf in enumerate(pfs) if k in rejected]
        pairs = reported_pairs(unrecognizable_pairs(list(pfs), sensor), out)
        bad = tuple((w.part_a, w.part_b) for w in pairs)
    if bad:
        return PitchRow(pitch, noise, bad)
    clock.check()
    result = clock.plan(
        lambda opts: make_plan(list(pfs), sensor, opts, uncertainty=IDEAL, members=members)
    ).result
    return PitchRow(pitch, noise, (), result.length, result.expected_length)


def widened_pairs(
    machine: PushAlignMachine,
    sensor: LedSensor,
    rejected: Collection[int] = (),
    clock: DesignClock | None = None,
) -> tuple[tuple[str, str], ...]:
    """The pairs of parts (names, in part order) with inseparable states in ``machine`` read
    by ``sensor`` (the fixpoint of section 8.4 over its reading intervals), but two rejected
    members'."""
    check = None if clock is None else clock.check
    masks = inseparable_masks(replace(machine, sensor=sensor), check)
    states = machine.states
    bad = sorted(
        {
            (states[i].part, states[j].part)
            for i in range(machine.n)
            for j in members(masks[i])
            if states[i].part < states[j].part
            and not (states[i].part in rejected and states[j].part in rejected)
        }
    )
    names = machine.part_names
    return tuple((names[a], names[b]) for a, b in bad)


def pitch_rows(
    pfs: Sequence[PushFunction],
    pitches: Sequence[float],
    noise: float,
    mix: StrongMix | None = None,
    clock: DesignClock | None = None,
    members: Sequence[PlanMember] | None = None,
    offsets: Offsets | None = None,
) -> tuple[PitchRow, ...]:
    """Every pitch of the list, ascending, each decided on its own (for strong plans at
    ``mix``'s uncertainty when given, else on the ideal model, for ``members``:
    :func:`pitch_row`); ``clock`` (:mod:`feederkit.design.limit`) is polled and told of
    each pitch decided. ``offsets``: the parts' reading offsets on the ideal model (default
    :func:`~feederkit.mechanics.modelerror.part_offsets`); where they widen a state the pairs are
    decided on the machine the planner plans on."""
    clock = clock or DesignClock()
    widened = None
    if mix is None:
        offsets = part_offsets(pfs) if offsets is None else offsets
        if widens(offsets):
            machine, wide = planned_machine(pfs, offsets)
            widened = machine if wide else None
    ordered = sorted(set(pitches))
    clock.begin(PITCHES, len(ordered))
    rows = []
    for p in ordered:
        clock.check()
        rows.append(pitch_row(pfs, p, noise, mix, clock, members, widened))
        clock.advance()
    return tuple(rows)


def parse_pitches(text: str) -> tuple[float, ...]:
    """``--pitches``: a list ``0.1,0.2,0.5`` or a range ``START:STOP:STEP`` (STOP included).

    InputError for an empty list or item, a value that is not a positive number, or a bad
    range.
    """
    items = [t.strip() for t in text.split(",")]
    if not any(items):
        raise InputError("--pitches is empty: give pitches in mm, e.g. 0.1,0.2,0.5 or 0.1:1:0.1")
    if not all(items):
        raise InputError(f"--pitches: an empty item in {text!r} (write 0.1,0.2, not 0.1,,0.2)")
    out: list[float] = []
    for item in items:
        if ":" in item:
            out.extend(_range(item))
            continue
        out.append(_positive(item))
    return tuple(sorted(set(out)))


def _number(item: str) -> float:
    """A finite number of mm; InputError otherwise."""
    try:
        v = float(item)
    except ValueError:
        raise InputError(f"--pitches: {item!r} is not a number of mm") from None
    if not math.isfinite(v):
        raise InputError(f"--pitches: a pitch must be a finite number of mm, got {item}")
    return v


def _positive(item: str) -> float:
    """A pitch: a positive finite number of mm; InputError otherwise."""
    v = _number(item)
    if v <= 0.0:
        raise InputError(f"--pitches: a pitch must be a positive number of mm, got {item}")
    return v


def _range(item: str) -> list[float]:
    """``START:STOP:STEP``, STOP included. START above STOP is said first: ``1:0:0.5`` is an
    empty range, not a zero pitch."""
    parts = item.split(":")
    if len(parts) != 3:
        raise InputError(f"--pitches: a range is START:STOP:STEP, got {item!r}")
    start, stop, step = (_number(p) for p in parts)
    if stop < start:
        raise InputError(
            f"--pitches: the range {item!r} is empty, it ends before it starts: START "
            f"{parts[0].strip()} is above STOP {parts[1].strip()} (write START:STOP:STEP)"
        )
    start = _positive(parts[0])  # then STOP >= START is positive too
    if step <= 0.0:
        raise InputError(
            f"--pitches: the range {item!r} needs a positive STEP of mm, got {parts[2].strip()}"
        )
    count = math.floor((stop - start) / step + 1e-9) + 1
    if count > 1000:
        raise InputError(f"--pitches: the range {item!r} has {count} pitches (at most 1000)")
    return [round(start + k * step, 12) for k in range(count)]
