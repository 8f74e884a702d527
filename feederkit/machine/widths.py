"""The widths a state may show beyond its model's: reading offsets on a built machine.

A machine is built from the parts' contact hulls; where import simplified a hull, the part
itself may read a little more or less than its model's state (the reading offsets of
:mod:`feederkit.mechanics.modelerror`). Planning on the widened widths keeps the planner from
telling states apart by differences only the simplification makes (a D-shape's 39.987 mm
against a rounded rectangle's 40.0 mm, both 40.0 mm made): its reading sets hold every
reading of the part itself, so each branch of its plan is right for it (section 5: the
reading sets of the states decide the branches).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from feederkit.machine.model import PushAlignMachine

Offsets = Sequence[Sequence[tuple[float, float] | None]]
"""Per part of the machine, per ideal stable state: the (least, largest) offset in mm of
what the part itself may read against the model's diameter, or None (no offset known)."""


def widen_widths(machine: PushAlignMachine, offsets: Offsets) -> PushAlignMachine:
    """``machine`` with each state's diameter interval widened by its ideal members'
    offsets (never narrowed: the interval keeps the model's own widths), or ``machine``
    itself when no offset widens anything.

    >>> from feederkit.machine.model import MachineState
    >>> m = PushAlignMachine(("a",), (MachineState(0, 0, 10.0, 1.0),), ((),), None, None)
    >>> widen_widths(m, [[(0.0, 0.02)]]).states[0].diameter_range
    (10.0, 10.02)
    """
    states = []
    changed = False
    for st in machine.states:
        own = offsets[st.part]
        found = [own[i] for i in (st.members or (st.state,)) if own[i] is not None]
        lo = min((o[0] for o in found), default=0.0)  # type: ignore[index]
        hi = max((o[1] for o in found), default=0.0)  # type: ignore[index]
        if lo >= 0.0 and hi <= 0.0:
            states.append(st)
            continue
        a, b = st.diameter_range or (st.diameter, st.diameter)
        states.append(replace(st, diameter_range=(a + min(lo, 0.0), b + max(hi, 0.0))))
        changed = True
    return replace(machine, states=tuple(states)) if changed else machine


__all__ = ["Offsets", "widen_widths"]
