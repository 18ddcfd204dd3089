"""The rosserial TCP server: what ``rosserial_python serial_node.py tcp`` does, without ROS.

Robots (ros_lib over WiFi, e.g. the CrowBot of 000_32b6074bbd2115c3.txt section 2.4) connect as
TCP clients to port 11411; each connection gets one ``RosserialSession`` (session.py) and is
shown to the rest of RoboDojo as a ``RobotConnection`` through a ``RosserialHandler``::

    class Bridge(RosserialHandler):
        def on_robot_connected(self, robot): ...
        def on_message(self, robot, topic, message): robot.send("Control", Twist(...))

    with RosserialServer(Bridge(), host="10.42.0.1", port=11411) as server:  # the robots' LAN
        ...

Threading: the server runs an asyncio event loop in its own thread ("rosserial"). Parsing is
CPU work, and a garbage flood must not stall the FastAPI loop that serves students' pages and
websockets; asyncio (rather than a thread per robot) gives cheap per-connection timers, flow
control and a fixed read buffer (``asyncio.BufferedProtocol``). Handler methods run on that
thread and must return quickly (hand over with ``loop.call_soon_threadsafe`` or a latest-value
slot). ``RobotConnection.send``/``stop`` and ``RosserialServer.stop`` may be called from any
thread; ``send`` checks the topic at once, in the caller's thread, and raises with a sentence.

Admission (admission.py): ros_lib has no authentication, so before a session exists the server
asks ``handler.admit(host)``; a refused peer is closed at once (no topic request, no slot), logged
once a minute per address and backed off when it keeps connecting. Connections that do not finish
the handshake within ``handshake_timeout_s`` are closed, and at most ``max_pending_per_address``
handshakes run per address (the newest wins: a rebooted robot's connection is the live one).

Commands are latest-wins (a stale Control is worse than none): a command frame is written when
the robot has sent anything since the last frame written on that topic, and the socket has taken
everything written before; otherwise it waits in a one-per-topic slot, where a newer command
replaces it, and goes out the moment the robot is heard again. A live robot publishes every loop,
so commands flow at its loop rate; a robot that froze (stalled firmware, WiFi stuck) without
closing its socket has at most one command per topic written after its last frame, and gets the
newest when it resumes, never a backlog. A robot that advertises no publisher gives no sign of
life, so only the socket bound holds for it. A stop (a zero Twist, or ``send(..., urgent=True)``)
never waits.

At rest first, always: the moment a robot's handshake names a command topic (its subscriber
TopicInfo), that topic is sent its rest (server/hardware/rest.py: zero velocity, LEDs off),
before any handler can write to it; and every stop (``RobotConnection.stop``, the server's own
``stop``) sends the rest before the tx-stop. A firmware without a watchdog holds its last
command: reconnected after a dropped link, it would otherwise drive on where the run that
commanded it had already ended.

Unlike rosserial_python (one connection at a time unless forking) it serves up to
``max_connections`` robots at once; it requests topics at once instead of after 2 s (that sleep
waits for an Arduino to reboot when its serial port opens; a TCP client is already running).
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import logging
import socket
import threading
import time
from collections import Counter
from collections.abc import Callable

from sandbox.msgs import Message
from sandbox.msgs.geometry_msgs import Twist
from server.hardware.rest import rest_message
from server.hardware.rosserial.admission import AdmissionControl, Refusal
from server.hardware.rosserial.events import Direction
from server.hardware.rosserial.frames import encode_frame
from server.hardware.rosserial.limits import DEFAULT_LIMITS, RosserialLimits
from server.hardware.rosserial.messages import LogLevel
from server.hardware.rosserial.session import (
    Closed,
    LogLine,
    MessageReceived,
    Problem,
    Ready,
    RobotTopic,
    RosserialSession,
    SessionEvent,
    SessionState,
    SyncLost,
    TopicRefused,
    TopicRegistered,
)

DEFAULT_PORT = 11411  # rosserial_python's tcp port; ros_lib's ArduinoTcpHardware default
logger = logging.getLogger(__name__)
_LOG_LEVELS = {
    LogLevel.DEBUG: logging.DEBUG,
    LogLevel.INFO: logging.INFO,
    LogLevel.WARN: logging.WARNING,
    LogLevel.ERROR: logging.ERROR,
    LogLevel.FATAL: logging.CRITICAL,
}


class RosserialHandler:
    """What the server tells the rest of RoboDojo; override the methods you need.

    All run on the rosserial thread. ``on_robot_connected`` comes once negotiation is over
    (``robot.topics`` and ``robot.problems`` are filled); ``on_robot_disconnected`` only follows
    a connected robot. Problems (refused topics, wrong protocol version...) and lost syncs also
    arrive as ``on_log`` lines at ERROR and WARN."""

    def admit(self, host: str) -> Refusal | None:
        """A peer connected from `host`: None gives it a session, a Refusal closes it at once.
        Runs on the rosserial thread before anything is sent; must be quick. Default: admit."""
        return None

    def on_robot_connected(self, robot: RobotConnection) -> None:
        """A robot finished negotiating its topics."""

    def on_robot_disconnected(self, robot: RobotConnection, reason: str) -> None:
        """A connected robot went away; `reason` is a sentence."""

    def on_message(self, robot: RobotConnection, topic: str, message: Message) -> None:
        """The robot published `message` on `topic`."""

    def on_log(self, robot: RobotConnection, level: LogLevel, line: str) -> None:
        """The robot logged `line`, or the host has something to say about it."""


class RobotConnection:
    """One robot's TCP connection and its session, as handlers see it."""

    def __init__(
        self,
        server: RosserialServer,
        robot_id: str,
        peer: tuple[str, int],
        session: RosserialSession,
    ) -> None:
        self._server = server
        self.id = robot_id
        self.peer = peer  # (host, port) of the robot
        self.session = session
        self.connected_at = time.time()  # [s] epoch
        self.started_s = time.monotonic()  # [s] for the handshake timeout
        self.announced = False  # on_robot_connected has been called
        self.outgoing_dropped = 0  # urgent frames not written: the robot stopped reading
        self.commands_replaced = 0  # commands a newer one replaced before they were written
        self.reads_paused = 0  # times reading paused for the rest of a second (max_bytes_per_s)
        self.last_heard_s: float | None = None  # [s] monotonic, the robot's latest bytes
        self._transport: asyncio.Transport | None = None
        # Latest-wins outgoing commands (module docstring); rosserial thread only.
        self._held: dict[str, bytes] = {}  # topic -> newest frame not yet written
        self._unanswered: set[str] = set()  # topics written since the robot was last heard
        self._last_written: dict[str, bytes] = {}  # topic -> the frame written last

    @property
    def state(self) -> SessionState:
        return self.session.state

    @property
    def connected(self) -> bool:
        """False once the session closed (a send() then raises RobotDisconnected)."""
        return self.session.state is not SessionState.CLOSED

    @property
    def listened_until_s(self) -> float | None:
        """[s] monotonic: what this robot sent before it has been read (RosserialServer)."""
        return self._server.listened_until_s

    @property
    def close_reason(self) -> str | None:
        """Why the session closed, as a sentence (None while connected)."""
        return self.session.close_reason

    @property
    def topics(self) -> dict[str, RobotTopic]:
        """Accepted topics by name, both directions."""
        return {**self.session.publishers, **self.session.subscribers}

    @property
    def problems(self) -> list[str]:
        return list(self.session.problems)

    @property
    def drops(self) -> Counter[str]:
        """Incoming frames dropped, by reason."""
        return self.session.drops

    def send(self, topic: str, message: Message, *, urgent: bool | None = None) -> None:
        """Send `message` on a topic the robot subscribes to; any thread.

        Raises TopicError or RobotDisconnected (a SessionError) at once, in the caller's thread;
        the frame is written on the rosserial thread, latest-wins (module docstring): it may wait
        for the robot's next frame, replaced by a newer command on the same topic. `urgent` (a
        stop; by default a zero geometry_msgs/Twist) is written at once unless the robot has not
        read the last ~16 KiB (then dropped and counted in ``outgoing_dropped``)."""
        frame = self.session.encode(topic, message)
        if urgent is None:
            urgent = _is_stop(message)
        self._server._call_on_loop(self._offer, topic, frame, urgent)

    @property
    def commands_waiting(self) -> int:
        """Commands held for the robot's next frame (at most one per topic)."""
        return len(self._held)

    def stop(self) -> None:
        """Put the robot at rest (zero velocity, LEDs off), send the tx-stop frame and close the
        connection at once; any thread. Nothing it sends afterwards is read."""
        self._server._call_on_loop(self._stop)

    def __repr__(self) -> str:
        return f"RobotConnection({self.id}, {self.peer[0]}:{self.peer[1]}, {self.state})"

    # --------------------------------------------------------------- rosserial thread only
    def _offer(self, topic: str, frame: bytes, urgent: bool) -> None:
        """Write a command now, or hold it as its topic's newest (module docstring)."""
        transport = self._transport
        if transport is None or transport.is_closing():
            return
        if urgent or self._may_write(topic):
            self._held.pop(topic, None)  # older than this one
            if urgent and topic in self._unanswered and self._last_written.get(topic) == frame:
                return  # the same stop again, and the robot has not even read the first
            self._write_command(topic, frame)
            return
        if topic in self._held:
            self.commands_replaced += 1
        self._held[topic] = frame

    def _may_write(self, topic: str) -> bool:
        transport = self._transport
        if transport is None or transport.is_closing():
            return False
        if transport.get_write_buffer_size() > 0:
            return False  # the socket has not taken what was written before
        # A robot that publishes nothing gives no sign of life to wait for.
        return not (self.session.publishers and topic in self._unanswered)

    def _write_command(self, topic: str, frame: bytes) -> None:
        transport = self._transport
        assert transport is not None
        if transport.get_write_buffer_size() > self._server.limits.max_write_buffer_bytes:
            self.outgoing_dropped += 1
            return
        self.session.queue_frame(frame)
        self._unanswered.add(topic)
        self._last_written[topic] = frame
        self._flush()

    def _heard(self, now_s: float) -> None:
        """The robot sent bytes: it is alive and reading, one more command per topic may go."""
        self.last_heard_s = now_s
        self._unanswered.clear()

    def _release(self) -> None:
        """Write the held commands that may go now."""
        for topic in list(self._held):
            if self._may_write(topic):
                self._write_command(topic, self._held.pop(topic))

    def _put_at_rest(self, topics: list[RobotTopic]) -> None:
        """Write the rest of each of `topics` now (server/hardware/rest.py), past the
        latest-wins slots: a stop never waits. Its frame is built from the topic itself, so it
        goes out in any state, even mid-negotiation."""
        transport = self._transport
        if transport is None or transport.is_closing():
            return
        for topic in topics:
            message = rest_message(topic.name, topic.message_class)
            if message is not None:
                self._held.pop(topic.name, None)  # a command that waited is older than this
                self._write_command(topic.name, encode_frame(topic.topic_id, message.serialize()))

    def _stop(self) -> None:
        self._put_at_rest(list(self.session.subscribers.values()))
        self._server._dispatch(self, self.session.stop())

    def _flush(self) -> None:
        data = self.session.data_to_send()
        transport = self._transport
        if data and transport is not None and not transport.is_closing():
            transport.write(data)


