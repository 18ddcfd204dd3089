"""`ir_scout`: the BeagleBone Black miniQ robot of 002_3fcfeb7b4c14107a.txt.

A 2WD miniQ chassis (12.2 cm diameter, 4.2 cm wheels, section II) with a Sharp-style IR
rangefinder on an RC servo. The paper splits obstacle avoidance into four ROS nodes (sensor,
servo, compare_distance, dc_motor; Fig. 8); the robot itself offers the hardware side of those
nodes:

- publishes `ir_adc` (std_msgs/Int32, the raw AIN0 count the paper's sensor node converts to cm),
  `ir_range` (sensor_msgs/Range, metres) and `servo_position` (std_msgs/Int16, degrees);
- subscribes `servo_angle` (std_msgs/Int16, 0-180 degrees: 90 ahead, 0 right, 180 left, as the
  paper's 0/180 degree checks), `motor_command` (std_msgs/String: forward, backward, left,
  right, stop, as the dc_motor node prints them, Fig. 14) and `cmd_vel` (geometry_msgs/Twist).

| constant | value | why |
|---|---|---|
| track | 0.10 m | wheel separation of the miniQ chassis (assumption: not in the paper) |
| forward speed | 0.12 m/s | the paper's micro gear motors at the duty dc_motor uses (assumption) |
| turn rate | 1.5 rad/s | in-place turn at the same duty |
| servo slew | 500 deg/s | SG90-class servo, 0.12 s per 60 degrees |
| sensor rate | 25 Hz | the GP2Y0A21 updates every ~38 ms |
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.std_msgs import Int16, String
from server.sim.motors import VelocityMotors
from server.sim.robots.base import (
    CommandError,
    Motors,
    RobotGeometry,
    RobotLimits,
    RobotModel,
    clamp_twist,
)
from server.sim.sensors.base import SenseContext, Sensor, StatelessSensor
from server.sim.sensors.ir_ranger import IrAdc, IrRange
from server.sim.sensors.mount import Mount
from server.sim.state import RobotState

SENSOR_RATE_HZ = 25.0  # [Hz]
IR_MOUNT = Mount(x_m=0.045)  # [m] servo horn near the front edge
WHEEL_RADIUS_M = 0.021  # [m] 4.2 cm wheels (section II)
TRACK_M = 0.10  # [m]
SERVO_SLEW_DEG_S = 500.0  # [deg/s]
SERVO_MIN_DEG, SERVO_MAX_DEG = 0, 180
FORWARD_M_S = 0.12  # [m/s]
BACKWARD_M_S = -0.08  # [m/s] slower in reverse: the caster drags
TURN_RAD_S = 1.5  # [rad/s]
MOTOR_WORDS = {
    "forward": (FORWARD_M_S, 0.0),
    "backward": (BACKWARD_M_S, 0.0),
    "left": (0.0, TURN_RAD_S),
    "right": (0.0, -TURN_RAD_S),
    "stop": (0.0, 0.0),
}


class ServoPosition(StatelessSensor):
    """Where the servo points now [deg], as a feedback pot would report it."""

    msg_type = Int16

    def __init__(self, rate_hz: float) -> None:
        self.rate_hz = rate_hz

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Int16:
        return Int16(data=round(ctx.state.servo_angle_deg))


class IrScout(RobotModel):
    id = "ir_scout"
    title = "miniQ IR scout (BeagleBone Black, IR ranger on a servo)"
    source = "002_3fcfeb7b4c14107a.txt sections II-III, Fig. 3-8"
    geometry = RobotGeometry(
        body_radius_m=0.061,  # [m] 12.2 cm chassis
        wheel_radius_m=WHEEL_RADIUS_M,
        track_m=TRACK_M,
        length_m=0.122,
        width_m=0.122,
        height_m=0.09,
    )
    limits = RobotLimits(max_linear_m_s=0.25, max_angular_rad_s=4.0)
    commands: ClassVar = {
        "servo_angle": (
            Int16,
            "point the IR ranger: degrees 0 (right) .. 90 (ahead) .. 180 (left)",
        ),
        "motor_command": (String, "drive: 'forward', 'backward', 'left', 'right' or 'stop'"),
        "cmd_vel": (Twist, "velocity command: linear.x [m/s], angular.z [rad/s]"),
    }
    sensor_descriptions: ClassVar = {
        "ir_adc": "raw 12-bit ADC count of the IR ranger (higher = closer)",
        "ir_range": "IR range [m], 0.10-0.80 m; inf when nothing is in range",
        "servo_position": "angle the servo points the ranger at now [deg]",
    }

    def build_sensors(self) -> dict[str, Sensor]:
        return {
            "ir_adc": IrAdc(IR_MOUNT, SENSOR_RATE_HZ),
            "ir_range": IrRange(IR_MOUNT, SENSOR_RATE_HZ),
            "servo_position": ServoPosition(SENSOR_RATE_HZ),
        }

    def build_motors(self) -> Motors:
        return VelocityMotors(
            wheel_radius_m=WHEEL_RADIUS_M,
            track_m=TRACK_M,
            max_wheel_rad_s=self.limits.max_linear_m_s / WHEEL_RADIUS_M,
            max_wheel_accel_rad_s2=60.0,  # [rad/s^2] light robot, strong gearing
            time_constant_s=0.04,  # [s]
        )

    def apply_command(
        self, topic: str, message: object, state: RobotState, motors: Motors, time_s: float
    ) -> None:
        if topic == "servo_angle":
            if not SERVO_MIN_DEG <= message.data <= SERVO_MAX_DEG:
                raise CommandError(
                    f"servo_angle must be between {SERVO_MIN_DEG} and {SERVO_MAX_DEG} degrees, "
                    f"got {message.data}"
                )
            state.servo_target_deg = float(message.data)
        elif topic == "motor_command":
            word = message.data.strip().lower()
            if word not in MOTOR_WORDS:
                raise CommandError(
                    f"motor_command {message.data!r} is not a direction; use one of "
                    + ", ".join(repr(w) for w in MOTOR_WORDS)
                )
            motors.command(*MOTOR_WORDS[word])
        elif topic == "cmd_vel":
            motors.command(*clamp_twist(message.linear.x, message.angular.z, self.limits))

    def sensor_frames(self, state: RobotState) -> dict[str, tuple[float, ...]]:
        # The ranger turns with the servo: 90 degrees points it ahead.
        servo_rad = math.radians(state.servo_angle_deg - 90.0)
        return {"ir_link": (IR_MOUNT.x_m, IR_MOUNT.y_m, IR_MOUNT.yaw_rad + servo_rad)}

    def advance(self, state: RobotState, dt_s: float, time_s: float) -> None:
        super().advance(state, dt_s, time_s)
        error = state.servo_target_deg - state.servo_angle_deg
        if error:
            step = math.copysign(min(abs(error), SERVO_SLEW_DEG_S * dt_s), error)
            state.servo_angle_deg += step
