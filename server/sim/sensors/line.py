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

from server.sim.geometry import offsets_from_segments, segment_arrays
from server.sim.sensors.adc import ADC_MAX_COUNT, AdcPair
from server.sim.sensors.base import SenseContext
from server.sim.sensors.mount import Mount

SPOT_RADIUS_M = 0.004
NOISE_COUNTS = 20.0  # [counts]
RIGHT_SENSOR = Mount(x_m=0.045, y_m=-0.012)
LEFT_SENSOR = Mount(x_m=0.045, y_m=0.012)


def tape_darkening(world, x: float, y: float) -> float:
    """How much the floor under (x, y) is darkened by tape, 0 (bare) .. 1 (black tape)."""
    tapes = world.tape_segments
    if len(tapes) == 0:
        return 0.0
    _, distance = offsets_from_segments(np.array([x, y]), *segment_arrays(tapes))
    # Coverage ramps from 1 (spot inside the tape) to 0 (spot clear of it) across the edge.
    half_width = world.tape_width / 2.0
    coverage = np.clip((half_width + SPOT_RADIUS_M - distance) / (2 * SPOT_RADIUS_M), 0.0, 1.0)
    return float(np.max(coverage * world.tape_darkness))


class LineSensors(AdcPair):
    """Two 12-bit reflectance readings [right, left]; dark tape reads high."""

    def __init__(self, rate_hz: float) -> None:
        super().__init__(rate_hz, RIGHT_SENSOR, LEFT_SENSOR, NOISE_COUNTS)

    def raw_count(self, mount: Mount, ctx: SenseContext) -> float:
        x, y, _ = mount.in_world(ctx.state.pose)
        reflectance = ctx.world.floor_reflectance * (1.0 - tape_darkening(ctx.world, x, y))
        return ADC_MAX_COUNT * (1.0 - reflectance)
