"""The TurtleBot's depth camera as the navigation stack sees it: a RealSense D435 depth image
turned into a planar scan by depthimage_to_laserscan.

Source: 003_4f92d1fa0a49ddae.txt section 3.3 (D435, ideal operating range 0.3-3 m, mounted in
the centre of the uppermost layer) and section 5.7 "Depth Image Processing" (rows sliced from the
image centre, minimum depth per column, representing the environment ~45 cm above the ground,
published on /scan). Field of view: the D435 datasheet's 87 degrees horizontal.

- Message: sensor_msgs/LaserScan, frame "camera_depth_frame" (depthimage_to_laserscan's
  default output frame). ROS angles: 0 = straight ahead, counter-clockwise positive, so
  `angle_min` = -FOV/2 (right edge) and `angle_max` = +FOV/2 (left edge); 320 beams evenly
  spaced in angle (a simplification: real columns are evenly spaced in tan(angle)).
- Units and range: metres, 0.3-3 m. Out of range or nothing seen reads NaN, as
  depthimage_to_laserscan leaves a column it could not fill (its ranges start as NaN and an
  out-of-range point never replaces them; the D435 reports depth 0 = invalid past its range).
- Noise: stereo depth error grows with the square of the depth. It is applied to the DEPTH along
  the optical axis (sd = 1 mm + 0.005 /m * z^2, from the D435's RMS error
  z^2 * subpixel / (focal_px * baseline) with subpixel 0.08, focal ~ 340 px, baseline 50 mm),
  then converted to range as depthimage_to_laserscan does (range = depth / cos(angle)).
- Rate: 15 Hz (depth stream at 15 fps, what the Raspberry Pi could convert; assumption).
  All columns come from one global-shutter frame, so `time_increment` = 0.
- Only geometry at least as tall as the slice height (0.45 m) is seen: a low box under the slice
  is invisible, which is why the paper marks such objects in the static map (chapter 6).
"""

from __future__ import annotations

import math

import numpy as np

from sandbox.msgs.sensor_msgs import LaserScan
from server.sim.sensors.base import SenseContext, StatelessSensor
from server.sim.sensors.frames import stamped_header
from server.sim.sensors.mount import Mount

# Defaults
# | name                 | value      | unit   | source / why                                   |
# |----------------------|------------|--------|------------------------------------------------|
_RATE_HZ = 15.0  # [Hz]                   depth stream rate converted on the RPi (assumption)
_BEAM_COUNT = 320  # [-]                  columns of a 320-px-wide depth image
_HORIZONTAL_FOV_RAD = math.radians(87.0)  # [rad] D435 depth field of view
_RANGE_MIN_M = 0.3  # [m]                 paper section 3.3
_RANGE_MAX_M = 3.0  # [m]                 paper section 3.3
_SLICE_HEIGHT_M = 0.45  # [m]             paper section 5.7, "Depth Image Processing"
_MOUNT_FORWARD_M = 0.0  # [m]             centre of the uppermost layer (section 3.3)
_DEPTH_NOISE_SD_M = 0.001  # [m]          floor of the depth noise
_DEPTH_NOISE_PER_M2 = 0.005  # [1/m]      stereo error: sd grows as depth^2
_NO_READING = math.nan  # [m]             what depthimage_to_laserscan leaves in an empty column


class DepthScan(StatelessSensor):
    """D435 depth image sliced to a forward-facing LaserScan (see module doc)."""

    msg_type = LaserScan

    def __init__(
        self,
        *,
        rate_hz: float = _RATE_HZ,
        beam_count: int = _BEAM_COUNT,
        horizontal_fov_rad: float = _HORIZONTAL_FOV_RAD,
        range_min_m: float = _RANGE_MIN_M,
        range_max_m: float = _RANGE_MAX_M,
        slice_height_m: float = _SLICE_HEIGHT_M,
        mount_forward_m: float = _MOUNT_FORWARD_M,
        depth_noise_sd_m: float = _DEPTH_NOISE_SD_M,
        depth_noise_per_m2: float = _DEPTH_NOISE_PER_M2,
        frame_id: str = "camera_depth_frame",
    ) -> None:
        if beam_count < 2 or not 0.0 < horizontal_fov_rad < math.pi:
            raise ValueError(
                "DepthScan needs beam_count >= 2 and 0 < horizontal_fov_rad < pi, "
                f"got {beam_count} and {horizontal_fov_rad}."
            )
        if not 0.0 < range_min_m < range_max_m:
            raise ValueError(
                f"DepthScan needs 0 < range_min_m < range_max_m, got {range_min_m}, {range_max_m}."
            )
        self.rate_hz = float(rate_hz)
        self.beam_count = int(beam_count)
        self.horizontal_fov_rad = float(horizontal_fov_rad)
        self.range_min_m = float(range_min_m)
        self.range_max_m = float(range_max_m)
        self.slice_height_m = float(slice_height_m)
        self.mount = Mount(x_m=float(mount_forward_m))
        self.depth_noise_sd_m = float(depth_noise_sd_m)
        self.depth_noise_per_m2 = float(depth_noise_per_m2)
        self.frame_id = frame_id
        half_fov = 0.5 * self.horizontal_fov_rad
        self.beam_angles_rad = np.linspace(-half_fov, half_fov, self.beam_count)
        self.angle_increment_rad = self.horizontal_fov_rad / (self.beam_count - 1)
        self._cos_beam = np.cos(self.beam_angles_rad)

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> LaserScan:
        x_m, y_m, heading_rad = self.mount.in_world(ctx.state.pose)
        hits = ctx.obstacles.cast(
            np.array([x_m, y_m]),
            heading_rad + self.beam_angles_rad,
            # Cast a little past range_max so noise can carry a far hit back into range.
            self.range_max_m * 1.2,
            min_height_m=self.slice_height_m,
        )
        true_depth_m = hits.distance_m * self._cos_beam  # along the optical axis
        finite = np.isfinite(true_depth_m)
        depth_or_zero = np.where(finite, true_depth_m, 0.0)
        sd_m = self.depth_noise_sd_m + self.depth_noise_per_m2 * depth_or_zero**2
        measured_depth_m = depth_or_zero + sd_m * rng.standard_normal(self.beam_count)
        range_m = measured_depth_m / self._cos_beam
        valid = finite & (range_m >= self.range_min_m) & (range_m <= self.range_max_m)
        ranges = np.where(valid, range_m, _NO_READING).astype(np.float32)
        return LaserScan(
            header=stamped_header(ctx.time_s, self.frame_id),
            angle_min=float(self.beam_angles_rad[0]),
            angle_max=float(self.beam_angles_rad[-1]),
            angle_increment=self.angle_increment_rad,
            time_increment=0.0,
            scan_time=1.0 / self.rate_hz,
            range_min=self.range_min_m,
            range_max=self.range_max_m,
            ranges=ranges,
            intensities=[],
        )
