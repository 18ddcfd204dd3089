"""A 360-degree 2D LiDAR like the YDLidar X2 on the crop-row robot.

Source: 001_8d7ab1b8a58c0603.txt section 2 (robot structure, YDLidar X2 on the top floor) and
Figure 5 (angle convention); rate, sample rate and range are the X2 datasheet's, which the paper
relies on.

- Message: sensor_msgs/LaserScan, frame "laser".
- Angles follow the paper's mount (Figure 5): 0 rad points to the robot's REAR (where the X2's
  motor is), the left side is (0, pi), the right side (-pi, 0), the front +/-pi. Increasing
  angles sweep CLOCKWISE seen from above: robot-frame direction = pi - lidar angle. So
  `angle_min` = -pi, `angle_max` = pi - one increment.
- Units and range: metres, 0.12-8 m. A beam with no return (nothing within 8 m, or closer than
  0.12 m) reads 0.0, as the YDLidar SDK/ROS driver reports invalid points; by the LaserScan
  rule "values outside [range_min, range_max] are invalid" consumers must skip them.
- Noise: Gaussian, sd = 8 mm + 0.2 % of the range (about 1 cm at 1 m, 2.4 cm at 8 m).
- Rate: ~7 Hz, 3000 samples/s -> 429 beams per revolution.
- Beams are rays in the horizontal plane at the sensor's height; surfaces lower than the plane are
  not seen. Plants are separate cylinders, so beams pass through the gaps between them as the
  paper's Figure 6(a) shows. Simplification: the whole revolution is taken at one pose (the
  ~0.14 s sweep's motion distortion is not modelled).
"""

from __future__ import annotations

import math

import numpy as np

from sandbox.msgs.sensor_msgs import LaserScan
from server.sim.sensors.base import SenseContext, StatelessSensor
from server.sim.sensors.frames import TWO_PI, stamped_header
from server.sim.sensors.mount import Mount

# Defaults (YDLidar X2 datasheet unless noted)
# | name                    | value  | unit      | why                                            |
# |-------------------------|--------|-----------|------------------------------------------------|
_SCAN_RATE_HZ = 7.0  # [Hz]       motor speed: one revolution ~ every 0.14 s
_SAMPLE_RATE_HZ = 3000.0  # [1/s] ranging frequency; beams = 3000 / 7 = 429
_RANGE_MIN_M = 0.12  # [m]        closer returns are invalid
_RANGE_MAX_M = 8.0  # [m]         farther returns are invalid
_NOISE_SD_M = 0.008  # [m]        range-independent part of the range noise
_NOISE_SD_PER_M = 0.002  # [m/m]  part that grows with range (weaker return)
_MOUNT_FORWARD_M = 0.0  # [m]    centred on the top floor (Figure 1)
_SCAN_PLANE_HEIGHT_M = 0.29  # [m] top of the 0.29 m tall robot (paper section 2)
_NO_RETURN_M = 0.0  # [m]         what the driver reports for an invalid beam


class Lidar2D(StatelessSensor):
    """YDLidar X2-like 360-degree scanner publishing sensor_msgs/LaserScan (see module doc)."""

    msg_type = LaserScan

    def __init__(
        self,
        *,
        rate_hz: float = _SCAN_RATE_HZ,
        sample_rate_hz: float = _SAMPLE_RATE_HZ,
        range_min_m: float = _RANGE_MIN_M,
        range_max_m: float = _RANGE_MAX_M,
        noise_sd_m: float = _NOISE_SD_M,
        noise_sd_per_m: float = _NOISE_SD_PER_M,
        mount_forward_m: float = _MOUNT_FORWARD_M,
        scan_plane_height_m: float = _SCAN_PLANE_HEIGHT_M,
        frame_id: str = "laser",
    ) -> None:
        if not 0.0 < range_min_m < range_max_m:
            raise ValueError(
                f"Lidar2D needs 0 < range_min_m < range_max_m, got {range_min_m}, {range_max_m}."
            )
        if rate_hz <= 0.0 or sample_rate_hz < 4.0 * rate_hz:
            raise ValueError(
                "Lidar2D needs rate_hz > 0 and at least 4 samples per revolution "
                f"(sample_rate_hz >= 4 * rate_hz), got {rate_hz} Hz and {sample_rate_hz} /s."
            )
        self.rate_hz = float(rate_hz)
        self.sample_rate_hz = float(sample_rate_hz)
        self.range_min_m = float(range_min_m)
        self.range_max_m = float(range_max_m)
        self.noise_sd_m = float(noise_sd_m)
        self.noise_sd_per_m = float(noise_sd_per_m)
        self.mount = Mount(x_m=float(mount_forward_m))
        self.scan_plane_height_m = float(scan_plane_height_m)
        self.frame_id = frame_id
        self.beam_count = round(self.sample_rate_hz / self.rate_hz)
        self.angle_increment_rad = TWO_PI / self.beam_count
        self.beam_angles_rad = -math.pi + self.angle_increment_rad * np.arange(self.beam_count)
        # Figure 5: lidar angle 0 is the rear and angles grow clockwise.
        self._robot_directions_rad = math.pi - self.beam_angles_rad

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> LaserScan:
        x_m, y_m, heading_rad = self.mount.in_world(ctx.state.pose)
        hits = ctx.obstacles.cast(
            np.array([x_m, y_m]),
            heading_rad + self._robot_directions_rad,
            self.range_max_m,
            min_height_m=self.scan_plane_height_m,
        )
        true_m = hits.distance_m
        finite = np.isfinite(true_m)
        sd_m = self.noise_sd_m + self.noise_sd_per_m * np.where(finite, true_m, 0.0)
        measured_m = true_m + sd_m * rng.standard_normal(self.beam_count)
        valid = finite & (measured_m >= self.range_min_m) & (measured_m <= self.range_max_m)
        ranges = np.where(valid, measured_m, _NO_RETURN_M).astype(np.float32)
        return LaserScan(
            header=stamped_header(ctx.time_s, self.frame_id),
            angle_min=float(self.beam_angles_rad[0]),
            angle_max=float(self.beam_angles_rad[-1]),
            angle_increment=self.angle_increment_rad,
            time_increment=1.0 / self.sample_rate_hz,
            scan_time=1.0 / self.rate_hz,
            range_min=self.range_min_m,
            range_max=self.range_max_m,
            ranges=ranges,
            intensities=[],
        )
