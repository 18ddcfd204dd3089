"""The TurtleBot3's 360-degree laser distance sensor, the Hitachi-LG LDS-01, as its ROS 1 driver
publishes it.

Sources: ROBOTIS e-manual, TurtleBot3 > Appendixes > LDS-01
(emanual.robotis.com/docs/en/platform/turtlebot3/appendix_lds_01/: range, accuracy, precision,
scan rate, sampling rate); the noetic driver, ROBOTIS-GIT/hls_lfcd_lds_driver
src/hlds_laser_publisher.cpp (message fields, beam order, units); turtlebot3_bringup
launch/turtlebot3_lidar.launch (frame `base_scan`); turtlebot3_description
urdf/turtlebot3_burger.urdf.xacro (where base_scan sits).

- Message: sensor_msgs/LaserScan on `scan`, frame `base_scan`, 360 beams. Beam i looks i degrees
  counter-clockwise from straight ahead: index 0 ahead, 90 left, 180 behind, 270 right (the
  driver stores sample k at 359 - k, turning the sensor's clockwise order counter-clockwise).
- Fields as the driver sets them: angle_min 0, angle_increment 2 pi / 360, angle_max
  2 pi - increment, range_min 0.12 m, range_max 3.5 m, time_increment 1 / (rpm * 6) s,
  scan_time 360 * time_increment (0.2 s at the nominal 300 rpm), 360 intensities.
- Ranges are the sensor's millimetres / 1000, so every reading is a whole number of mm. A beam
  with no return reads 0.0: the driver copies the sensor's 0 mm through unchanged (it neither
  filters nor writes inf), so consumers must skip readings below range_min. Nothing within
  3.5 m, or a measurement outside 0.12-3.5 m, gives that 0.0 here.
- Noise (datasheet): accuracy +-15 mm from 120 to 499 mm and +-5.0 % from 500 to 3500 mm;
  precision (repeatability) +-10 mm and +-3.5 %. Modelled as Gaussian with sd = half the
  precision, truncated at the accuracy band, so no reading is ever further off than the
  datasheet allows.
- Intensities: the driver sends one per beam (device units). The datasheet gives no scale, so
  this model reports `_INTENSITY_RETURN` for a return and 0 for none (assumption: the values
  are not the real sensor's, only the shape of the array and the zero for no return are).
- Geometry: the scan plane is 0.182 m above the floor (base_footprint -> base_link 0.010 m,
  base_link -> base_scan 0.172 m), so lower obstacles are not seen. Simplification: the whole
  0.2 s revolution is taken at one pose (no motion distortion).
"""

from __future__ import annotations

import math

import numpy as np

from sandbox.msgs.sensor_msgs import LaserScan
from server.sim.sensors.base import SenseContext, StatelessSensor
from server.sim.sensors.frames import TWO_PI, stamped_header
from server.sim.sensors.mount import Mount

# | name                        | value  | unit  | why                                         |
# |-----------------------------|--------|-------|---------------------------------------------|
BEAM_COUNT = 360  # [1]                   angular resolution 1 degree over 360 degrees
SCAN_RPM = 300.0  # [rpm]                 scan rate 300 +- 10 rpm -> 5 Hz
RANGE_MIN_M = 0.12  # [m]                 driver's range_min (detection from 120 mm)
RANGE_MAX_M = 3.5  # [m]                  driver's range_max (detection to 3500 mm)
NEAR_LIMIT_M = 0.5  # [m]                 accuracy is absolute below 500 mm, relative above
NEAR_ACCURACY_M = 0.015  # [m]            +-15 mm, 120-499 mm
FAR_ACCURACY = 0.05  # [1]                +-5.0 %, 500-3500 mm
NEAR_PRECISION_M = 0.010  # [m]           +-10 mm, 120-499 mm
FAR_PRECISION = 0.035  # [1]              +-3.5 %, 500-3500 mm
RESOLUTION_M = 0.001  # [m]               the sensor reports whole millimetres
NO_RETURN_M = 0.0  # [m]                  what the driver publishes for a beam without echo
MOUNT_X_M = -0.032  # [m]                 base_scan is 32 mm behind base_link (the axle)
SCAN_PLANE_HEIGHT_M = 0.182  # [m]        0.010 + 0.172 above the floor
_INTENSITY_RETURN = 1000.0  # [device units] assumption, see the module docstring


