"""Building the push-align machine from push functions (sections 3 and 8.5).

This is where the abstract machine meets geometry: each part's resting states, resting
ranges and action ranges (:mod:`feederkit.mechanics`) become machine states and maps. Under a
declared uncertainty (design.md, "Uncertainty") the states are the physical resting states of
:mod:`feederkit.mechanics.uncertain`, each with its diameter interval, and each action range
leads to the set of states nature may pick; the ideal model (``IDEAL``) gives exactly the
paper's machine.
"""

from __future__ import annotations

from collections.abc import Sequence

from feederkit.angles import ActionRange
from feederkit.machine.model import MachineState, OutcomeRange, PushAlignMachine
from feederkit.mechanics.actions import action_ranges
from feederkit.mechanics.push import PushFunction, resting_widths
from feederkit.mechanics.symmetry import DIAMETER_REL_EPS
from feederkit.mechanics.uncertain import UncertainMechanics, action_map, uncertain_mechanics
from feederkit.sensors import NoSensor, Sensor
from feederkit.uncertainty import IDEAL, Uncertainty


def snap(values: Sequence[float], eps: float) -> list[float]:
    """Replace values equal within ``eps`` (chained in sorted order) by their cluster's first."""
    order = sorted(range(len(values)), key=lambda i: values[i])
    out = list(values)
    rep = None
    for i in order:
        if rep is None or values[i] - rep > eps:
            rep = values[i]
        out[i] = rep
    return out


def build_machine(
    push_functions: Sequence[PushFunction],
    sensor: Sensor | None = None,
    uncertainty: Uncertainty | None = None,
) -> PushAlignMachine:
    """The machine of one part or a mix (section 8.5): the parts' states side by side.

    ``uncertainty`` defaults to design.md's ``Uncertainty()`` (rotation error 1 degree);
    ``IDEAL`` gives the paper's machine: one state per stable state, exact diameters, one
    target per action range. Otherwise a state is a physical resting state with a diameter
    interval and its action ranges lead to outcome sets (:func:`uncertain_machine`).
    Diameters equal within ``DIAMETER_REL_EPS`` of the largest part are made exactly equal
    (docs/conventions.md), so exact symmetry survives rounding. Raises InputError for a shape
    tolerance too large for a part.
    """
    sensor = NoSensor() if sensor is None else sensor
    uncertainty = Uncertainty() if uncertainty is None else uncertainty
    if not uncertainty.is_ideal:
        mechs = [uncertain_mechanics(pf.part, uncertainty) for pf in push_functions]
        return uncertain_machine(push_functions, mechs, sensor)
    offsets = []
    total = 0
    for pf in push_functions:
        offsets.append(total)
        total += pf.n
    eps = DIAMETER_REL_EPS * max(pf.part.size for pf in push_functions)
    diam = snap([s.diameter for pf in push_functions for s in pf.states], eps)
    states = []
    maps = []
    k = 0
    share = len(push_functions)
    for p, pf in enumerate(push_functions):
        widths = resting_widths(pf)
        for s in pf.states:
            states.append(MachineState(p, s.id, diam[k], widths[s.id] / 360.0 / share))
            ranges = action_ranges(pf, s.id)
            maps.append(tuple(ActionRange(r.lo, r.hi, r.target + offsets[p]) for r in ranges))
            k += 1
    return PushAlignMachine(
        part_names=tuple(pf.part.name for pf in push_functions),
        states=tuple(states),
        action_maps=tuple(maps),
        sensor=sensor,
        uncertainty=IDEAL,
    )


def uncertain_machine(
    push_functions: Sequence[PushFunction],
    mechanics: Sequence[UncertainMechanics],
    sensor: Sensor,
) -> PushAlignMachine:
    """The machine of the parts' physical resting states under their mechanics' uncertainty.

    A state's ``members`` are its ideal stable states, ``state`` the first of them,
    ``diameter_range`` its reading interval (endpoints snapped like exact diameters) and its
    weight the resting ranges of the ideal states a first alignment can end in, each shared
    equally among the physical states it may settle in (``destinations``).
    """
    offsets = []
    total = 0
    for mech in mechanics:
        offsets.append(total)
        total += mech.n
    eps = DIAMETER_REL_EPS * max(pf.part.size for pf in push_functions)
    ends = snap([x for mech in mechanics for s in mech.states for x in s.diameter], eps)
    share = len(push_functions)
    states = []
    maps = []
    k = 0
    for p, (pf, mech) in enumerate(zip(push_functions, mechanics, strict=True)):
        widths = resting_widths(pf)
        weight = [0.0] * mech.n
        for i, dest in enumerate(mech.destinations):
            for t in dest:
                weight[t] += widths[i] / 360.0 / share / len(dest)
        for s in mech.states:
            lo, hi = ends[k], ends[k + 1]
            k += 2
            states.append(
                MachineState(p, s.members[0], (lo + hi) / 2.0, weight[s.id], (lo, hi), s.members)
            )
            ranges = []
            for a, b, targets in action_map(mech, s.id):
                mask = 0
                for t in targets:
                    mask |= 1 << (t + offsets[p])
                ranges.append(OutcomeRange(a, b, mask))
            maps.append(tuple(ranges))
    return PushAlignMachine(
        part_names=tuple(pf.part.name for pf in push_functions),
        states=tuple(states),
        action_maps=tuple(maps),
        sensor=sensor,
        uncertainty=mechanics[0].uncertainty,
    )
