"""The push-align machine: states, transitions and readings (Akella & Mason 1999, section 3.3).

States are the resting states of one or more parts (section 8.5: a state carries its part);
an action is a rotation in [0, 360); each state has a piecewise-constant action map (its
action ranges, definition 9); the sensor model gives each state's readings (section 5).

Under uncertainty (design.md, "Uncertainty"; docs/uncertainty.md) a state is a physical
resting state (one or more ideal stable states, a diameter interval) and an action range
leads to a *set* of states (:class:`OutcomeRange`, a bit mask): nature picks the outcome.
The ideal machine is the special case of exact diameters and singleton outcomes
(:class:`~feederkit.angles.ActionRange`). Nothing here looks at geometry: machines are values
that can be built by hand (tests do), and :mod:`feederkit.machine.build` makes them from push
functions.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from feederkit.angles import ActionRange, RotationRange, norm360
from feederkit.sensors import Diameter, Sensor
from feederkit.uncertainty import IDEAL, Uncertainty


@dataclass(frozen=True)
class MachineState:
    """A state of the machine: stable state ``state`` of part ``part``.

    ``weight`` is the probability that the first alignment from a uniformly random
    orientation ends here (resting range / 360 times the member's prior share: divided by
    the number of parts unless :func:`feederkit.machine.weights.weigh_members` gave shares).
    Under uncertainty ``state`` is the first of the ideal ``members`` of a physical resting
    state and ``diameter_range`` the interval of widths it can show (``diameter`` its middle).
    On the ideal model a snapped state's ``diameter`` is its cluster's smallest value and
    ``diameter_range`` (when set) the cluster's span (:func:`feederkit.machine.build.snap_spans`).
    ``reject`` marks a state of a member the next station cannot take (a rejected landing,
    design.md "Landings"): a set of only such states is a goal, a reject leaf
    (:attr:`feederkit.machine.space.SearchSpace.inseparable`). It travels with the state, so
    renumbering the states keeps it. ``look_alike`` names (by ``state``) the other states of
    the same part whose poses look like this one's to the next station (near-congruent
    outlines, docs/planning.md "Near-symmetric states under uncertainty") or that no plan
    tells apart even on the ideal model (``machine.build.ideal_twins``): the only pairs of
    one part a leaf may list together, in the goal (``SearchSpace.alike``) and when no
    strong plan resolves them. The machine build records it under uncertainty; None (a
    machine built by hand, or the ideal model, where nothing is lumped) records nothing,
    and then any pair may be listed. ``unlike_members`` marks a physical state whose ideal
    members include poses that do not look alike (a part at rest may wander between them
    under the uncertainty: a leaf holding it does not orient the part).
    """

    part: int
    state: int
    diameter: float
    weight: float
    diameter_range: tuple[float, float] | None = None
    members: tuple[int, ...] = ()
    reject: bool = False
    look_alike: tuple[int, ...] | None = None
    unlike_members: bool = False

    @property
    def sensed(self) -> Diameter:
        """What the sensor sees: the exact diameter, or the diameter interval."""
        return self.diameter if self.diameter_range is None else self.diameter_range

    def alike(self, other: MachineState) -> bool:
        """Whether a leaf may list this state with ``other``: a state of another part, or
        of this part when each names the other in ``look_alike`` (any when either records
        nothing)."""
        if self.part != other.part or self.look_alike is None or other.look_alike is None:
            return True
        return other.state in self.look_alike and self.state in other.look_alike

    @property
    def ideal_states(self) -> tuple[int, ...]:
        """The ideal stable states this state stands for (``(state,)`` in the ideal model)."""
        return self.members or (self.state,)


@dataclass(frozen=True)
class OverlapRange(RotationRange):
    """An overlap range of a set of states (section 3.2.2): rotations in ``(lo, hi)`` send the
    set to the set ``image`` (a bit mask).

    ``representative`` (the middle) is the rotation a plan uses; ``margin`` (the half-width)
    the rotation error it tolerates.
    """

    image: int


@dataclass(frozen=True)
class OutcomeRange(RotationRange):
    """Rotations ``lo < a < hi`` (deg; ``lo`` in [0, 360), ``hi`` may pass 360) after which a
    state can end in any state of ``targets`` (a bit mask), for every rotation error within
    the declared bound: the nondeterministic action range."""

    targets: int


def target_at(starts: Sequence[float], targets: Sequence[int], action: float) -> int:
    """The target of an action map (range starts ``starts`` ascending in [0, 360), their
    ``targets``) for a rotation strictly inside one of its ranges.

    The one successor lookup: before the first start is the last range, which wraps.
    """
    k = bisect.bisect_right(starts, norm360(action)) - 1
    return targets[k]


@dataclass(frozen=True)
class PushAlignMachine:
    """States, action maps and sensor of a push-align feeder for one or more parts.

    ``action_maps[i]`` are state ``i``'s action ranges, sorted by ``lo`` (in [0, 360)):
    :class:`~feederkit.angles.ActionRange` (one target state) or :class:`OutcomeRange` (a set
    of target states). ``starts`` and ``outcomes_of`` (per range, the mask of its targets) are
    the same maps as plain lists for the successor lookup, derived once when the machine is
    made; ``targets`` holds each range's single target (-1 where a range has several).
    ``uncertainty`` is the declared uncertainty the machine was built under (the ideal model
    for hand-built machines): a record for results, the planners never read it.
    """

    part_names: tuple[str, ...]
    states: tuple[MachineState, ...]
    action_maps: tuple[tuple[ActionRange | OutcomeRange, ...], ...]
    sensor: Sensor
    uncertainty: Uncertainty = IDEAL
    starts: tuple[list[float], ...] = field(init=False, repr=False, compare=False)
    targets: tuple[list[int], ...] = field(init=False, repr=False, compare=False)
    outcomes_of: tuple[list[int], ...] = field(init=False, repr=False, compare=False)
    deterministic: bool = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "starts", tuple([r.lo for r in rs] for rs in self.action_maps))
        masks = tuple([_range_mask(r) for r in rs] for rs in self.action_maps)
        set_(self, "outcomes_of", masks)
        set_(
            self,
            "targets",
            tuple([m.bit_length() - 1 if m & (m - 1) == 0 else -1 for m in ms] for ms in masks),
        )
        set_(self, "deterministic", all(t >= 0 for ts in self.targets for t in ts))

    @property
    def n(self) -> int:
        """Number of states."""
        return len(self.states)

    @property
    def all_states(self) -> int:
        """The bit mask of every state."""
        return (1 << len(self.states)) - 1

    def successor(self, state: int, action: float) -> int:
        """Where ``state`` goes under a rotation strictly inside one of its action ranges.

        Only for a single outcome (the ideal model); :meth:`outcomes` is the general form.
        """
        t = target_at(self.starts[state], self.targets[state], action)
        if t < 0:
            raise ValueError(f"state {state} has several outcomes under {action:g} deg")
        return t

    def outcomes(self, state: int, action: float) -> int:
        """The set of states (a mask) ``state`` can end in under a rotation strictly inside
        one of its action ranges."""
        return target_at(self.starts[state], self.outcomes_of[state], action)

    def image(self, mask: int, action: float) -> int:
        """The set of states a set of states can end in under one rotation: the union of its
        members' outcome sets."""
        out = 0
        for i in members(mask):
            out |= self.outcomes(i, action)
        return out

    def diameters(self, mask: int | None = None) -> list[float]:
        """The diameters of the states in ``mask`` (all states by default), ascending index."""
        idx = range(self.n) if mask is None else members(mask)
        return [self.states[i].diameter for i in idx]

    def sensed(self, mask: int | None = None) -> list[Diameter]:
        """What the sensor sees of the states in ``mask`` (exact diameters or intervals)."""
        idx = range(self.n) if mask is None else members(mask)
        return [self.states[i].sensed for i in idx]


