"""The planning problem: a push-align machine prepared for search over sets of states.

States are bit masks (section 3.3: a node of the search holds the set of states consistent
with the operations so far). A :class:`Problem` ties together the pieces every planner on
the same machine shares, each with one job and its own caches:

- the goal test (:meth:`Problem.is_goal`, the inseparable states of
  :mod:`feederkit.machine.inseparable`);
- the reading branches of the sets met (:class:`~feederkit.planning.readings.Readings`);
- the representative actions of a set (:class:`~feederkit.planning.choices.Choices`): the
  overlap ranges of section 3.2.2 keeping those with at least ``min_margin``, each with
  the sets of states the reading can leave (section 6.1).
"""

from __future__ import annotations

from feederkit.machine import Grouping, PushAlignMachine, is_goal, search_space
from feederkit.planning.choices import Act, Choices
from feederkit.planning.readings import Readings, maximal_sets

__all__ = ["Act", "Problem", "maximal_sets", "popcount"]


def popcount(mask: int) -> int:
    """Number of states in a mask."""
    return mask.bit_count()


class Problem:
    """A machine, a reading grouping and a margin floor, with the pieces planners share.

    ``readings`` answers for reading branches, ``choices`` for actions. ``distinct_maps``
    keeps one action per distinct map of the members rather than per distinct image (the
    expected objective needs it: equal images can follow different paths).
    """

    def __init__(
        self,
        machine: PushAlignMachine,
        grouping: Grouping | str = Grouping.EXACT,
        min_margin: float = 0.0,
        insep: tuple[int, ...] | None = None,
        distinct_maps: bool = False,
        readings: Readings | None = None,
    ) -> None:
        self.machine = machine
        self.grouping = Grouping(grouping)
        self.min_margin = min_margin
        self.distinct_maps = distinct_maps
        self.n = machine.n
        self.full = machine.all_states
        self.insep = search_space(machine).inseparable if insep is None else insep
        self.readings = (
            Readings(machine, self.grouping, self.insep) if readings is None else readings
        )
        self.sensorless = self.readings.sensorless
        self.choices = Choices(machine, self.readings, min_margin, distinct_maps)
        self._goal: dict[int, bool] = {}

    def with_margin(self, min_margin: float) -> Problem:
        """The same problem keeping only actions with at least ``min_margin``."""
        return Problem(
            self.machine,
            self.grouping,
            min_margin,
            self.insep,
            self.distinct_maps,
            self.readings,
        )

    def carries_no_information(self, mask: int) -> bool:
        """Whether no reading can split any set reachable from ``mask`` (readings then carry
        no information: a sensorless problem inside a sensor-based one,
        :meth:`~feederkit.planning.readings.Readings.carries_no_information`)."""
        return self.readings.carries_no_information(mask)

    def is_goal(self, mask: int) -> bool:
        """Whether every pair of states in ``mask`` is inseparable (the set is oriented;
        :func:`feederkit.machine.is_goal`, memoised per set)."""
        g = self._goal.get(mask)
        if g is None:
            g = self._goal[mask] = is_goal(self.insep, mask)
        return g