def _is_stop(message: Message) -> bool:
    """A zero velocity: stopping must not wait for the robot's next frame."""
    return isinstance(message, Twist) and message == Twist()


class _Connection(asyncio.BufferedProtocol):
    """asyncio glue for one socket: reads into a fixed buffer, feeds the session."""

    def __init__(self, server: RosserialServer) -> None:
        self._server = server
        self._buffer = bytearray(server.limits.read_buffer_bytes)
        self._robot: RobotConnection | None = None
        self._window_start_s = 0.0
        self._window_bytes = 0

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        server = self._server
        peer = transport.get_extra_info("peername") or ("?", 0)
        if not server._admit(str(peer[0])):
            transport.abort()
            return
        if len(server._robots) >= server.limits.max_connections:
            logger.warning(
                "rosserial: refused %s:%s, already %d robots connected (max_connections)",
                peer[0],
                peer[1],
                len(server._robots),
            )
            transport.abort()
            return
        sock = transport.get_extra_info("socket")
        if sock is not None:
            with contextlib.suppress(OSError):
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE, 1)
                sock.setsockopt(
                    socket.SOL_SOCKET, socket.SO_SNDBUF, server.limits.socket_send_buffer_bytes
                )
        session = RosserialSession(clock_ns=server.clock_ns, limits=server.limits)
        robot = RobotConnection(server, f"robot-{next(server._ids)}", (peer[0], peer[1]), session)
        robot._transport = transport
        self._robot = robot
        server._robots[robot.id] = robot
        logger.info("rosserial: %s connected from %s:%s", robot.id, peer[0], peer[1])
        session.start(time.monotonic())
        robot._flush()

    def get_buffer(self, sizehint: int) -> memoryview:
        return memoryview(self._buffer)

    def buffer_updated(self, nbytes: int) -> None:
        robot = self._robot
        if robot is None or robot.session.state is SessionState.CLOSED:
            return
        now_s = time.monotonic()
        self._limit_rate(now_s, nbytes)
        robot._heard(now_s)  # before the handlers: their answers to these frames go at once
        events = robot.session.receive_data(memoryview(self._buffer)[:nbytes], now_s)
        self._server._dispatch(robot, events)
        robot._release()  # what still waits from before these frames

    def _limit_rate(self, now_s: float, nbytes: int) -> None:
        """Past max_bytes_per_s, stop reading until the second is over (TCP pushes back)."""
        if now_s - self._window_start_s >= 1.0:
            self._window_start_s, self._window_bytes = now_s, 0
        self._window_bytes += nbytes
        robot = self._robot
        if self._window_bytes >= self._server.limits.max_bytes_per_s and robot is not None:
            transport = robot._transport
            if transport is not None and transport.is_reading():
                transport.pause_reading()
                robot.reads_paused += 1
                asyncio.get_running_loop().call_later(
                    max(0.0, self._window_start_s + 1.0 - now_s), self._resume
                )

    def _resume(self) -> None:
        robot = self._robot
        if robot is not None and robot._transport is not None:
            transport = robot._transport
            if not transport.is_closing() and not transport.is_reading():
                transport.resume_reading()

    def eof_received(self) -> bool:
        return False  # close the transport: the robot closed its side

    def connection_lost(self, exc: Exception | None) -> None:
        robot = self._robot
        if robot is None:
            return
        reason = f"connection lost: {exc}" if exc else "the robot closed the connection"
        self._server._dispatch(robot, robot.session.close(reason))
        self._server._forget(robot)


