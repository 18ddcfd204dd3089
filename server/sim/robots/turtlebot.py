"""`turtlebot`: the Roomba-based TurtleBot of 003_4f92d1fa0a49ddae.txt.

An iRobot Roomba 531 base driven by body velocities (section 2.1: the base handles the wheel
transformations, eq. 2.7, internally), a RealSense D435 whose depth image is sliced into a laser
scan at ~0.45 m (sections 3.3 and 5), seven HC-SR04 rangers fired one after another (section
3.4) and a simulated IMU (section 5, "Simulated IMU"), as the thesis's ROS 2 network presents
them:

- publishes `odom` (nav_msgs/Odometry), `imu` (sensor_msgs/Imu), `bumper`
  (std_msgs/Int32MultiArray [left, right]), `scan` (sensor_msgs/LaserScan from depth),
  `ultrasonic/range_0` .. `ultrasonic/range_6` (sensor_msgs/Range, right to left);
- subscribes `cmd_vel` (geometry_msgs/Twist).

| constant | value | why |
|---|---|---|
| body radius | 0.17 m | Roomba 500 series, 34 cm across |
| wheel radius, track | 0.036 m, 0.235 m | Create Open Interface spec |
| wheel speed limit | 0.5 m/s per wheel | Drive Direct accepts -500..500 mm/s |
| acceleration | 1.0 m/s^2 per wheel | what the base firmware ramps to (assumption) |
"""

from __future__ import annotations

from typing import ClassVar

from sandbox.msgs.geometry_msgs import Twist
from server.sim.motors import VelocityMotors
from server.sim.robots.base import Motors, RobotGeometry, RobotLimits, RobotModel, clamp_twist
from server.sim.sensors.base import Sensor
from server.sim.sensors.depth_scan import DepthScan
from server.sim.sensors.imu import Imu
from server.sim.sensors.odometry import Bumper, WheelOdometry
from server.sim.sensors.ultrasonic_ring import UltrasonicRing
from server.sim.state import RobotState

WHEEL_RADIUS_M = 0.036  # [m]
TRACK_M = 0.235  # [m]
MAX_WHEEL_M_S = 0.5  # [m/s]
MAX_WHEEL_ACCEL_M_S2 = 1.0  # [m/s^2]
RATE_ODOM_HZ = 20.0  # [Hz] create driver's odometry rate (assumption)
RATE_IMU_HZ = 50.0  # [Hz] Gazebo IMU plugin default update rate in the thesis's setup
RATE_BUMPER_HZ = 20.0  # [Hz] sensor stream polling
ULTRASONIC_RING = UltrasonicRing()  # its geometry, for the sensor frames


class TurtleBot(RobotModel):
    id = "turtlebot"
    title = "TurtleBot (Roomba 531 base, depth scan, ultrasonic ring)"
    source = "003_4f92d1fa0a49ddae.txt sections 2.1, 3.1-3.4, 5"
    geometry = RobotGeometry(
        body_radius_m=0.17,
        wheel_radius_m=WHEEL_RADIUS_M,
        track_m=TRACK_M,
        length_m=0.34,
        width_m=0.34,
        height_m=0.45,
    )
    limits = RobotLimits(
        max_linear_m_s=MAX_WHEEL_M_S, max_angular_rad_s=2 * MAX_WHEEL_M_S / TRACK_M
    )
    commands: ClassVar = {
        "cmd_vel": (Twist, "velocity command: linear.x [m/s], angular.z [rad/s]"),
    }
    frames: ClassVar = {
        "camera_depth_frame": (0.0, 0.0, 0.0),
        "imu_link": (0.0, 0.0, 0.0),
        **{
            ranger.frame_id: (ranger.mount.x_m, ranger.mount.y_m, ranger.mount.yaw_rad)
            for ranger in ULTRASONIC_RING.rangers
        },
    }
    sensor_descriptions: ClassVar = {
        "odom": "wheel odometry (drifts): pose in the odom frame and body velocities",
        "imu": "orientation, yaw rate and acceleration of the base",
        "bumper": "bump switches [left, right], 1 = pressed",
        "scan": "laser scan sliced from the depth camera, 87 deg ahead, 0.3-3 m",
        **{
            f"ultrasonic/range_{i}": f"HC-SR04 ranger {i} of 7 (0 = right, 6 = left), 0.02-4 m"
            for i in range(7)
        },
    }

    def build_sensors(self) -> dict[str, Sensor]:
        return {
            "odom": WheelOdometry(
                rate_hz=RATE_ODOM_HZ, wheel_radius_m=WHEEL_RADIUS_M, track_m=TRACK_M
            ),
            "imu": Imu(rate_hz=RATE_IMU_HZ),
            "bumper": Bumper(rate_hz=RATE_BUMPER_HZ),
            "scan": DepthScan(),
            **UltrasonicRing().topics,
        }

    def build_motors(self) -> Motors:
        return VelocityMotors(
            wheel_radius_m=WHEEL_RADIUS_M,
            track_m=TRACK_M,
            max_wheel_rad_s=MAX_WHEEL_M_S / WHEEL_RADIUS_M,
            max_wheel_accel_rad_s2=MAX_WHEEL_ACCEL_M_S2 / WHEEL_RADIUS_M,
            time_constant_s=0.05,  # [s]
        )

    def apply_command(
        self, topic: str, message: object, state: RobotState, motors: Motors, time_s: float
    ) -> None:
        motors.command(*clamp_twist(message.linear.x, message.angular.z, self.limits))
