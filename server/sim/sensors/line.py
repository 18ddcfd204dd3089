"""The CrowBot's two line (reflectance) sensors, published on `Line` as std_msgs/Int32MultiArray.

000_32b6074bbd2115c3.txt section 3.2 (Fig. 13): two 12-bit readings 0..4095, S1 the right sensor
and S2 the left, at the front underside. An IR LED lights the floor and a phototransistor pulls
the reading down as more light comes back, so bright floor reads low and dark tape reads high.

Model: the sensor sees a spot of radius `SPOT_RADIUS_M`; the fraction of the spot covered by a tape
(a smooth ramp across the tape's edge) times the tape's darkness dims the floor's reflectance.
raw = 4095 * (1 - reflectance) + noise.

| constant | value | why |
|---|---|---|
| sensors | right then left, at x = 0.045 m, y = -/+0.012 m | close together, under the nose |
| spot radius | 4 mm | a TCRT5000-class sensor at ~5 mm height |
| noise | 20 counts | ADC noise plus ambient IR |
"""

from __future__ import annotations

import numpy as np

from sandbox.msgs.std_msgs import Int32MultiArray
from server.sim.sensors.base import SenseContext, StatelessSensor
from server.sim.sensors.mount import Mount

ADC_MAX_COUNT = 4095
SPOT_RADIUS_M = 0.004
NOISE_COUNTS = 20.0
RIGHT_SENSOR = Mount(x_m=0.045, y_m=-0.012)
LEFT_SENSOR = Mount(x_m=0.045, y_m=0.012)


def tape_darkening(world, x: float, y: float) -> float:
    """How much the floor under (x, y) is darkened by tape, 0 (bare) .. 1 (black tape)."""
    tapes = world.tape_segments
    if len(tapes) == 0:
        return 0.0
    start = tapes[:, 0:2]
    edge = tapes[:, 2:4] - start
    length_sq = np.maximum(np.sum(edge * edge, axis=1), 1e-18)
    rel = np.array([x, y]) - start
    along = np.clip(np.sum(rel * edge, axis=1) / length_sq, 0.0, 1.0)
    offset = rel - along[:, None] * edge
    distance = np.hypot(offset[:, 0], offset[:, 1])
    # Coverage ramps from 1 (spot inside the tape) to 0 (spot clear of it) across the edge.
    half_width = world.tape_width / 2.0
    coverage = np.clip((half_width + SPOT_RADIUS_M - distance) / (2 * SPOT_RADIUS_M), 0.0, 1.0)
    return float(np.max(coverage * world.tape_darkness))


class LineSensors(StatelessSensor):
    """Two 12-bit reflectance readings [right, left]; dark tape reads high."""

    msg_type = Int32MultiArray

    def __init__(self, rate_hz: float) -> None:
        self.rate_hz = rate_hz
        self.mounts = (RIGHT_SENSOR, LEFT_SENSOR)

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Int32MultiArray:
        readings = []
        for mount, noise in zip(self.mounts, rng.normal(0.0, NOISE_COUNTS, 2), strict=True):
            x, y, _ = mount.in_world(ctx.state.pose)
            reflectance = ctx.world.floor_reflectance * (1.0 - tape_darkening(ctx.world, x, y))
            raw = ADC_MAX_COUNT * (1.0 - reflectance) + noise
            readings.append(max(0, min(ADC_MAX_COUNT, round(raw))))
        return Int32MultiArray(data=readings)