class RosserialServer:
    """rosserial host over TCP; see the module docstring. ``start()``/``stop()`` or ``with``."""

    def __init__(
        self,
        handler: RosserialHandler | None = None,
        *,
        host: str = "127.0.0.1",
        port: int = DEFAULT_PORT,
        limits: RosserialLimits = DEFAULT_LIMITS,
        clock_ns: Callable[[], int] = time.time_ns,
    ) -> None:
        self.handler = handler or RosserialHandler()
        self.host = host
        self._requested_port = port
        self.limits = limits
        self.clock_ns = clock_ns
        self._robots: dict[str, RobotConnection] = {}
        self._ids = itertools.count(1)
        self.admission = AdmissionControl(limits)
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._listener: asyncio.Server | None = None
        self._port: int | None = None
        self.handler_errors = 0
        # [s] monotonic: every byte a robot sent before this has been read and dispatched (the
        # rosserial thread's beat before last; `_beat`). None until the thread has beaten twice.
        self.listened_until_s: float | None = None
        self._last_beat_s: float | None = None

    # ------------------------------------------------------------------------ any thread
    @property
    def port(self) -> int:
        """The TCP port listened on (the real one when constructed with port=0)."""
        if self._port is None:
            raise RuntimeError("the rosserial server is not running; call start() first")
        return self._port

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def robots(self) -> list[RobotConnection]:
        """The connections open now (a snapshot)."""
        return list(self._robots.values())

    def start(self) -> None:
        """Listen (in the rosserial thread); returns once bound. Raises OSError with the
        address when the port cannot be bound."""
        if self._thread is not None:
            raise RuntimeError("this RosserialServer was already started; make a new one")
        started = threading.Event()
        failure: list[BaseException] = []
        self._thread = threading.Thread(
            target=self._run, args=(started, failure), name="rosserial", daemon=True
        )
        self._thread.start()
        started.wait()
        if failure:
            self._thread.join()
            error = failure[0]
            raise OSError(
                f"rosserial server cannot listen on {self.host}:{self._requested_port}: {error}"
            ) from error

    def stop(self, timeout_s: float = 5.0) -> None:
        """Send tx-stop to every robot, close the connections and the listener, end the
        thread. Safe to call twice."""
        loop, thread = self._loop, self._thread
        if loop is None or thread is None or not thread.is_alive():
            return
        if threading.current_thread() is thread:
            raise RuntimeError(
                "RosserialServer.stop() was called from a handler (the rosserial thread); call "
                "robot.stop() there, or stop the server from another thread"
            )
        future = asyncio.run_coroutine_threadsafe(self._shutdown(), loop)
        with contextlib.suppress(TimeoutError):
            future.result(timeout_s)
        loop.call_soon_threadsafe(loop.stop)
        thread.join(timeout_s)

    def __enter__(self) -> RosserialServer:
        self.start()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.stop()

    def _call_on_loop(self, function: Callable[..., None], *args: object) -> None:
        loop = self._loop
        if loop is None or loop.is_closed():
            return
        if threading.current_thread() is self._thread:
            function(*args)
        else:
            with contextlib.suppress(RuntimeError):  # loop closed in between: nothing to do
                loop.call_soon_threadsafe(function, *args)

    # ------------------------------------------------------------------------ rosserial thread
    def _run(self, started: threading.Event, failure: list[BaseException]) -> None:
        loop = asyncio.new_event_loop()
        self._loop = loop
        try:
            try:
                self._listener = loop.run_until_complete(
                    loop.create_server(
                        lambda: _Connection(self),
                        self.host,
                        self._requested_port,
                        reuse_address=True,
                    )
                )
            except OSError as error:
                failure.append(error)
                return
            self._port = self._listener.sockets[0].getsockname()[1]
            logger.info("rosserial: listening on %s:%d", self.host, self._port)
            loop.call_later(self.limits.poll_interval_s, self._poll)
            loop.call_soon(self._beat)
            started.set()
            loop.run_forever()
        finally:
            started.set()
            with contextlib.suppress(Exception):
                loop.run_until_complete(loop.shutdown_asyncgens())
            loop.close()

    async def _shutdown(self) -> None:
        for robot in list(self._robots.values()):
            robot._stop()  # at rest, then tx-stop
        if self._listener is not None:
            self._listener.close()
            await self._listener.wait_closed()
        await asyncio.sleep(0.05)  # transports write their tx-stop and close

    def _admit(self, host: str) -> bool:
        """Ask the handler whether `host` gets a session (back-off first); make room among the
        address's unfinished handshakes. False: close the peer now."""
        now_s = time.monotonic()
        if self.admission.backed_off(host, now_s):
            return False
        try:
            refusal = self.handler.admit(host)
        except Exception:
            self.handler_errors += 1
            logger.exception("rosserial: handler admit raised")
            refusal = Refusal("the server could not check the address (see the error above)", False)
        if refusal is not None:
            self.admission.refuse(host, refusal, now_s)
            return False
        pending = sorted(
            (r for r in self._robots.values() if r.peer[0] == host and not r.announced),
            key=lambda r: r.started_s,
        )
        for old in pending[: max(0, len(pending) - self.limits.max_pending_per_address + 1)]:
            self._dispatch(
                old,
                old.session.close(
                    f"a newer connection from {host} came before this one finished its handshake"
                ),
            )
        return True

    def _poll(self) -> None:
        now_s = time.monotonic()
        limit_s = self.limits.handshake_timeout_s
        for robot in list(self._robots.values()):
            self._dispatch(robot, robot.session.poll(now_s))
            robot._release()  # commands that waited only for the socket to drain
            if not robot.announced and robot.connected and now_s - robot.started_s > limit_s:
                self._dispatch(
                    robot,
                    robot.session.close(
                        f"no rosserial handshake within {limit_s:g} s of connecting (topics "
                        "not advertised): closed so it cannot hold a connection slot"
                    ),
                )
        loop = self._loop
        if loop is not None and loop.is_running():
            loop.call_later(self.limits.poll_interval_s, self._poll)

    def _beat(self) -> None:
        """Note how far the sockets have been read. This callback runs in a later turn of the
        loop than the previous beat, after a select() that began once that beat was over, so
        every byte that arrived before the previous beat has been read and dispatched by now.
        A thread starved by a busy host beats late, and a run's silence watchdog
        (server/hardware/backend.py) then does not count the robot silent past this time."""
        now_s = time.monotonic()
        if self._last_beat_s is not None:
            self.listened_until_s = self._last_beat_s
        self._last_beat_s = now_s
        loop = self._loop
        if loop is not None and loop.is_running():
            loop.call_later(self.limits.listen_beat_s, self._beat)

    def _forget(self, robot: RobotConnection) -> None:
        self._robots.pop(robot.id, None)
        robot._transport = None

    def _dispatch(self, robot: RobotConnection, events: list[SessionEvent]) -> None:
        robot._flush()  # answers (time, topic requests) go out before handlers run
        handler = self.handler
        for event in events:
            if isinstance(event, MessageReceived):
                self._call(handler.on_message, robot, event.topic, event.message)
            elif isinstance(event, LogLine):
                logger.log(_LOG_LEVELS[event.level], "rosserial %s: %s", robot.id, event.text)
                self._call(handler.on_log, robot, event.level, event.text)
            elif isinstance(event, Ready):
                robot.announced = True
                logger.info(
                    "rosserial: %s ready: publishes %s; subscribes %s%s",
                    robot.id,
                    ", ".join(robot.session.publishers) or "nothing",
                    ", ".join(robot.session.subscribers) or "nothing",
                    f"; {len(robot.session.problems)} problem(s)" if robot.session.problems else "",
                )
                self._call(handler.on_robot_connected, robot)
            elif isinstance(event, TopicRegistered):
                topic = event.topic
                if topic.direction is Direction.SUBSCRIBES:
                    robot._put_at_rest([topic])  # before anyone can command it (docstring)
                logger.info(
                    "rosserial %s: setup %s on %s [%s]",
                    robot.id,
                    "publisher" if topic.direction == "publishes" else "subscriber",
                    topic.name,
                    topic.message_type,
                )
            elif isinstance(event, (Problem, SyncLost)):
                text = event.text if isinstance(event, Problem) else event.reason
                level = LogLevel.ERROR if isinstance(event, Problem) else LogLevel.WARN
                logger.log(_LOG_LEVELS[level], "rosserial %s: %s", robot.id, text)
                self._call(handler.on_log, robot, level, text)
            elif isinstance(event, TopicRefused):
                pass  # its sentence follows as a Problem
            elif isinstance(event, Closed):
                robot._flush()
                transport = robot._transport
                if transport is not None and not transport.is_closing():
                    transport.close()  # writes what is buffered (the tx-stop), then closes
                logger.info("rosserial: %s disconnected: %s", robot.id, event.reason)
                self._forget(robot)
                if robot.announced:
                    self._call(handler.on_robot_disconnected, robot, event.reason)
        robot._flush()  # what handlers sent from this thread

    def _call(self, method: Callable[..., None], *args: object) -> None:
        try:
            method(*args)
        except Exception:
            self.handler_errors += 1
            logger.exception("rosserial: handler %s raised", getattr(method, "__name__", method))
