"""Plans as files a controller can run: JSON version 1, execution and verification on geometry.

- :mod:`~feederkit.plans.fileformat`: ``plan_to_dict``, ``validate_plan``, ``read_plan``,
  ``write_plan`` (atomic), ``plan_json``.
- :mod:`~feederkit.plans.stats`: the ``stats`` object (length, margins, Fig. 14 class bound).
- :mod:`~feederkit.plans.execute`: ``execute`` a plan on the kinematic model rebuilt from
  the file's hulls and COMs, giving a ``Trace``.
- :mod:`~feederkit.plans.verify`: ``verify_plan`` / ``check_plan``: every start, reading and
  branch.
- :mod:`~feederkit.plans.match`: which plan part a loaded part is; parts a plan lumps together.
- :mod:`~feederkit.plans.render`: rich tree and tables.
"""

from feederkit.plans.execute import KinematicModel, Trace, TraceStep, execute, kinematic_model
from feederkit.plans.fileformat import (
    CONVENTIONS,
    FORMAT,
    VERSION,
    plan_json,
    plan_to_dict,
    read_plan,
    validate_plan,
    write_plan,
)
from feederkit.plans.match import leaf_part_pairs, match_part
from feederkit.plans.stats import plan_stats
from feederkit.plans.verify import PartCheck, VerificationReport, check_plan, verify_plan

__all__ = [
    "CONVENTIONS",
    "FORMAT",
    "VERSION",
    "KinematicModel",
    "PartCheck",
    "Trace",
    "TraceStep",
    "VerificationReport",
    "check_plan",
    "execute",
    "kinematic_model",
    "leaf_part_pairs",
    "match_part",
    "plan_json",
    "plan_stats",
    "plan_to_dict",
    "read_plan",
    "validate_plan",
    "verify_plan",
    "write_plan",
]
