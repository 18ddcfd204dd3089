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

from server.sim.sensors.adc import ADC_MAX_COUNT, AdcPair
from server.sim.sensors.base import SenseContext
from server.sim.sensors.mount import Mount

SATURATION_DISTANCE_M = 0.3
NOISE_COUNTS = 12.0  # [counts]
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


class LightSensors(AdcPair):
    """Two 12-bit light readings [right, left]."""

    def __init__(self, rate_hz: float) -> None:
        super().__init__(rate_hz, RIGHT_SENSOR, LEFT_SENSOR, NOISE_COUNTS)

    def raw_count(self, mount: Mount, ctx: SenseContext) -> float:
        return ADC_MAX_COUNT * (1.0 - min(1.0, illuminance(mount, ctx)))
