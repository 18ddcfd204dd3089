"""`CreateDriver`: an iRobot Create/Roomba base over its Open Interface, presenting the topics
of the simulated `turtlebot` (server/sim/robots/turtlebot.py): it takes `cmd_vel`
(geometry_msgs/Twist) and publishes `odom` (nav_msgs/Odometry) and `bumper`
(std_msgs/Int32MultiArray [left, right], 1 = pressed).

Lifecycle (`CreateState`, transitions checked)::

    NEW --open()--> CONNECTING --first good frame--> STREAMING <--> SILENT
                                                          \\          /
                                                           stop() -> STOPPED --close()--> CLOSED

`open()` sends Start, then Safe (or Full) and asks for a sensor stream (packets 7, 35, 43, 44);
it returns once the first good frame arrives, or raises `CreateNoAnswerError` after
`connect_timeout_s`. One reader thread ("create-reader") then parses the stream, integrates the
encoders, calls `on_message(topic, message)` at `publish_rate_hz` (and at once when a bump
switch changes), notices silence, a robot that left Safe mode, and a command that went stale.
Callbacks run on the reader thread: keep them short, hand work to a queue of your own.

Drive commands are latest-wins: one is written when a sensor frame has arrived since the last
one written (the robot streams every 15 ms, so a live robot takes them at once); otherwise it
waits in a single slot, replaced by any newer command, and goes out with the next frame. A base
whose link stalls (a WiFi-serial bridge, a stuck adapter) gets the newest command when it comes
back, never a backlog; zero velocity (a stop) is written at once, always.

Why Safe by default: in Safe mode the robot's firmware still stops the wheels and drops to
Passive on a wheel drop, a cliff or the charger plugged in, whatever the student's controller
says; Full mode turns all of that off (a cliff at the stairs is then the controller's problem).
Use `mode="full"` only on a table-free floor, for exercises that need to drive over a ledge.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import replace
from enum import Enum
from typing import Literal

import serial

from server.hardware.create import kinematics, oi, topics
from server.hardware.create.port import (
    CreateError,
    CreateNoAnswerError,
    CreatePortError,
    CreateStateError,
    open_serial,
)

logger = logging.getLogger(__name__)

__all__ = [
    "CreateDriver",
    "CreateError",
    "CreateNoAnswerError",
    "CreatePortError",
    "CreateState",
    "CreateStateError",
]

# The packets streamed, in this order.
STREAM_PACKETS = (oi.BUMPS_WHEEL_DROPS, oi.OI_MODE, oi.LEFT_ENCODER_COUNTS, oi.RIGHT_ENCODER_COUNTS)

# Defaults, and why.
DEFAULT_BAUD = 115200  # Roomba 500/600 and Create 2 OI default (Create 1: 57600)
CONNECT_TIMEOUT_S = 2.0  # [s] Start + Safe + first frame take ~50 ms; 2 s is a robot that is off
SILENCE_TIMEOUT_S = 0.5  # [s] 33 missed 15 ms frames: no longer a hiccup of the USB adapter
COMMAND_LATCH_S = 0.5  # [s] a cmd_vel older than this is replaced by zero velocity. create_robot
#                        (the thesis's driver) latches 0.2 s; its Stanley controller ran at 5 Hz,
#                        so 0.2 s would stutter it. None turns the latch off (the simulator's way).
MODE_CHANGE_PAUSE_S = 0.02  # [s] assumption: time for the OI to switch mode before the next one


class CreateState(Enum):
    """Where the driver is in its lifecycle (see module doc)."""

    NEW = "new"
    CONNECTING = "connecting"
    STREAMING = "streaming"
    SILENT = "silent"
    STOPPED = "stopped"
    CLOSED = "closed"


_TRANSITIONS: dict[CreateState, frozenset[CreateState]] = {
    CreateState.NEW: frozenset({CreateState.CONNECTING, CreateState.CLOSED}),
    CreateState.CONNECTING: frozenset({CreateState.STREAMING, CreateState.CLOSED}),
    CreateState.STREAMING: frozenset({CreateState.SILENT, CreateState.STOPPED}),
    CreateState.SILENT: frozenset({CreateState.STREAMING, CreateState.STOPPED}),
    CreateState.STOPPED: frozenset({CreateState.CLOSED}),
    CreateState.CLOSED: frozenset(),
}


OnMessage = Callable[[str, object], None]
OnState = Callable[[CreateState, str | None], None]


class CreateDriver:
    """One Create/Roomba base on one serial port (see module doc).

    `clock` stamps the messages [s] (default wall time, as ROS stamps are); the driver's own
    timeouts use time.monotonic. Messages are sandbox.msgs instances, fresh for every call.
    """

    def __init__(
        self,
        port: str,
        baud: int = DEFAULT_BAUD,
        *,
        mode: Literal["safe", "full"] = "safe",
        stop_with: Literal["passive", "off"] = "passive",
        on_message: OnMessage | None = None,
        on_state: OnState | None = None,
        clock: Callable[[], float] = time.time,
        connect_timeout_s: float = CONNECT_TIMEOUT_S,
        silence_timeout_s: float = SILENCE_TIMEOUT_S,
        command_latch_s: float | None = COMMAND_LATCH_S,
        publish_rate_hz: float = topics.PUBLISH_RATE_HZ,
        frame_id: str = "odom",
        child_frame_id: str = "base_link",
    ) -> None:
        if mode not in ("safe", "full"):
            raise ValueError(f"mode must be 'safe' or 'full', got {mode!r}")
        if stop_with not in ("passive", "off"):
            raise ValueError(f"stop_with must be 'passive' or 'off', got {stop_with!r}")
        self.port = port
        self.baud = int(baud)
        self.mode = mode
        self.stop_with = stop_with
        self.on_message = on_message
        self.on_state = on_state
        self.clock = clock
        self.connect_timeout_s = float(connect_timeout_s)
        self.silence_timeout_s = float(silence_timeout_s)
        self.command_latch_s = command_latch_s
        self._topics = topics.CreateTopics(
            publish_rate_hz=publish_rate_hz, frame_id=frame_id, child_frame_id=child_frame_id
        )
        self._state = CreateState.NEW
        self._problem: str | None = None
        self._mode_problem: str | None = None  # the robot is not in the mode asked for
        self._state_lock = threading.Lock()
        self._write_lock = threading.Lock()
        self._serial: serial.Serial | None = None
        self._reader: threading.Thread | None = None
        self._stop_reading = threading.Event()
        self._first_frame = threading.Event()
        self._parser = oi.StreamParser(packet_ids=STREAM_PACKETS)
        self._bytes_received = 0
        self._oi_mode: oi.OIMode | None = None
        self._last_command_s: float | None = None  # monotonic time of the last nonzero command
        # Latest-wins drive commands (module doc): a drive written since the last frame makes
        # the next one wait in `_held_drive`.
        self._drive_lock = threading.Lock()
        self._held_drive: bytes | None = None
        self._drive_unanswered = False
        self.drives_replaced = 0  # drive commands a newer one replaced before they were written

    # --- state -------------------------------------------------------------------------------

    @property
    def state(self) -> CreateState:
        return self._state

    @property
    def problem(self) -> str | None:
        """The latest trouble as a sentence (silence, robot left Safe mode, port failure), or
        None while all is well."""
        return self._problem or self._mode_problem

    @property
    def stats(self) -> oi.StreamStats:
        """A copy of the stream parser's counts: good frames, bad frames, discarded bytes."""
        return replace(self._parser.stats)

    @property
    def oi_mode(self) -> oi.OIMode | None:
        """The mode the robot last reported (packet 35)."""
        return self._oi_mode

    @property
    def pose(self) -> kinematics.Pose2D:
        """The integrated odometry pose."""
        return self._topics.odometry.pose

    def _transition(self, new_state: CreateState, reason: str | None = None) -> None:
        with self._state_lock:
            if new_state not in _TRANSITIONS[self._state]:
                raise CreateStateError(
                    f"the Create driver cannot go from {self._state.value} to {new_state.value}"
                )
            self._state = new_state
            self._problem = reason
        if self.on_state is not None:
            try:
                self.on_state(new_state, reason)
            except Exception:
                logger.exception("on_state callback failed (ignored)")

    # --- lifecycle ---------------------------------------------------------------------------

    def open(self) -> None:
        """Open the port, start the OI, and wait for the first sensor frame.

        Raises CreatePortError (port missing, no permission, in use) or CreateNoAnswerError
        (nothing valid came back within `connect_timeout_s`); either leaves the driver CLOSED.
        """
        if self._state is not CreateState.NEW:
            raise CreateStateError(
                f"open() is called once, on a new driver; this one is {self._state.value}. "
                "Make a new CreateDriver to reconnect."
            )
        try:
            self._serial = open_serial(self.port, self.baud)
        except CreatePortError:
            self._transition(CreateState.CLOSED)
            raise
        self._transition(CreateState.CONNECTING)
        try:
            self._write(oi.encode_opcode(oi.Opcode.START))
            time.sleep(MODE_CHANGE_PAUSE_S)
            self._write(oi.encode_opcode(self._mode_opcode()))
            time.sleep(MODE_CHANGE_PAUSE_S)
            self._write(oi.encode_stream(STREAM_PACKETS))
        except CreatePortError:
            self._abort_open()
            raise
        self._reader = threading.Thread(target=self._read_loop, name="create-reader", daemon=True)
        self._reader.start()
        if not self._first_frame.wait(self.connect_timeout_s):
            received = self._bytes_received
            port_failure = self._problem
            self._abort_open()
            if port_failure is not None:
                raise CreatePortError(port_failure)
            if received:
                detail = (
                    f"{received} bytes came back but no valid sensor frame: is the baud rate "
                    f"right? Roomba 500/600 and Create 2 talk 115200, Create 1 57600 "
                    f"(this driver used {self.baud})"
                )
            else:
                detail = (
                    "nothing came back: is the robot switched on (press its power button; a "
                    "Roomba asleep after 5 minutes in Passive mode does not listen) and the "
                    "cable in its Mini-DIN port?"
                )
            raise CreateNoAnswerError(
                f"no answer from the Create on {self.port} within "
                f"{self.connect_timeout_s:.1f} s: {detail}"
            )
        self._transition(CreateState.STREAMING)

    def _mode_opcode(self) -> oi.Opcode:
        return oi.Opcode.SAFE if self.mode == "safe" else oi.Opcode.FULL

    def _stop_opcode(self) -> oi.Opcode:
        return oi.Opcode.START if self.stop_with == "passive" else oi.Opcode.STOP

    def _abort_open(self) -> None:
        self._stop_reading.set()
        if self._reader is not None:
            self._reader.join()
        if self._serial is not None:
            self._serial.close()
        self._transition(CreateState.CLOSED)

    def __enter__(self) -> CreateDriver:
        self.open()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def command(self, twist: object) -> None:
        """Drive: a geometry_msgs/Twist's linear.x [m/s] and angular.z [rad/s] -> Drive Direct.

        Past 0.5 m/s on a wheel the command is scaled down as a whole (same curve, slower).
        A non-finite value sends zero velocity and raises ValueError.
        """
        if self._state not in (CreateState.STREAMING, CreateState.SILENT):
            raise CreateStateError(
                f"command() needs a streaming driver, this one is {self._state.value}: "
                + (
                    "call open() first"
                    if self._state is CreateState.NEW
                    else "make a new CreateDriver and open() it"
                )
            )
        try:
            linear_m_s = float(twist.linear.x)  # type: ignore[attr-defined]
            angular_rad_s = float(twist.angular.z)  # type: ignore[attr-defined]
        except (AttributeError, TypeError, ValueError):
            raise TypeError(
                f"command() takes a geometry_msgs/Twist (linear.x, angular.z), "
                f"got {type(twist).__name__}"
            ) from None
        try:
            wheels = kinematics.twist_to_wheel_speeds(linear_m_s, angular_rad_s)
        except ValueError:
            self._drive(0.0, 0.0)
            raise
        self._drive(wheels.left_m_s, wheels.right_m_s)

    @property
    def commands_waiting(self) -> int:
        """Drive commands held for the robot's next frame (0 or 1)."""
        return int(self._held_drive is not None)

    def _drive(self, left_m_s: float, right_m_s: float) -> None:
        moving = bool(left_m_s or right_m_s)
        self._last_command_s = time.monotonic() if moving else None
        frame = oi.encode_drive_direct(right_m_s * 1000.0, left_m_s * 1000.0)
        with self._drive_lock:
            if moving and self._drive_unanswered:
                if self._held_drive is not None:
                    self.drives_replaced += 1
                self._held_drive = frame
                return
            self._held_drive = None  # older than this one (a stop goes out at once)
            self._drive_unanswered = True
            self._write(frame)

    def _release_drive(self) -> None:
        """A frame arrived: the robot's link moves; write the command that waited, if any."""
        with self._drive_lock:
            held, self._held_drive = self._held_drive, None
            self._drive_unanswered = held is not None
            if held is not None:
                self._write(held)

    def rearm(self) -> None:
        """Send Safe (or Full) again, after the robot dropped to Passive on a wheel drop, a
        cliff or the charger. Look at the robot first: it will drive again."""
        if self._state not in (CreateState.STREAMING, CreateState.SILENT):
            raise CreateStateError(f"rearm() needs a streaming driver, this one is {self._state}")
        self._write(oi.encode_opcode(self._mode_opcode()))

    def stop(self) -> None:
        """Zero velocity, pause the stream, then leave user control: by default Start, which
        drops the robot to Passive (every OI version knows it, and the firmware holds the wheels
        still in Passive); with stop_with="off", Stop (173), which shuts the OI down (Create 2 /
        Roomba 600 OI; older firmware ignores it). The driver then takes no more commands.
        Safe to call twice."""
        if self._state in (CreateState.NEW, CreateState.STOPPED, CreateState.CLOSED):
            return
        try:
            self._drive(0.0, 0.0)
            self._write(oi.encode_pause_resume_stream(resume=False))
            self._write(oi.encode_opcode(self._stop_opcode()))
        except CreatePortError as exc:
            logger.warning("stopping the Create: %s", exc)
        self._stop_reading.set()
        if self._reader is not None and self._reader is not threading.current_thread():
            self._reader.join()
        self._transition(CreateState.STOPPED, self._problem)

    def close(self) -> None:
        """stop() if needed, then release the port. Safe to call twice."""
        if self._state is CreateState.CLOSED:
            return
        self.stop()
        if self._serial is not None:
            self._serial.close()
        self._transition(CreateState.CLOSED)

    # --- reader thread -----------------------------------------------------------------------

    def _write(self, data: bytes) -> None:
        assert self._serial is not None
        try:
            with self._write_lock:
                self._serial.write(data)
        except (serial.SerialException, OSError) as exc:
            raise CreatePortError(
                f"writing to the Create on {self.port} failed ({exc}): the cable may be "
                "unplugged; make a new CreateDriver once it is back"
            ) from exc

    def _read_loop(self) -> None:
        assert self._serial is not None
        last_frame_s = time.monotonic()
        while not self._stop_reading.is_set():
            try:
                chunk = self._serial.read(max(1, self._serial.in_waiting))
            except (serial.SerialException, OSError) as exc:
                self._on_port_failure(
                    f"reading the serial port {self.port} failed ({exc}): the cable may be "
                    "unplugged; odometry is frozen, make a new CreateDriver once it is back"
                )
                return
            now_s = time.monotonic()
            if chunk:
                self._bytes_received += len(chunk)
                frames = self._parser.feed(chunk)
                if frames:
                    last_frame_s = now_s
                    self._on_frames(frames, now_s)
                    try:
                        self._release_drive()
                    except CreatePortError as exc:
                        self._on_port_failure(str(exc))
            self._check_silence(now_s - last_frame_s)
            self._check_latch(now_s)

    def _on_port_failure(self, reason: str) -> None:
        logger.error(reason)
        if self._state is CreateState.STREAMING:
            self._transition(CreateState.SILENT, reason)
        else:
            self._problem = reason

    def _check_silence(self, silent_for_s: float) -> None:
        if self._state is CreateState.STREAMING and silent_for_s > self.silence_timeout_s:
            reason = (
                f"no sensor frame from the Create on {self.port} for {silent_for_s:.2f} s (it "
                "sends one every 15 ms): the robot may be off, its battery flat or its cable "
                "loose; odometry is frozen until frames come back"
            )
            logger.warning(reason)
            self._transition(CreateState.SILENT, reason)

    def _check_latch(self, now_s: float) -> None:
        if (
            self.command_latch_s is not None
            and self._last_command_s is not None
            and now_s - self._last_command_s > self.command_latch_s
        ):
            logger.info("no cmd_vel for %.2f s: stopping the wheels", self.command_latch_s)
            try:
                self._drive(0.0, 0.0)
            except CreatePortError as exc:
                self._on_port_failure(str(exc))

    def _on_frames(self, frames: list[dict[int, int]], now_s: float) -> None:
        for message_topic, message in self._topics.on_frames(frames, now_s, self.clock()):
            self._publish(message_topic, message)
        for packets in frames:
            self._on_oi_mode(packets[oi.OI_MODE])
        if not self._first_frame.is_set():
            self._first_frame.set()
        elif self._state is CreateState.SILENT:
            self._transition(CreateState.STREAMING)

    def _on_oi_mode(self, value: int) -> None:
        try:
            mode = oi.OIMode(value)
        except ValueError:
            return
        if mode == self._oi_mode:
            return
        self._oi_mode = mode
        wanted = oi.OIMode.SAFE if self.mode == "safe" else oi.OIMode.FULL
        if mode == wanted:
            self._mode_problem = None
            return
        cause = (
            "a wheel dropped"
            if self._topics.wheel_dropped
            else "a cliff, a wheel drop or the charger"
        )
        self._mode_problem = (
            f"the Create is in {mode.name.title()} mode, not {wanted.name.title()} ({cause}?): "
            "it ignores drive commands now; check the robot, then call rearm()"
        )
        logger.warning(self._mode_problem)

    def _publish(self, topic: str, message: object) -> None:
        if self.on_message is None:
            return
        try:
            self.on_message(topic, message)
        except Exception:
            logger.exception("on_message callback for %s failed (ignored)", topic)
