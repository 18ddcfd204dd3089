"""What a robot is to the simulator: a registry entry that declares its topics, geometry and
limits, builds its sensors and motor model, and turns command messages into motor commands.

Each robot module defines one `RobotModel` subclass; `server.sim.registry` registers them by id
and `server.sim.checks.check_robot` checks every entry (the tests run it over the whole registry).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import ClassVar, Protocol

from server.sim.sensors.base import Sensor
from server.sim.state import RobotState

TWIST_TYPE = "geometry_msgs/Twist"  # the velocity command type of every wheeled robot here


class Direction(StrEnum):
    """Seen from the robot: it publishes sensor topics and subscribes to command topics."""

    PUBLISH = "publish"
    SUBSCRIBE = "subscribe"


@dataclass(frozen=True, slots=True)
class TopicSpec:
    """One topic of a robot: name, ROS message class, direction, rate [Hz] (publishers only)."""

    name: str
    msg_type: type
    direction: Direction
    rate_hz: float | None
    description: str

    @property
    def type_name(self) -> str:
        return self.msg_type._type


@dataclass(frozen=True, slots=True)
class RobotGeometry:
    """Sizes [m]. The body is a disc of `body_radius_m` for collisions (the circumscribed circle
    for a rectangular chassis, so the simulated robot never fits where the real one cannot),
    centred `body_offset_x_m` ahead of the point between the wheels (negative: behind it, as on
    a TurtleBot3 whose axle is near the front); `length_m`/`width_m`/`height_m` are for drawing."""

    body_radius_m: float
    wheel_radius_m: float
    track_m: float
    length_m: float
    width_m: float
    height_m: float
    body_offset_x_m: float = 0.0


@dataclass(frozen=True, slots=True)
class RobotLimits:
    """What the robot can physically do: top speeds the motors reach."""

    max_linear_m_s: float
    max_angular_rad_s: float


class Motors(Protocol):
    """A motor model (see server.sim.motors)."""

    def reset(self) -> None: ...
    def command(self, linear_m_s: float, angular_rad_s: float) -> None: ...
    def step(self, dt_s: float) -> tuple[float, float]: ...


class CommandError(ValueError):
    """A command message whose content the robot cannot accept (the sentence says why)."""


class RobotModel:
    """Base of every robot. Subclasses set the class attributes and override the builders."""

    id: ClassVar[str]
    title: ClassVar[str]
    source: ClassVar[str]  # the paper and section the model follows
    geometry: ClassVar[RobotGeometry]
    limits: ClassVar[RobotLimits]
    # name -> (message class, description) for each command topic the robot subscribes to.
    commands: ClassVar[dict[str, tuple[type, str]]]
    # name -> description for each sensor topic (the sensor object supplies type and rate).
    sensor_descriptions: ClassVar[dict[str, str]]
    # Frames the sensors stamp their messages with: frame -> (x [m], y [m], yaw [rad]) in the
    # robot frame, or (x, y, yaw, roll [rad]) for a scanner whose angles grow clockwise.
    frames: ClassVar[dict[str, tuple[float, ...]]] = {}

    def build_sensors(self) -> dict[str, Sensor]:
        """A fresh sensor object per published topic."""
        raise NotImplementedError

    def build_motors(self) -> Motors:
        raise NotImplementedError

    def apply_command(
        self, topic: str, message: object, state: RobotState, motors: Motors, time_s: float
    ) -> None:
        """Act on a (type-checked, finite) command message. Raise CommandError for content the
        robot cannot accept."""
        raise NotImplementedError

    def sensor_frames(self, state: RobotState) -> dict[str, tuple[float, ...]]:
        """The sensor frames where they are now (a servo turns one; most never move)."""
        return self.frames

    def advance(self, state: RobotState, dt_s: float, time_s: float) -> None:
        """For actuators other than the wheels (servo slew, buzzer timer): once per tick, or
        once for a run of ticks with `dt_s` their sum and `time_s` the last one's end
        (server/sim/tick_runs.py). So it must add up over time: one call with dt_a + dt_b
        leaves the state two calls with dt_a and dt_b would."""
        if state.buzzer_on and time_s >= state.buzzer_until_s:
            state.buzzer_on = False

    def velocity_topics(self) -> tuple[str, ...]:
        """The command topics that take a geometry_msgs/Twist (Control, cmd_vel), in declared
        order: the one a step API's (v, w) goes to is the first; stopping zeroes them all."""
        return tuple(
            name for name, (msg_type, _) in self.commands.items() if msg_type._type == TWIST_TYPE
        )

    def topics(self) -> tuple[TopicSpec, ...]:
        """All topics, publishers first, each with its type and rate."""
        published = tuple(
            TopicSpec(
                name,
                sensor.msg_type,
                Direction.PUBLISH,
                sensor.rate_hz,
                self.sensor_descriptions.get(name, ""),
            )
            for name, sensor in self.build_sensors().items()
        )
        subscribed = tuple(
            TopicSpec(name, msg_type, Direction.SUBSCRIBE, None, description)
            for name, (msg_type, description) in self.commands.items()
        )
        return published + subscribed


def clamp_twist(
    linear_m_s: float, angular_rad_s: float, limits: RobotLimits
) -> tuple[float, float]:
    """Clip a velocity command to what the robot can do (commands beyond it are not errors:
    students often ask for more than a robot has, as they would on the real one)."""
    return (
        max(-limits.max_linear_m_s, min(limits.max_linear_m_s, linear_m_s)),
        max(-limits.max_angular_rad_s, min(limits.max_angular_rad_s, angular_rad_s)),
    )
