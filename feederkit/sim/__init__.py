"""Check plans in a physics engine: a MuJoCo conveyor, fence and robot (issue 7).

Optional: needs the ``feederkit[sim]`` extra (mujoco), imported only when a simulation
runs. ``simulate_plan`` executes a plan file over many trials; ``simulate_push`` performs
one push-align operation and compares it with the push function (paper, section 3.1).
"""

from feederkit.sim.api import (
    DEFAULT_BELT_SPEED,
    DEFAULT_FRICTION_BELT,
    DEFAULT_FRICTION_FENCE,
    PushCheck,
    simulate_plan,
    simulate_push,
)
from feederkit.sim.engine import MISSING_MESSAGE, mujoco_available, require_mujoco
from feederkit.sim.pushalign import PushAligner, PushOutcome, SettleRule
from feederkit.sim.scene import SceneConfig
from feederkit.sim.summary import PushMiss, PushRecord, SimSettings, SimulationSummary, TrialResult

__all__ = [
    "DEFAULT_BELT_SPEED",
    "DEFAULT_FRICTION_BELT",
    "DEFAULT_FRICTION_FENCE",
    "MISSING_MESSAGE",
    "PushAligner",
    "PushCheck",
    "PushMiss",
    "PushOutcome",
    "PushRecord",
    "SceneConfig",
    "SettleRule",
    "SimSettings",
    "SimulationSummary",
    "TrialResult",
    "mujoco_available",
    "require_mujoco",
    "simulate_plan",
    "simulate_push",
]
