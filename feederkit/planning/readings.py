"""How likely each reading branch is: the distribution the expected objective uses.

The paper leaves the reading distribution open (section 6: "the expected number of
operations depends on the initial distribution of part orientations"). feederkit fixes it:

- the initial orientation is uniform on the circle, so the first alignment ends in state
  ``s`` with probability ``MachineState.weight`` (its resting range / 360);
- a reading error is uniform over the state's reading set: with ``ToleranceSensor(e)`` a
  state of diameter ``d`` reads uniformly in ``(d - e, d + e)``; with ``LedSensor(p, e)``
  the width is uniform in ``[d - e, d + e]`` (exactly ``d`` when ``e = 0``) and the count is
  the number of beams below it; without a sensor there is one reading.

A state therefore follows a branch ``[lo, hi]`` with the probability that its reading falls
in it, and its probability mass is split between the branches it can follow in that
proportion (with exact branching they add up to 1; with the components rule each state
follows one branch). Planner and statistics use this same model.
"""

from __future__ import annotations

from feederkit.machine import Branch
from feederkit.sensors import LedSensor, SensorModel, ToleranceSensor


def reading_probability(sensor: SensorModel, branch: Branch, diameter: float) -> float:
    """Probability that a state of this diameter gives a reading in ``branch``."""
    if branch.lo is None or branch.hi is None:
        return 1.0
    if isinstance(sensor, ToleranceSensor):
        e = sensor.tolerance
        lo, hi = max(branch.lo, diameter - e), min(branch.hi, diameter + e)
        return max(0.0, min(1.0, (hi - lo) / (2.0 * e)))
    if isinstance(sensor, LedSensor):
        # Count c means c * p < width <= (c + 1) * p; the branch holds counts lo/p .. hi/p.
        wlo, whi = branch.lo, branch.hi + sensor.pitch
        e = sensor.noise
        if e <= 0.0:
            return 1.0 if wlo < diameter <= whi else 0.0
        lo, hi = max(wlo, diameter - e), min(whi, diameter + e)
        return max(0.0, min(1.0, (hi - lo) / (2.0 * e)))
    return 1.0
