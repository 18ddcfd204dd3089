"""A real robot in place of the simulator inside a Run: the same topics, names and types as the
simulated robot of that kind, so the code that ran in simulation runs unchanged.

    robot = HardwareRobot("crowbot", link, limits)       # link: a connected robot (RobotLink)
    run = Run(spec, launcher, out_dir, backend=robot)    # spec.clock must be realtime

It implements `server.sim.backend.RobotBackend`, the protocol `Simulation` implements too, so a
Run drives either without asking which. `step()` hands over what the robot sent since the last
call, timed on the run's clock; `apply()` passes commands through the safety layer
(server/hardware/safety.py) before the link. The watchdog runs in `step()`: a node that stops
commanding for 500 ms stops the robot. When the link drops, `step()` raises `RobotLost` and the
run ends saying so ("failed: lost the link to the robot: the robot closed the connection");
when a sensor topic goes silent past its bound (server/hardware/silence.py), `step()` sends zero
velocity and raises `RobotSilent`: "failed: robot stopped sending Distance for 0.3 s", naming a
topic the run's nodes read when several went silent (`note_readers`). Every end
of a run calls `stop()`: zero velocity and LEDs off (server/hardware/rest.py); a robot whose link
had dropped gets them when it connects again. What the safety layer sent is recorded beside the
student's command: `Control_applied` (the Twist on the wire) and, when something changed it,
`Control_limit` (which: the MotionLimits fields as "max_linear_m_s,max_linear_accel_m_s2", or
"watchdog", "stop").
"""

from __future__ import annotations

import contextlib
import math
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.msgs.std_msgs import String
from server.hardware.rest import rest_message
from server.hardware.safety import (
    DEFAULT_WATCHDOG_S,
    MotionLimits,
    Velocity,
    VelocityLimiter,
    Watchdog,
)
from server.hardware.silence import SILENCE_LIMITS, SensorSilenceWatchdog, SilenceLimits
from server.sim import Pose2D
from server.sim.registry import get_robot
from server.sim.robots.base import Direction
from server.sim.simulation import Published, SimulationError
from server.sim.state import RobotState

if TYPE_CHECKING:
    from server.sim.robots.base import TopicSpec
    from server.sim.simulation import SimEvent
    from server.sim.world import LightSource

POLL_S = 0.005  # [s] how often a realtime run looks for the robot's messages (200 Hz)
NO_BOUNDS = (-math.inf, -math.inf, math.inf, math.inf)  # a lab bench has no map edges we know
# Recorded beside the student's command (Control, cmd_vel): what the safety layer sent the robot
# (geometry_msgs/Twist on "<topic>_applied") and, when something changed it, why (std_msgs/String
# on "<topic>_limit": the MotionLimits fields, "not_finite", "watchdog" or "stop").
APPLIED_SUFFIX = "_applied"
LIMIT_SUFFIX = "_limit"
WATCHDOG_LIMIT = "watchdog"  # the node stopped commanding: zero sent
STOP_LIMIT = "stop"  # the run ended or the emergency stop: zero sent
APPLIED_KEPT = 1000  # applied commands waiting for step(): ~10 s at 100 Hz; older ones go
_BENCH_ORIGIN = Pose2D(0.0, 0.0, 0.0)  # frozen, so one instance serves every robot


class RobotLost(SimulationError):
    """The connection to the robot is gone; the message says how."""


class RobotSilent(RobotLost):
    """A sensor topic the run depends on stopped arriving; the message names it and for how
    long (server/hardware/silence.py)."""


class RobotLink(Protocol):
    """A connected robot as a protocol adapter presents it (rosserial session, Create driver)."""

    @property
    def connected(self) -> bool: ...

    @property
    def lost_reason(self) -> str: ...

    def send(self, topic: str, message: object) -> None: ...

    def take_received(self) -> list[tuple[str, object, float]]:
        """(topic, message, monotonic receive time [s]) since the last call."""
        ...

    # Optional: `publishes` (a collection of topic names the robot sends). A link that has it
    # has those topics watched for silence from the start of a run; one without it has each
    # topic watched from its first message.
    # Optional: `listened_until_s` (monotonic [s], or None): everything the robot sent before it
    # has reached take_received(). Silence is counted up to there, not up to now, so a reader
    # thread a busy host did not schedule does not make a talking robot look silent.


