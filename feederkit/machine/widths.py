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
        a, b = st.diameter_range or (st.diameter, st.diameter)
        span = widened_span(a, b, offsets[st.part], st.members or (st.state,))
        if span == (a, b):
            states.append(st)
            continue
        states.append(replace(st, diameter_range=span))
        changed = True
    return replace(machine, states=tuple(states)) if changed else machine


def widens(offsets: Offsets) -> bool:
    """Whether some offset may widen a state (a part whose contact hull is simplified)."""
    return any(o is not None and (o[0] < 0.0 or o[1] > 0.0) for off in offsets for o in off)


def widened_span(
    lo: float,
    hi: float,
    own: Sequence[tuple[float, float] | None],
    ideal: Sequence[int],
) -> tuple[float, float]:
    """``[lo, hi]`` widened by the least and largest of the ideal states ``ideal``'s offsets
    (``own``: their part's), never narrowed: the one rule for a state's widths.

    >>> widened_span(10.0, 10.0, [(0.01, 0.02), None, (-0.01, 0.0)], (0, 2))
    (9.99, 10.02)
    """
    found = [o for o in (own[i] for i in ideal) if o is not None]
    a = min((o[0] for o in found), default=0.0)
    b = max((o[1] for o in found), default=0.0)
    return (lo + min(a, 0.0), hi + max(b, 0.0))


__all__ = ["Offsets", "widen_widths", "widened_span", "widens"]
