"""`crowbot`: the ESP32 CrowBot BOLT of 000_32b6074bbd2115c3.txt, as its firmware presents it.

Topics (section 2.4, Fig. 6, Table 1; names and types exactly as the firmware advertises them):
publishes `Distance` (std_msgs/Int32, cm), `Button` (std_msgs/Bool), `Light` and `Line`
(std_msgs/Int32MultiArray, [right, left], 12-bit); subscribes `Control` (geometry_msgs/Twist),
`Leds` (std_msgs/Int32MultiArray [r, g, b], all four LEDs), `Buzzer` (std_msgs/Bool: true plays
B4 for one second).

Wheels: r = 0.02 m, d = 0.08 m, K = 40 (Table 2), driven through the firmware's PWM path
(server.sim.motors.CrowBotFirmwareMotors): top speed 255 / K = 6.4 rad/s per wheel, 0.128 m/s.

Rates: the paper runs its controllers at 10 and 20 Hz (section 3.5); the firmware loop publishes
every sensor at 20 Hz here so a 20 Hz controller always has a fresh reading.
"""

from __future__ import annotations

from typing import ClassVar

from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.std_msgs import Bool, Int32MultiArray
from server.sim.motors import (
    CROWBOT_PWM_MAX,
    CROWBOT_PWM_PER_RAD_S,
    CROWBOT_TRACK_M,
    CROWBOT_WHEEL_RADIUS_M,
    CrowBotFirmwareMotors,
)
from server.sim.robots.base import CommandError, Motors, RobotGeometry, RobotLimits, RobotModel
from server.sim.sensors.base import Sensor
from server.sim.sensors.button import Button
from server.sim.sensors.light import LightSensors
from server.sim.sensors.line import LineSensors
from server.sim.sensors.mount import Mount
from server.sim.sensors.ultrasonic import UltrasonicRanger
from server.sim.state import RobotState

SENSOR_RATE_HZ = 20.0  # [Hz] firmware publish rate for every sensor topic
ULTRASONIC_MOUNT = Mount(x_m=0.05)  # [m] ranger face at the front edge of the board
BUZZER_TONE_S = 1.0  # [s] the firmware plays B4 for one second
_WHEEL_TOP_RAD_S = CROWBOT_PWM_MAX / CROWBOT_PWM_PER_RAD_S  # [rad/s] PWM 255 / K


class CrowBot(RobotModel):
    id = "crowbot"
    title = "CrowBot BOLT (ESP32, rosserial over WiFi)"
    source = "000_32b6074bbd2115c3.txt sections 2.1-2.5, Table 1-2; firmware facts in seeds/README"
    geometry = RobotGeometry(
        body_radius_m=0.06,  # [m] ~12 cm round board (assumption: the paper gives no size)
        wheel_radius_m=CROWBOT_WHEEL_RADIUS_M,
        track_m=CROWBOT_TRACK_M,
        length_m=0.12,
        width_m=0.12,
        height_m=0.06,
    )
    limits = RobotLimits(
        max_linear_m_s=_WHEEL_TOP_RAD_S * CROWBOT_WHEEL_RADIUS_M,
        max_angular_rad_s=2 * _WHEEL_TOP_RAD_S * CROWBOT_WHEEL_RADIUS_M / CROWBOT_TRACK_M,
    )
    commands: ClassVar = {
        "Control": (Twist, "velocity command: linear.x [m/s], angular.z [rad/s]"),
        "Leds": (Int32MultiArray, "colour of all four LEDs: data = [r, g, b], each 0-255"),
        "Buzzer": (Bool, "true plays the note B4 for one second"),
    }
    sensor_descriptions: ClassVar = {
        "Distance": "ultrasonic range to the obstacle ahead [cm]; 0 when no echo",
        "Button": "the programmable button, true while pressed",
        "Light": "light sensors [right, left], 0-4095, lower = brighter",
        "Line": "line sensors [right, left], 0-4095, dark tape reads high",
    }

    def build_sensors(self) -> dict[str, Sensor]:
        return {
            "Distance": UltrasonicRanger(ULTRASONIC_MOUNT, SENSOR_RATE_HZ),
            "Button": Button(SENSOR_RATE_HZ),
            "Light": LightSensors(SENSOR_RATE_HZ),
            "Line": LineSensors(SENSOR_RATE_HZ),
        }

    def build_motors(self) -> Motors:
        return CrowBotFirmwareMotors()

    def apply_command(
        self, topic: str, message: object, state: RobotState, motors: Motors, time_s: float
    ) -> None:
        if topic == "Control":
            # No clamp here: the firmware's PWM clamp is the real limit, in the motor model.
            motors.command(message.linear.x, message.angular.z)
        elif topic == "Leds":
            colour = list(message.data)
            if len(colour) != 3 or any(not 0 <= c <= 255 for c in colour):
                raise CommandError(
                    f"Leds expects data = [r, g, b] with each value 0-255, got {colour}"
                )
            state.leds_rgb = (colour[0], colour[1], colour[2])
        elif topic == "Buzzer":
            state.buzzer_on = bool(message.data)
            state.buzzer_until_s = time_s + BUZZER_TONE_S if message.data else time_s
