"""`turtlebot3`: the ROBOTIS TurtleBot3 Burger as its ROS 1 (noetic) bringup presents it, the
robot most ROS 1 courses are written for.

Topics (turtlebot3_bringup turtlebot3_robot.launch: the OpenCR firmware through rosserial, and
the LDS-01 driver):

- publishes `scan` (sensor_msgs/LaserScan, 360 beams, index 0 ahead, counter-clockwise, 0.0 for
  no return; server.sim.sensors.lds01), `odom` (nav_msgs/Odometry, frame `odom`, child
  `base_footprint`), `imu` (sensor_msgs/Imu, frame `imu_link`, yaw 0 at start-up);
- subscribes `cmd_vel` (geometry_msgs/Twist): linear.x and angular.z, clamped as the firmware
  does; a command older than 0.5 s stops the wheels (the firmware's watchdog,
  server.sim.motors.OpenCrMotors), so a controller must keep publishing, as on the real robot.

Not modelled (say so to students who look for them): `joint_states`, `battery_state`,
`sensor_state` (turtlebot3_msgs/SensorState), `firmware_version`, `magnetic_field`,
`cmd_vel_rc100`, `rpms`, `diagnostics`; the subscribers `sound`, `motor_power`, `reset`.

Frames: base_link is the point between the wheels (URDF: base_footprint -> base_link 10 mm up);
the scanner and the IMU sit 32 mm behind it; the body's centre too.

| constant | value | source |
|---|---|---|
| wheel radius | 0.033 m | turtlebot3_burger.h WHEEL_RADIUS; URDF wheel cylinder |
| wheel separation | 0.160 m | turtlebot3_burger.h WHEEL_SEPARATION; URDF wheels at y +-0.08 |
| max linear | 0.2108 m/s | turtlebot3_burger.h: r 2 pi 61 rpm / 60; constrain() on cmd_vel |
| max angular | 2.635 rad/s | turtlebot3_burger.h: max linear / TURNING_RADIUS 0.080 m |
| (e-manual) | 0.22 m/s, 2.84 rad/s | e-manual and turtlebot3_teleop; the firmware clamps lower |
| wheel units | 41.7 per rad/s, +-265 | turtlebot3_motor_driver.h VELOCITY_CONSTANT_VALUE |
| control, watchdog | 30 Hz, 0.5 s | turtlebot3_core_config.h CONTROL_MOTOR_SPEED_FREQUENCY |
| odom, imu rates | 30 Hz, 200 Hz | turtlebot3_core_config.h DRIVE_INFORMATION_, IMU_PUBLISH_ |
| imu covariances | 0.0025, 0.02, 0.04 | OpenCR turtlebot3_sensor.cpp getIMU() diagonals |
| size L x W x H | 138 x 178 x 192 mm | e-manual Specifications (W includes the wheels) |
| mass | 1 kg | e-manual Specifications (with SBC, battery, sensors) |
| body centre, sensors | 32 mm behind the axle | URDF collision box, imu_joint, scan_joint |
| collision radius | 0.113 m | circumscribed circle of 138 x 178 mm round the body centre |
| wheel acceleration | 2.5 m/s^2 | turtlebot3_navigation dwa_local_planner_params_burger |
| wheel lag | 0.05 s | Dynamixel XL430 velocity loop (assumption) |

Sources: ROBOTIS-GIT/OpenCR noetic-devel (arduino/opencr_arduino/opencr/libraries/turtlebot3),
ROBOTIS-GIT/turtlebot3 noetic (turtlebot3_bringup, turtlebot3_description), the ROBOTIS
e-manual (emanual.robotis.com/docs/en/platform/turtlebot3/specifications/).
"""

from __future__ import annotations

import math
from typing import ClassVar

from sandbox.msgs.geometry_msgs import Twist
from server.sim.motors import (
    TB3_BURGER_LIMIT_UNITS,
    TB3_UNITS_PER_RAD_S,
    OpenCrMotors,
    VelocityMotors,
)
from server.sim.robots.base import Motors, RobotGeometry, RobotLimits, RobotModel, clamp_twist
from server.sim.sensors.base import Sensor
from server.sim.sensors.imu import Imu
from server.sim.sensors.lds01 import MOUNT_X_M, Lds01
from server.sim.sensors.odometry import WheelOdometry
from server.sim.state import RobotState