def accuracy_band_m(true_range_m: np.ndarray) -> np.ndarray:
    """The datasheet's worst-case error [m] at each true range: 15 mm below 0.5 m, 5 % above."""
    ranges = np.asarray(true_range_m, dtype=np.float64)
    return np.where(ranges < NEAR_LIMIT_M, NEAR_ACCURACY_M, FAR_ACCURACY * ranges)


def _noise_sd_m(true_range_m: np.ndarray) -> np.ndarray:
    """Half the datasheet precision: the spread of repeated readings of one target."""
    return 0.5 * np.where(
        true_range_m < NEAR_LIMIT_M, NEAR_PRECISION_M, FAR_PRECISION * true_range_m
    )


class Lds01(StatelessSensor):
    """The LDS-01 publishing sensor_msgs/LaserScan as hls_lfcd_lds_driver does (module doc)."""

    msg_type = LaserScan

    def __init__(self, *, frame_id: str = "base_scan", rpm: float = SCAN_RPM) -> None:
        if not (math.isfinite(rpm) and rpm > 0.0):
            raise ValueError(f"Lds01 needs a positive rotation speed in rpm, got {rpm}")
        self.frame_id = frame_id
        self.rate_hz = rpm / 60.0  # [Hz] one scan per revolution
        self.time_increment_s = 1.0 / (rpm * 6.0)  # [s] the driver's formula: 360 beams a turn
        self.mount = Mount(x_m=MOUNT_X_M)
        self.angle_increment_rad = TWO_PI / BEAM_COUNT
        self.beam_angles_rad = self.angle_increment_rad * np.arange(BEAM_COUNT)

    def ranges(self, true_range_m: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """What the driver publishes for beams whose true ranges are `true_range_m` [m] (inf for
        no surface): noisy, truncated to the accuracy band, whole mm, 0.0 when out of range."""
        true_m = np.asarray(true_range_m, dtype=np.float64)
        hit = np.isfinite(true_m)
        safe_m = np.where(hit, true_m, 0.0)
        band_m = accuracy_band_m(safe_m)
        error_m = np.clip(_noise_sd_m(safe_m) * rng.standard_normal(true_m.shape), -band_m, band_m)
        measured_m = np.round((safe_m + error_m) / RESOLUTION_M) * RESOLUTION_M
        valid = hit & (measured_m >= RANGE_MIN_M) & (measured_m <= RANGE_MAX_M)
        return np.where(valid, measured_m, NO_RETURN_M).astype(np.float32)

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> LaserScan:
        x_m, y_m, heading_rad = self.mount.in_world(ctx.state.pose)
        hits = ctx.obstacles.cast(
            np.array([x_m, y_m]),
            heading_rad + self.beam_angles_rad,
            RANGE_MAX_M + FAR_ACCURACY * RANGE_MAX_M,  # a wall just beyond may still read 3.5
            min_height_m=SCAN_PLANE_HEIGHT_M,
        )
        ranges = self.ranges(hits.distance_m, rng)
        intensities = np.where(ranges > 0.0, _INTENSITY_RETURN, 0.0).astype(np.float32)
        return LaserScan(
            header=stamped_header(ctx.time_s, self.frame_id),
            angle_min=0.0,
            angle_max=TWO_PI - self.angle_increment_rad,
            angle_increment=self.angle_increment_rad,
            time_increment=self.time_increment_s,
            scan_time=self.time_increment_s * BEAM_COUNT,
            range_min=RANGE_MIN_M,
            range_max=RANGE_MAX_M,
            ranges=ranges,
            intensities=intensities,
        )
