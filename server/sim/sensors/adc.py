"""Analog sensors read through a 12-bit ADC (the CrowBot's ESP32, the IR scout's BeagleBone AIN0):
a reading is a whole count 0..4095.

`AdcPair` is the CrowBot's pattern of two such sensors, right then left, published together as
std_msgs/Int32MultiArray (its light and line sensors, 000_32b6074bbd2115c3.txt section 3.2).
"""

from __future__ import annotations

import numpy as np

from sandbox.msgs.std_msgs import Int32MultiArray
from server.sim.sensors.base import SenseContext, StatelessSensor
from server.sim.sensors.mount import Mount

ADC_MAX_COUNT = 4095  # [counts] full scale of a 12-bit ADC


def adc_count(raw_count: float) -> int:
    """`raw_count` [counts] rounded to a whole count and clamped to the ADC's range."""
    return max(0, min(ADC_MAX_COUNT, round(raw_count)))


class AdcPair(StatelessSensor):
    """Two analog sensors [right, left]: each reads `raw_count` at its mount plus Gaussian ADC
    noise of `noise_counts` [counts]. Subclasses say what a sensor sees (`raw_count`)."""

    msg_type = Int32MultiArray

    def __init__(self, rate_hz: float, right: Mount, left: Mount, noise_counts: float) -> None:
        self.rate_hz = rate_hz
        self.mounts = (right, left)
        self.noise_counts = noise_counts

    def raw_count(self, mount: Mount, ctx: SenseContext) -> float:
        """The noiseless reading [counts] of the sensor at `mount`."""
        raise NotImplementedError

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Int32MultiArray:
        # As Python floats: numpy scalars cost ~10x more in the arithmetic below (the CrowBot
        # samples two such pairs 20 times a second in every run).
        noise = rng.normal(0.0, self.noise_counts, len(self.mounts)).tolist()
        readings = [
            adc_count(self.raw_count(mount, ctx) + noise_counts)
            for mount, noise_counts in zip(self.mounts, noise, strict=True)
        ]
        return Int32MultiArray(data=readings)