WHEEL_RADIUS_M = 0.033  # [m]
WHEEL_SEPARATION_M = 0.160  # [m]
TURNING_RADIUS_M = 0.080  # [m] firmware: half the wheel separation
MAX_WHEEL_RPM = 61.0  # [rpm] the firmware's figure for the XL430 at 12 V
# The firmware writes pi as 3.14159265359; the difference from math.pi is below 1e-12.
MAX_LINEAR_M_S = WHEEL_RADIUS_M * 2 * math.pi * MAX_WHEEL_RPM / 60  # [m/s] 0.2108
MAX_ANGULAR_RAD_S = MAX_LINEAR_M_S / TURNING_RADIUS_M  # [rad/s] 2.635
MAX_WHEEL_ACCEL_M_S2 = 2.5  # [m/s^2] ROBOTIS's planner limit for the Burger
WHEEL_LAG_S = 0.05  # [s] assumption
RATE_ODOM_HZ = 30.0  # [Hz] DRIVE_INFORMATION_PUBLISH_FREQUENCY
RATE_IMU_HZ = 200.0  # [Hz] IMU_PUBLISH_FREQUENCY
# getIMU(): orientation, angular velocity, linear acceleration variances (diagonals).
IMU_COVARIANCES = (0.0025, 0.02, 0.04)  # [rad^2, (rad/s)^2, (m/s^2)^2]
SENSOR_X_M = MOUNT_X_M  # [m] base_scan and imu_link, 32 mm behind base_link
_ZERO_VARIANCES = (0.0,) * 6  # the firmware leaves the odometry covariances unset


class TurtleBot3(RobotModel):
    id = "turtlebot3"
    title = "TurtleBot3 Burger (LDS-01 lidar, OpenCR, ROS 1 noetic bringup)"
    source = (
        "ROBOTIS e-manual TurtleBot3 specifications and LDS-01 appendix; ROBOTIS-GIT/OpenCR "
        "turtlebot3_core (noetic-devel); ROBOTIS-GIT/turtlebot3 noetic bringup and URDF"
    )
    geometry = RobotGeometry(
        body_radius_m=math.ceil(math.hypot(0.138, 0.178) / 2 * 1000) / 1000,  # [m] 0.113
        wheel_radius_m=WHEEL_RADIUS_M,
        track_m=WHEEL_SEPARATION_M,
        length_m=0.138,
        width_m=0.178,
        height_m=0.192,
        body_offset_x_m=SENSOR_X_M,
    )
    limits = RobotLimits(max_linear_m_s=MAX_LINEAR_M_S, max_angular_rad_s=MAX_ANGULAR_RAD_S)
    commands: ClassVar = {
        "cmd_vel": (
            Twist,
            "velocity command: linear.x [m/s] (+-0.21), angular.z [rad/s] (+-2.63); "
            "the wheels stop 0.5 s after the last one",
        ),
    }
    # base_footprint hangs below base_link here (the real tree has it as base_link's parent,
    # 10 mm lower): /tf stays a tree with the run's map -> base_link, and the odometry's child
    # frame exists for tf lookups.
    frames: ClassVar = {
        "base_footprint": (0.0, 0.0, 0.0),
        "base_scan": (SENSOR_X_M, 0.0, 0.0),
        "imu_link": (SENSOR_X_M, 0.0, 0.0),
    }
    sensor_descriptions: ClassVar = {
        "scan": "LDS-01 lidar: 360 ranges [m], index 0 ahead, counter-clockwise, "
        "0.12-3.5 m, 0.0 = no return",
        "odom": "wheel odometry from start-up: pose in odom, child base_footprint (drifts)",
        "imu": "orientation (yaw 0 at start-up), yaw rate and acceleration",
    }

    def build_sensors(self) -> dict[str, Sensor]:
        return {
            "scan": Lds01(),
            "odom": WheelOdometry(
                rate_hz=RATE_ODOM_HZ,
                wheel_radius_m=WHEEL_RADIUS_M,
                track_m=WHEEL_SEPARATION_M,
                child_frame_id="base_footprint",
                pose_variances=_ZERO_VARIANCES,
                twist_variances=_ZERO_VARIANCES,
            ),
            "imu": Imu(
                rate_hz=RATE_IMU_HZ, heading_from_start=True, fixed_covariances=IMU_COVARIANCES
            ),
        }

    def build_motors(self) -> Motors:
        wheels = VelocityMotors(
            wheel_radius_m=WHEEL_RADIUS_M,
            track_m=WHEEL_SEPARATION_M,
            max_wheel_rad_s=TB3_BURGER_LIMIT_UNITS / TB3_UNITS_PER_RAD_S,
            max_wheel_accel_rad_s2=MAX_WHEEL_ACCEL_M_S2 / WHEEL_RADIUS_M,
            time_constant_s=WHEEL_LAG_S,
        )
        return OpenCrMotors(WHEEL_RADIUS_M, WHEEL_SEPARATION_M, wheels)

    def apply_command(
        self, topic: str, message: object, state: RobotState, motors: Motors, time_s: float
    ) -> None:
        # The firmware's cmd_vel callback: constrain() each velocity, then the motor loop.
        motors.command(*clamp_twist(message.linear.x, message.angular.z, self.limits))
