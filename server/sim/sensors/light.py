"""The CrowBot's two light sensors, published on `Light` as std_msgs/Int32MultiArray.

000_32b6074bbd2115c3.txt section 3.2 (Fig. 12): two 12-bit readings, 0..4095, L1 the right sensor
and L2 the left; the firmware reads them with analogRead, and a reading FALLS as the light grows
(the published controller uses (4095 - raw) / 4095). Each sensor faces forward and a little
outward, so a light to the left lowers the left reading more than the right one: the difference
drives the P controller of eq. 5.

Model: illuminance at a sensor = ambient + sum over lights of intensity * (d0 / d)^2 * max(0,
cos(angle off the sensor's axis)); d0 = 0.3 m, so a light of intensity 1 head-on at 0.3 m
saturates the sensor. raw = round(4095 * (1 - min(1, illuminance))) + noise, clamped to 0..4095.

| constant | value | why |
|---|---|---|
| sensors | right then left, at x = 0.04 m, y = -/+0.03 m | front corners of the BOLT's board |
| axes | -/+30 deg from the nose | so the difference follows sin(bearing) |
| saturation distance d0 | 0.3 m | a flashlight at 30 cm saturates, as in the paper's test |
| noise | 12 counts | ADC noise of the ESP32 |
"""

from __future__ import annotations

import math

import numpy as np

from sandbox.msgs.std_msgs import Int32MultiArray
from server.sim.sensors.base import SenseContext, StatelessSensor
from server.sim.sensors.mount import Mount

ADC_MAX_COUNT = 4095
SATURATION_DISTANCE_M = 0.3
NOISE_COUNTS = 12.0
RIGHT_SENSOR = Mount(x_m=0.04, y_m=-0.03, yaw_rad=math.radians(-30.0))
LEFT_SENSOR = Mount(x_m=0.04, y_m=0.03, yaw_rad=math.radians(30.0))


def illuminance(mount: Mount, ctx: SenseContext) -> float:
    """Relative illuminance [0..] at a sensor (1 saturates it)."""
    x, y, axis = mount.in_world(ctx.state.pose)
    total = ctx.world.ambient_light
    for light in ctx.lights:
        dx, dy = light.x - x, light.y - y
        distance = max(math.sqrt(dx * dx + dy * dy + light.z * light.z), 1e-3)
        off_axis = math.atan2(dy, dx) - axis
        facing = max(0.0, math.cos(off_axis))
        total += light.intensity * (SATURATION_DISTANCE_M / distance) ** 2 * facing
    return total


class LightSensors(StatelessSensor):
    """Two 12-bit light readings [right, left]."""

    msg_type = Int32MultiArray

    def __init__(self, rate_hz: float) -> None:
        self.rate_hz = rate_hz
        self.mounts = (RIGHT_SENSOR, LEFT_SENSOR)

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Int32MultiArray:
        readings = []
        for mount, noise in zip(self.mounts, rng.normal(0.0, NOISE_COUNTS, 2), strict=True):
            raw = ADC_MAX_COUNT * (1.0 - min(1.0, illuminance(mount, ctx))) + noise
            readings.append(max(0, min(ADC_MAX_COUNT, round(raw))))
        return Int32MultiArray(data=readings)