class _Bench:
    """The world a hardware run happens in: no map, no lights we control."""

    id = "lab_bench"
    bounds = NO_BOUNDS
    lights = ()

    def in_bounds(self, x: float, y: float, margin_m: float = 0.0) -> bool:
        return True  # a bench has no map edges we know


class HardwareRobot:
    """A real robot as a `RobotBackend` (server/sim/backend.py; see the module docstring). It
    does not inherit the protocol, so a member it lacked would fail the conformance test
    (tests/hardware/test_backend_protocol.py) instead of quietly returning None."""

    is_hardware = True

    def __init__(
        self,
        robot_id: str,
        link: RobotLink,
        limits: MotionLimits,
        watchdog_s: float = DEFAULT_WATCHDOG_S,
        clock=time.monotonic,
        silence_limits: SilenceLimits = SILENCE_LIMITS,
    ) -> None:
        self.robot = get_robot(robot_id)
        self.world = _Bench()
        self.lights: tuple[LightSource, ...] = ()
        self.link = link
        self.state = RobotState()  # the true pose is unknown on a bench: stays at the origin
        self.limiter = VelocityLimiter(limits)
        self.watchdog = Watchdog(watchdog_s)
        self._clock = clock
        self._started_s: float | None = None
        self._time_s = 0.0
        self._latest: dict[str, object] = {}
        self._velocity_topics = set(self.robot.velocity_topics())
        self._zero_sent = False
        self.commands_sent = 0
        self._sensor_rates_hz = {
            t.name: t.rate_hz for t in self.topics if t.direction is Direction.PUBLISH
        }
        self.silence_limits = silence_limits
        self.silence: SensorSilenceWatchdog | None = None  # made by reset()
        self._is_read: Callable[[str], bool] | None = None  # see note_readers()
        # (topic, Twist sent, limits that changed it), published by step() (any thread adds).
        self._applied: deque[tuple[str, Twist, tuple[str, ...]]] = deque(maxlen=APPLIED_KEPT)

    # ------------------------------------------------------------------ what a Run reads
    @property
    def topics(self) -> tuple[TopicSpec, ...]:
        return self.robot.topics()

    @property
    def odometry_origin(self) -> Pose2D:
        """Where the robot's odometry starts: the origin, as a bench has no map."""
        return _BENCH_ORIGIN

    @property
    def time_s(self) -> float:
        return self._time_s

    @property
    def tick_s(self) -> float:
        return POLL_S  # [s] the run looks for the robot's messages this often

    def next_publication_s(self) -> float:
        return self._time_s + POLL_S

    def reset(self, seed: int | None = None) -> list[Published]:
        self._started_s = self._clock()
        self.watchdog = Watchdog(self.watchdog.timeout_s)
        publishes = getattr(self.link, "publishes", None)
        watched = {
            name: rate
            for name, rate in self._sensor_rates_hz.items()
            if publishes is not None and name in publishes
        }
        self.silence = SensorSilenceWatchdog(watched, self._started_s, self.silence_limits)
        return []

    def drain_events(self) -> list[SimEvent]:
        return []  # contacts and bounds are the simulator's to see

    def note_readers(self, is_read: Callable[[str], bool]) -> None:
        """`is_read(topic)`: does a node of the run read it now? A robot that froze stops every
        topic at once; the silence named is then one the student's code was waiting for."""
        self._is_read = is_read

    def read(self, topic: str) -> object | None:
        return self._latest.get(topic)

    # ------------------------------------------------------------------ commands
    def apply(self, topic: str, message: object) -> None:
        if not self.link.connected:
            raise RobotLost(self.link.lost_reason or "robot disconnected")
        if topic in self._velocity_topics:
            now = self._clock()
            wanted = Velocity(message.linear.x, message.angular.z)
            sent = self.limiter.apply(wanted, now)
            self.watchdog.feed(now)
            message = Twist(
                linear=Vector3(x=sent.linear_m_s), angular=Vector3(z=sent.angular_rad_s)
            )
            self._zero_sent = sent == Velocity()
            self.link.send(topic, message)
            self._applied.append((topic, message, self.limiter.limited_by))
        else:
            self.link.send(topic, message)
        self.commands_sent += 1

    def press_button(self, pressed: bool) -> None:
        raise SimulationError("a real robot's button is pressed by a hand on the bench")

    def move_light(self, name: str, x: float, y: float) -> None:
        raise SimulationError("the lights of the lab bench are not ours to move")

    # ------------------------------------------------------------------ time
    def step(self, dt_s: float) -> list[Published]:
        """Advance the run's clock by `dt_s`; return what the robot sent meanwhile."""
        if not self.link.connected:
            raise RobotLost(self.link.lost_reason or "robot disconnected")
        self._time_s += dt_s
        started = self._started_s if self._started_s is not None else self._clock()
        published = []
        # Before take_received(): what arrived before this moment is in the inbox being taken.
        listened_s = getattr(self.link, "listened_until_s", None)
        silence = self.silence
        if silence is None:
            silence = self.silence = SensorSilenceWatchdog({}, started, self.silence_limits)
        for topic, message, received_s in self.link.take_received():
            time_s = min(self._time_s, max(0.0, received_s - started))
            self._latest[topic] = message
            published.append(Published(topic, time_s, message))
            if topic not in silence.bounds_s and topic in self._sensor_rates_hz:
                silence.watch(topic, self._sensor_rates_hz[topic], received_s)
            silence.heard(topic, received_s)
        now = self._clock()
        heard_until_s = now if listened_s is None else min(now, listened_s)
        if (silent := silence.check(heard_until_s, self._is_read)) is not None:
            self._stop_wheels()
            raise RobotSilent(silent.sentence)
        if self.watchdog.expired(now) and not self._zero_sent:
            self._send_zero(WATCHDOG_LIMIT)
        published += self._take_applied()
        return published

    def _take_applied(self) -> list[Published]:
        """The commands sent since the last step, as `<topic>_applied` and `<topic>_limit`."""
        out = []
        while self._applied:
            topic, twist, limited_by = self._applied.popleft()
            out.append(Published(topic + APPLIED_SUFFIX, self._time_s, twist))
            if limited_by:
                out.append(
                    Published(topic + LIMIT_SUFFIX, self._time_s, String(data=",".join(limited_by)))
                )
        return out

    def take_logs(self) -> list[str]:
        """What the robot logged (rosserial id 7) since the last call, for the run's log."""
        take = getattr(self.link, "take_logs", None)
        return take() if take is not None else []

    def stop(self) -> None:
        """At rest (server/hardware/rest.py: zero velocity, LEDs off): every end of a run. A
        link already gone takes nothing; the robot is put at rest when it connects again."""
        if not self.link.connected:
            return
        try:
            self._send_zero()
            for topic, (message_class, _) in self.robot.commands.items():
                if topic in self._velocity_topics:
                    continue  # zero sent above, through the safety layer's record
                if (rest := rest_message(topic, message_class)) is not None:
                    self.link.send(topic, rest)
        except RobotLost:  # gone in between: nothing left to stop
            pass

    def _stop_wheels(self) -> None:
        """Zero velocity if the link still takes writes; the run's end sends it again."""
        if not self.link.connected:
            return
        with contextlib.suppress(Exception):  # the run ends either way; stop() tries again
            self._send_zero(STOP_LIMIT)

    def _send_zero(self, why: str = STOP_LIMIT) -> None:
        for topic in self._velocity_topics:
            self.link.send(topic, Twist())
            self._applied.append((topic, Twist(), (why,)))
        self.limiter.sent = Velocity()
        self._zero_sent = True
