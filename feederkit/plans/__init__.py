"""Plans as files a controller can run: JSON version 2 (version 1 read), execution and
verification on geometry; plans over landings (reject results) and shared subplans.

- :mod:`~feederkit.plans.model`: the one immutable :class:`Plan` (parts, sensor, tree, stats).
- :mod:`~feederkit.plans.fileformat`: the format's constants, the maker of a Plan from a
  planner's result (``plan_from_result``) and its writer: ``plan_to_dict``, ``plan_json``.
- :mod:`~feederkit.plans.readplan`: the reader and checker of a plan file:
  ``plan_from_dict``, ``read_plan`` (size and depth limits).
- :mod:`~feederkit.plans.writeplan`: ``plan_file_text`` and ``read_back`` (checked as the
  reader will before anything is written), ``write_plan`` (atomic).
- :mod:`~feederkit.plans.stats`: the ``stats`` object (length, margins, Fig. 14 class bound).
- :mod:`~feederkit.plans.execute`: ``execute`` a plan on the kinematic model rebuilt from
  the plan's hulls and COMs, giving a ``Trace``.
- :mod:`~feederkit.plans.verify`: ``verify_plan`` / ``check_plan``: every start, reading and
  rotation, by interval arithmetic.
- :mod:`~feederkit.plans.match`: which plan part a loaded part is; parts a plan lumps together.
"""

from feederkit.plans.execute import Trace, TraceStep, execute
from feederkit.plans.fileformat import (
    CONVENTIONS,
    FORMAT,
    VERSION,
    plan_from_result,
    plan_json,
    plan_to_dict,
)
from feederkit.plans.match import leaf_part_pairs, match_part
from feederkit.plans.model import (
    Branch,
    Leaf,
    Plan,
    PlanMember,
    PlanPart,
    PlanStats,
    ResultEntry,
    Step,
    push_function_of,
)
from feederkit.plans.readplan import (
    MAX_PLAN_BYTES,
    MAX_PLAN_DEPTH,
    as_plan,
    plan_from_dict,
    read_plan,
    validate_plan,
)
from feederkit.plans.stats import plan_stats
from feederkit.plans.verify import PartCheck, VerificationReport, check_plan, verify_plan
from feederkit.plans.writeplan import plan_file_text, read_back, write_plan

__all__ = [
    "CONVENTIONS",
    "FORMAT",
    "MAX_PLAN_BYTES",
    "MAX_PLAN_DEPTH",
    "VERSION",
    "Branch",
    "Leaf",
    "PartCheck",
    "Plan",
    "PlanMember",
    "PlanPart",
    "PlanStats",
    "ResultEntry",
    "Step",
    "Trace",
    "TraceStep",
    "VerificationReport",
    "as_plan",
    "check_plan",
    "execute",
    "leaf_part_pairs",
    "match_part",
    "plan_file_text",
    "plan_from_dict",
    "plan_from_result",
    "plan_json",
    "plan_stats",
    "plan_to_dict",
    "push_function_of",
    "read_back",
    "read_plan",
    "validate_plan",
    "verify_plan",
    "write_plan",
]