def _range_mask(r: ActionRange | OutcomeRange) -> int:
    """The targets of an action range as a mask."""
    return r.targets if isinstance(r, OutcomeRange) else 1 << r.target


def mask_of(indices: Iterable[int]) -> int:
    """The bit mask of a collection of state indices."""
    m = 0
    for i in indices:
        m |= 1 << i
    return m


def members(mask: int) -> list[int]:
    """The state indices in a bit mask, ascending."""
    out = []
    while mask:
        low = mask & -mask
        out.append(low.bit_length() - 1)
        mask ^= low
    return out


def bit_rows(masks: Sequence[int], n: int) -> np.ndarray:
    """Sets as a boolean matrix, a row per mask and a column per state (``n`` states): many
    sets at once for array operations.

    >>> bit_rows([0b101, 0b010], 3).tolist()
    [[True, False, True], [False, True, False]]
    """
    if any(m >> n for m in masks):
        raise ValueError(f"a set holds states beyond the {n} of the machine")
    width = (n + 7) // 8
    raw = np.frombuffer(b"".join(m.to_bytes(width, "little") for m in masks), np.uint8)
    rows = raw.reshape(len(masks), width)
    return np.unpackbits(rows, axis=1, count=n, bitorder="little").astype(bool)


def successor(machine: PushAlignMachine, state: int, action: float) -> int:
    """``machine.successor(state, action)``."""
    return machine.successor(state, action)


def image(machine: PushAlignMachine, mask: int, action: float) -> int:
    """``machine.image(mask, action)``."""
    return machine.image(mask, action)
