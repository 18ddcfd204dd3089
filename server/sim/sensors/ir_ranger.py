"""The IR scout's Sharp-style infrared rangefinder on a hobby servo (002_3fcfeb7b4c14107a.txt).

The paper's robot reads a Sharp IR rangefinder on the BeagleBone's analog pin AIN0 and turns it
to centimetres in its sensor node (section II, Fig. 5); the servo points it at 45, 90 and 135
degrees and at 0 and 180 degrees to compare left and right (Fig. 3, 6). The paper names the
sensor's limitation: it "is unable to detect object not perpendicular to the sensor" - a surface
hit at a grazing angle scatters the spot away from the detector, and the reading then looks like
open space. Modelled here as a narrow beam that misses beyond `GRAZING_MISS_INCIDENCE_RAD`.

Two topics come from the same measurement:
- `ir_adc` (std_msgs/Int32): the raw 12-bit AIN0 count, as the paper's sensor node reads it.
  The sensor's 0.4-3.1 V output goes through a 1:2 divider to fit the BeagleBone's 1.8 V input.
- `ir_range` (sensor_msgs/Range, INFRARED): the same reading in metres for students who skip the
  conversion; +inf when nothing is within range (ROS REP 117).

| constant | value | why |
|---|---|---|
| range | 0.10-0.80 m | GP2Y0A21-class datasheet |
| beam | 2 deg full angle, 3 rays | a narrow spot beam |
| voltage law | V = (d_cm / 29.988) ** (-1 / 1.173) | common power-law fit to the datasheet curve |
| far/no-target voltage | 0.30 V | datasheet output with no reflector |
| voltage noise | 0.02 V | supply ripple seen on the analog output |
| ADC | 12 bit, 1.8 V full scale, 1:2 divider | BeagleBone Black AIN |
| grazing miss | incidence > 40 deg | the limitation the paper describes |
"""

from __future__ import annotations

import math

import numpy as np

from sandbox.msgs import Time
from sandbox.msgs.sensor_msgs import Range
from sandbox.msgs.std_msgs import Header, Int32
from server.sim.sensors.adc import ADC_MAX_COUNT, adc_count
from server.sim.sensors.base import SenseContext, StatelessSensor, fan
from server.sim.sensors.mount import Mount

MIN_RANGE_M = 0.10
MAX_RANGE_M = 0.80
BEAM_FULL_ANGLE_RAD = math.radians(2.0)
BEAM_RAYS = 3
FIT_SCALE_CM = 29.988
FIT_EXPONENT = -1.173
NO_TARGET_VOLTS = 0.30
VOLTAGE_NOISE_V = 0.02
ADC_FULL_SCALE_V = 1.8
DIVIDER_RATIO = 0.5
GRAZING_MISS_INCIDENCE_RAD = math.radians(40.0)
SERVO_CENTRE_DEG = 90.0  # servo angle that points the ranger straight ahead


def volts_for_range(distance_cm: float) -> float:
    """Sensor output voltage for a target at `distance_cm` (the datasheet power law)."""
    return (distance_cm / FIT_SCALE_CM) ** (1.0 / FIT_EXPONENT)


def range_cm_for_volts(volts: float) -> float:
    """Inverse of `volts_for_range`: what a student's sensor node computes from the ADC."""
    return FIT_SCALE_CM * volts**FIT_EXPONENT


class IrMeasurement:
    """The ranger itself: beam geometry, the grazing-angle miss and the voltage law; both
    topics sample it (each with its own noise draw, as two ADC reads would)."""

    def __init__(self, mount: Mount) -> None:
        self.mount = mount
        self._offsets = np.linspace(-BEAM_FULL_ANGLE_RAD / 2, BEAM_FULL_ANGLE_RAD / 2, BEAM_RAYS)

    def beam_origin(self, ctx: SenseContext) -> tuple[float, float, float]:
        """World (x, y [m], heading [rad]) of the beam, turned by the servo."""
        servo_rad = math.radians(ctx.state.servo_angle_deg - SERVO_CENTRE_DEG)
        return self.mount.in_world(ctx.state.pose, servo_rad)

    def true_range_m(self, ctx: SenseContext) -> float:
        """Range [m] to a surface the beam can see, inf when nothing answers."""
        x, y, heading = self.beam_origin(ctx)
        hits = ctx.obstacles.cast(np.array([x, y]), heading + self._offsets, MAX_RANGE_M * 1.5)
        seen = hits.incidence_rad <= GRAZING_MISS_INCIDENCE_RAD
        nearest = float(np.where(seen, hits.distance_m, np.inf).min())
        return nearest

    def volts(self, ctx: SenseContext, rng: np.random.Generator) -> float:
        distance_m = self.true_range_m(ctx)
        if math.isfinite(distance_m) and distance_m <= MAX_RANGE_M:
            # Closer than the minimum the real sensor's curve folds back; clamp to its peak.
            volts = volts_for_range(max(distance_m, MIN_RANGE_M) * 100.0)
        else:
            volts = NO_TARGET_VOLTS
        return max(0.0, volts + rng.normal(0.0, VOLTAGE_NOISE_V))


class IrAdc(StatelessSensor):
    """`ir_adc`: the raw AIN0 count."""

    msg_type = Int32

    def __init__(self, mount: Mount, rate_hz: float) -> None:
        self.measurement = IrMeasurement(mount)
        self.rate_hz = rate_hz

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Int32:
        volts = self.measurement.volts(ctx, rng) * DIVIDER_RATIO
        return Int32(data=adc_count(volts / ADC_FULL_SCALE_V * ADC_MAX_COUNT))


class IrRange(StatelessSensor):
    """`ir_range`: the reading in metres as sensor_msgs/Range."""

    msg_type = Range

    def __init__(self, mount: Mount, rate_hz: float, frame_id: str = "ir_link") -> None:
        self.measurement = IrMeasurement(mount)
        self.rate_hz = rate_hz
        self.frame_id = frame_id

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Range:
        volts = self.measurement.volts(ctx, rng)
        if volts <= NO_TARGET_VOLTS + 3 * VOLTAGE_NOISE_V:
            range_m = math.inf
        else:
            range_m = min(MAX_RANGE_M, max(MIN_RANGE_M, range_cm_for_volts(volts) / 100.0))
        return Range(
            header=Header(stamp=Time.from_sec(ctx.time_s), frame_id=self.frame_id),
            radiation_type=Range.INFRARED,
            field_of_view=BEAM_FULL_ANGLE_RAD,
            min_range=MIN_RANGE_M,
            max_range=MAX_RANGE_M,
            range=range_m,
        )

    def rays(self, ctx: SenseContext, message: Range) -> np.ndarray:
        """The beam, as long as the reading (full range when nothing answered)."""
        x, y, heading = self.measurement.beam_origin(ctx)
        length = message.range if math.isfinite(message.range) else MAX_RANGE_M
        return fan(x, y, np.array([heading]), length)
