"""What the plan's sensor reads for a simulated width across the belt (design.md, sensors)."""

from __future__ import annotations

from feederkit.sensors import LedSensor, NoSensor, SensorModel, led_count


def reading_of(sensor: SensorModel, width_mm: float) -> float | None:
    """The reading a width produces: None sensorless, the width itself for a tolerance
    sensor, the blocked beam count times the pitch (mm) for an LED array."""
    if isinstance(sensor, NoSensor):
        return None
    if isinstance(sensor, LedSensor):
        return led_count(sensor.pitch, width_mm) * sensor.pitch
    return width_mm
