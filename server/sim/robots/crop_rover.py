"""`crop_rover`: the LiDAR + IMU crop-row rover of 001_8d7ab1b8a58c0603.txt.

A differential-drive rover about 0.19 m long, 0.2 m wide, 0.29 m tall, 1.5 kg (section 2), with a
YDLidar X2 on the top floor (0 rad at the rear, left side in (0, pi), right in (-pi, 0); Figure 5)
and a BNO055 yaw read through an Arduino (Figure 4, 8). The paper's ROS graph (Figure 8): the
Arduino node publishes the orientation psi, the LIDAR node computes the lateral distance l, the
fuzzy node publishes the control word u, which the Arduino turns into motor signals: negative u
steers left, positive u steers right (section 2.2; the fuzzy output spans about -85..+85).

- publishes `scan` (sensor_msgs/LaserScan, ~7 Hz), `psi` (std_msgs/Float32, yaw [rad]),
  `imu` (sensor_msgs/Imu), `odom` (nav_msgs/Odometry);
- subscribes `u` (std_msgs/Float32, control word -100..100) and `cmd_vel` (geometry_msgs/Twist).

How the Arduino turns u into motion (the paper does not give it; assumption, documented): the
rover cruises at `CRUISE_M_S` and turns at `-u / 100 * MAX_TURN_RAD_S` (positive u = clockwise, a
right turn). A Twist on `cmd_vel` replaces the u behaviour until the next u arrives.

| constant | value | why |
|---|---|---|
| collision radius | 0.138 m | circumscribed circle of 0.19 x 0.2 m |
| wheel radius, track | 0.035 m, 0.17 m | 12 V gear motors with 7 cm wheels (assumption) |
| cruise speed | 0.15 m/s | walking pace between rows (assumption) |
| max turn | 1.2 rad/s | at |u| = 100 |
"""

from __future__ import annotations

import math
from typing import ClassVar

from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.std_msgs import Float32
from server.sim.motors import VelocityMotors
from server.sim.robots.base import (
    CommandError,
    Motors,
    RobotGeometry,
    RobotLimits,
    RobotModel,
    clamp_twist,
)
from server.sim.sensors.base import Sensor
from server.sim.sensors.imu import Imu, ImuYaw
from server.sim.sensors.lidar import Lidar2D
from server.sim.sensors.odometry import WheelOdometry
from server.sim.state import RobotState

WHEEL_RADIUS_M = 0.035  # [m]
TRACK_M = 0.17  # [m]
CRUISE_M_S = 0.15  # [m/s]
MAX_TURN_RAD_S = 1.2  # [rad/s] at |u| = 100
U_LIMIT = 100.0  # [1] control words beyond +-100 are rejected
RATE_PSI_HZ = 20.0  # [Hz] Arduino bridge
RATE_IMU_HZ = 50.0  # [Hz]
RATE_ODOM_HZ = 20.0  # [Hz]


class CropRover(RobotModel):
    id = "crop_rover"
    title = "Crop-row rover (YDLidar X2, BNO055, fuzzy row following)"
    source = "001_8d7ab1b8a58c0603.txt sections 2, 2.1, 2.2, Figures 5, 7, 8"
    geometry = RobotGeometry(
        body_radius_m=math.hypot(0.19, 0.2) / 2,
        wheel_radius_m=WHEEL_RADIUS_M,
        track_m=TRACK_M,
        length_m=0.19,
        width_m=0.2,
        height_m=0.29,
    )
    limits = RobotLimits(max_linear_m_s=0.4, max_angular_rad_s=3.0)
    commands: ClassVar = {
        "u": (Float32, "fuzzy control word -100..100: negative steers left, positive right"),
        "cmd_vel": (Twist, "velocity command: linear.x [m/s], angular.z [rad/s]"),
    }
    # The YDLidar's angles grow clockwise from the rear (Figure 5): the frame is turned half a
    # circle and mounted upside down, so ROS tools draw beam a in robot direction pi - a.
    frames: ClassVar = {"laser": (0.0, 0.0, math.pi, math.pi), "imu_link": (0.0, 0.0, 0.0)}
    sensor_descriptions: ClassVar = {
        "scan": "360 deg LiDAR scan: 0 rad at the rear, left side (0, pi), right side (-pi, 0)",
        "psi": "yaw from the BNO055 [rad], drifts slowly",
        "imu": "orientation, yaw rate and acceleration",
        "odom": "wheel odometry (drifts)",
    }

    def build_sensors(self) -> dict[str, Sensor]:
        return {
            "scan": Lidar2D(),
            "psi": ImuYaw(rate_hz=RATE_PSI_HZ),
            "imu": Imu(rate_hz=RATE_IMU_HZ),
            "odom": WheelOdometry(
                rate_hz=RATE_ODOM_HZ, wheel_radius_m=WHEEL_RADIUS_M, track_m=TRACK_M
            ),
        }

    def build_motors(self) -> Motors:
        return VelocityMotors(
            wheel_radius_m=WHEEL_RADIUS_M,
            track_m=TRACK_M,
            max_wheel_rad_s=self.limits.max_linear_m_s / WHEEL_RADIUS_M,
            max_wheel_accel_rad_s2=20.0,  # [rad/s^2] 1.5 kg on small gear motors
            time_constant_s=0.08,  # [s]
        )

    def apply_command(
        self, topic: str, message: object, state: RobotState, motors: Motors, time_s: float
    ) -> None:
        if topic == "u":
            if not -U_LIMIT <= message.data <= U_LIMIT:
                raise CommandError(
                    f"u must be between {-U_LIMIT:g} and {U_LIMIT:g} (negative = left), "
                    f"got {message.data:g}"
                )
            motors.command(CRUISE_M_S, -message.data / U_LIMIT * MAX_TURN_RAD_S)
        elif topic == "cmd_vel":
            motors.command(*clamp_twist(message.linear.x, message.angular.z, self.limits))
