"""The push-align machine (Akella & Mason 1999, section 3.3) and the planners' view of it.

- :mod:`~feederkit.machine.model`: the abstract machine, states, transitions, readings;
- :mod:`~feederkit.machine.space`: sets of states, their overlap ranges and reading
  branches (what the planners search);
- :mod:`~feederkit.machine.inseparable`: the goal, a greatest fixpoint over state pairs;
- :mod:`~feederkit.machine.build`: the machine of one part or a mix from push functions
  (the only module here that knows geometry).
"""

from feederkit.angles import ActionRange, RotationRange
from feederkit.machine.build import build_machine
from feederkit.machine.inseparable import (
    greatest_fixpoint,
    pair_outcomes,
    pair_successors,
    prune_pairs,
)
from feederkit.machine.model import (
    MachineState,
    OutcomeRange,
    OverlapRange,
    PushAlignMachine,
    bit_rows,
    image,
    mask_of,
    members,
    successor,
    target_at,
)
from feederkit.machine.space import (
    SearchSpace,
    branches,
    inseparable,
    is_goal,
    overlap_cells,
    overlap_ranges,
    search_space,
)
from feederkit.sensors import Grouping, ReadingBranch

__all__ = [
    "ActionRange",
    "Grouping",
    "MachineState",
    "OutcomeRange",
    "OverlapRange",
    "PushAlignMachine",
    "ReadingBranch",
    "RotationRange",
    "SearchSpace",
    "bit_rows",
    "branches",
    "build_machine",
    "greatest_fixpoint",
    "image",
    "inseparable",
    "is_goal",
    "mask_of",
    "members",
    "overlap_cells",
    "overlap_ranges",
    "pair_outcomes",
    "pair_successors",
    "prune_pairs",
    "search_space",
    "successor",
    "target_at",
]
