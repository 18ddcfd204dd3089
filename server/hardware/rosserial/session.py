"""One rosserial connection's protocol state machine, as rosserial_python's SerialClient runs it.

Pure (sans-IO): ``receive_data(bytes, now_s)`` and ``poll(now_s)`` return typed events, and the
bytes to write to the robot collect in ``data_to_send()``. The caller owns the socket and the
monotonic clock; the wall clock answering time requests is injected (``clock_ns``)::

    session = RosserialSession(clock_ns=time.time_ns)
    session.start(now_s)                       # queues the topic request
    sock.send(session.data_to_send())
    for event in session.receive_data(sock.recv(4096), now_s): ...
    session.send("Control", Twist(...))        # a topic the robot subscribes to

States (checked; an illegal transition raises SessionError)::

    CONNECTING --start()--> NEGOTIATING --topics advertised--> READY
         any state --close()/stop()/timeouts--> CLOSED

Behaviour and its sources (rosserial_python SerialClient.py, noetic-devel; ros_lib
node_handle.h; shared/notes/protocols.md):

- start: request topics, ``ff fe 00 00 ff 00 00 ff``; the device answers with a time request and
  one TopicInfo per publisher (id 0) and per subscriber (id 1), all back to back.
- TopicInfo: the advertised md5sum must equal ours for that type name (``Publisher.__init__``
  raises "Checksum does not match"); here a mismatch or an unknown type refuses the topic with
  a sentence naming both sums, kept in ``problems`` for the instructor.
- time request (id 10): answered with std_msgs/Time = the injected clock (``handleTimeRequest``).
  ros_lib's request carries a zeroed std_msgs/Time (8 bytes); any payload is accepted.
- log (id 7): a LogLine event (``handleLoggingRequest``).
- a frame on an id nobody advertised: "Tried to publish before configured", topics requested
  again (rate limited here).
- no time request for ``sync_timeout_s`` (rosserial_python: 3 x 5 s): "Lost sync with device",
  topics requested again; nothing at all for ``idle_timeout_s``: the connection is closed.
- stop: the tx-stop frame ``ff fe 00 00 ff 0b 00 f4`` (``txStopRequest``); ros_lib then drops
  its configuration and stops publishing.
- send: refused when the payload exceeds the robot's receive buffer (rosserial_python logs
  "message larger than buffer"; ros_lib would overrun message_in, it does not check).
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum

from sandbox.msgs import (
    DeserializationError,
    Message,
    UnknownMessageTypeError,
    get_message_class,
)
from sandbox.msgs import Time as RosTime
from sandbox.msgs.std_msgs import Time as TimeMessage
from sandbox.units import NS_PER_S
from server.hardware.rosserial.events import (
    Closed,
    Direction,
    LogLine,
    MessageReceived,
    Problem,
    Ready,
    RobotTopic,
    SessionEvent,
    SyncLost,
    TopicRefused,
    TopicRegistered,
)
from server.hardware.rosserial.frames import (
    FIRST_DYNAMIC_TOPIC_ID,
    PROTOCOL_VERSION,
    PROTOCOL_VERSION_NAMES,
    REQUEST_TOPICS_FRAME,
    TX_STOP_FRAME,
    DropReason,
    Frame,
    FrameParser,
    TopicId,
    encode_frame,
)
from server.hardware.rosserial.limits import DEFAULT_LIMITS, RosserialLimits
from server.hardware.rosserial.messages import Log, LogLevel, TopicInfo

_SERVICE_IDS = {
    TopicId.SERVICE_SERVER,
    TopicId.SERVICE_SERVER + 1,
    TopicId.SERVICE_CLIENT,
    TopicId.SERVICE_CLIENT + 1,
}
RATE_LIMITED = "rate_limited"  # key in ``drops`` for data frames over max_frames_per_s


class SessionState(StrEnum):
    CONNECTING = "connecting"
    NEGOTIATING = "negotiating"
    READY = "ready"
    CLOSED = "closed"


_TRANSITIONS: dict[SessionState, frozenset[SessionState]] = {
    SessionState.CONNECTING: frozenset({SessionState.NEGOTIATING, SessionState.CLOSED}),
    SessionState.NEGOTIATING: frozenset({SessionState.READY, SessionState.CLOSED}),
    SessionState.READY: frozenset({SessionState.CLOSED}),
    SessionState.CLOSED: frozenset(),
}


class SessionError(RuntimeError):
    """A call the session cannot take in its current state; the message says what to do."""


class RobotDisconnected(SessionError):
    """``send()`` after the session closed (the robot went away, or was stopped)."""


class TopicError(ValueError):
    """``send()`` to a topic the robot does not subscribe to, or with the wrong message."""


@dataclass(slots=True)
class SessionStats:
    """Counters of one session (frame drops by reason are in ``RosserialSession.drops``)."""

    messages_in: int = 0
    time_requests: int = 0
    log_lines: int = 0
    undecodable: int = 0
    unknown_topic_frames: int = 0
    topic_requests: int = 0
    sync_losses: int = 0
    messages_out: int = 0
    outbox_dropped: int = 0
    rate_limited: int = 0  # data frames over max_frames_per_s, dropped
    reserved_ignored: int = 0  # frames on reserved ids a device never sends (e.g. 11)
    bytes_in: int = 0


class RosserialSession:
    """The host side of one rosserial connection. See the module docstring for the contract."""

    def __init__(
        self,
        *,
        clock_ns: Callable[[], int] = time.time_ns,
        limits: RosserialLimits = DEFAULT_LIMITS,
        resolve_type: Callable[[str], type[Message]] = get_message_class,
    ) -> None:
        self.limits = limits
        self._clock_ns = clock_ns
        self._resolve_type = resolve_type
        self.state = SessionState.CONNECTING
        self.close_reason: str | None = None
        self.parser = FrameParser(limits.max_payload_bytes)
        self.publishers: dict[str, RobotTopic] = {}  # robot -> host, by topic name
        self.subscribers: dict[str, RobotTopic] = {}  # host -> robot, by topic name
        self._by_id: dict[int, RobotTopic] = {}  # publishers by the robot's topic id
        self._problems: dict[str, str] = {}  # key -> sentence, for the instructor
        self.stats = SessionStats()
        self.synced = False  # a time request has been answered since the last topic request
        self._outbox = bytearray()
        self._advertisements = 0  # TopicInfo frames received (accepted or refused)
        self._foreign_versions_seen = 0
        self._once: set[str] = set()
        self._started_s = self._last_rx_s = self._last_sync_s = 0.0
        self.last_time_request_s: float | None = None  # [s] monotonic, the robot's latest
        self._last_topic_info_s = self._last_request_s = 0.0
        self._rate_window_s = 0.0
        self._rate_count = 0

    # ------------------------------------------------------------------------------ lifecycle
    def start(self, now_s: float) -> None:
        """Begin: queue the topic request (CONNECTING -> NEGOTIATING)."""
        self._transition(SessionState.NEGOTIATING)
        self._started_s = self._last_rx_s = self._last_sync_s = now_s
        self._request_topics(now_s)

    def stop(self) -> list[SessionEvent]:
        """Queue the tx-stop frame (the robot stops publishing) and close the session."""
        if self.state is SessionState.CLOSED:
            return []
        if self.state is not SessionState.CONNECTING:
            self._queue(TX_STOP_FRAME)
        return self.close("stopped by RoboDojo (tx stop sent)")

    def close(self, reason: str) -> list[SessionEvent]:
        """End the session (the connection went away, or the server shuts down)."""
        if self.state is SessionState.CLOSED:
            return []
        self._transition(SessionState.CLOSED)
        self.close_reason = reason
        return [Closed(reason)]

    @property
    def problems(self) -> list[str]:
        """What the instructor should know, each once. Frames on a topic id sent before the
        robot advertised it are forgotten once it does (ros_lib publishes before it answers a
        reconnection's topic request): a clean handshake clears them."""
        return list(self._problems.values())

    @property
    def drops(self) -> Counter[str]:
        """Frames dropped, by reason: the parser's DropReasons plus ``rate_limited``."""
        counts: Counter[str] = Counter({str(k): v for k, v in self.parser.drops.items()})
        if self.stats.rate_limited:
            counts[RATE_LIMITED] = self.stats.rate_limited
        return counts

    # ------------------------------------------------------------------------------ input
    def receive_data(
        self, data: bytes | bytearray | memoryview, now_s: float
    ) -> list[SessionEvent]:
        """Bytes from the robot -> events; answers (time, topic requests) go to the outbox."""
        self._require_open("receive_data()")
        self.stats.bytes_in += len(data)
        self._last_rx_s = now_s
        frames = self.parser.feed(data)
        return self._after_parse(frames, now_s)

    def poll(self, now_s: float) -> list[SessionEvent]:
        """Run the timers: frame timeout, end of negotiation, sync loss, silence."""
        if self.state in (SessionState.CONNECTING, SessionState.CLOSED):
            return []
        limits = self.limits
        events: list[SessionEvent] = []
        quiet_s = now_s - self._last_rx_s
        if self.parser.buffered_bytes and quiet_s > limits.frame_timeout_s:
            events += self._after_parse(self.parser.expire(), now_s)
            while self.parser.buffered_bytes and self.state is not SessionState.CLOSED:
                # Each expiry frees one bogus header; the rest may hide more (all quiet alike).
                events += self._after_parse(self.parser.expire(), now_s)
        if self.state is SessionState.CLOSED:
            return events
        if quiet_s > limits.idle_timeout_s:
            return events + self.close(
                f"the robot sent nothing for {quiet_s:.0f} s (powered off, out of WiFi range, "
                "or a half-open connection)"
            )
        if self.state is SessionState.NEGOTIATING:
            negotiating_s = now_s - self._started_s
            if self._advertisements and now_s - self._last_topic_info_s >= limits.settle_s:
                events += self._become_ready()
            elif not self._advertisements and negotiating_s > limits.negotiation_timeout_s:
                return events + self.close(
                    f"no topic advertised within {limits.negotiation_timeout_s:.0f} s of the "
                    "topic request: is this a rosserial client (ros_lib of ROS Hydro or newer)?"
                )
        if now_s - self._last_sync_s > limits.sync_timeout_s:
            self.stats.sync_losses += 1
            if self.synced:
                reason = (
                    f"lost sync with the robot (no time request for {limits.sync_timeout_s:.0f} "
                    "s); requesting topics again"
                )
            elif self.last_time_request_s is not None:
                reason = (
                    "still no sync with the robot: its last time request came "
                    f"{now_s - self.last_time_request_s:.0f} s ago and it has not answered the "
                    "topic request since (frozen firmware or a stalled WiFi link?); requesting "
                    "topics again"
                )
            else:
                reason = (
                    "unable to sync with the robot (it never asked for the time); possible link "
                    "problem or rosserial version mismatch; requesting topics again"
                )
            self.synced = False
            self._last_sync_s = now_s
            self._request_topics(now_s)
            events.append(SyncLost(reason))
        return events

    def _after_parse(self, frames: list[Frame], now_s: float) -> list[SessionEvent]:
        events: list[SessionEvent] = []
        foreign = self.parser.drops[DropReason.WRONG_PROTOCOL_VERSION]
        if foreign > self._foreign_versions_seen:
            self._foreign_versions_seen = foreign
            version = self.parser.foreign_version or 0
            found = PROTOCOL_VERSION_NAMES.get(version, "unrecognized")
            events += self._problem(
                f"Mismatched protocol version in packet (0x{version:02x}): lost sync, or the "
                f"robot's rosserial client is from another ROS release; protocol version of the "
                f"client is {found}, expected {PROTOCOL_VERSION_NAMES[PROTOCOL_VERSION]} "
                "(rebuild the firmware with a ros_lib of ROS Hydro or newer)",
                key="protocol-version",
            )
        for frame in frames:
            if self.state is SessionState.CLOSED:
                break
            events += self._handle(frame, now_s)
        return events

    def _handle(self, frame: Frame, now_s: float) -> list[SessionEvent]:
        topic_id = frame.topic_id
        if topic_id >= FIRST_DYNAMIC_TOPIC_ID:
            return self._topic_data(frame, now_s)
        if topic_id == TopicId.TIME:
            self.stats.time_requests += 1
            self.synced = True
            self._last_sync_s = self.last_time_request_s = now_s
            secs, nsecs = divmod(self._clock_ns(), NS_PER_S)
            self._queue(encode_frame(TopicId.TIME, TimeMessage(RosTime(secs, nsecs)).serialize()))
            return []
        if topic_id in (TopicId.PUBLISHER, TopicId.SUBSCRIBER):
            return self._topic_info(frame, now_s)
        if topic_id == TopicId.LOG:
            return self._log(frame)
        if topic_id in _SERVICE_IDS:
            name = _peek_topic_name(frame.payload)
            return self._problem(
                f"the robot advertised service '{name}'; RoboDojo's rosserial host carries "
                "topics only, so the service is not available",
                key=f"service:{name}",
            )
        if topic_id == TopicId.PARAMETER_REQUEST:
            name = _peek_string(frame.payload)
            return self._problem(
                f"the robot asked for parameter '{name}'; RoboDojo serves no parameters, so the "
                "robot's requestParam() times out and it keeps its default",
                key=f"param:{name}",
            )
        self.stats.reserved_ignored += 1
        return []

    def _topic_data(self, frame: Frame, now_s: float) -> list[SessionEvent]:
        topic = self._by_id.get(frame.topic_id)
        if topic is None:
            self.stats.unknown_topic_frames += 1
            events = self._problem(
                f"Tried to publish before configured, topic id {frame.topic_id}: the robot "
                "sends on a topic it has not advertised (requesting topics again)",
                key=f"unknown-id:{frame.topic_id}",
            )
            if now_s - self._last_request_s >= self.limits.request_topics_interval_s:
                self._request_topics(now_s)
            return events
        if now_s - self._rate_window_s >= 1.0:
            self._rate_window_s, self._rate_count = now_s, 0
        self._rate_count += 1
        if self._rate_count > self.limits.max_frames_per_s:
            self.stats.rate_limited += 1
            return []
        try:
            message = topic.message_class.deserialize(frame.payload)
        except DeserializationError as error:
            self.stats.undecodable += 1
            return self._problem(
                f"a frame on '{topic.name}' is not a valid {topic.message_type}: {error}",
                key=f"undecodable:{topic.name}",
            )
        self.stats.messages_in += 1
        events: list[SessionEvent] = []
        if self.state is SessionState.NEGOTIATING:
            events += self._become_ready()
        events.append(MessageReceived(topic.name, message))
        return events

    def _topic_info(self, frame: Frame, now_s: float) -> list[SessionEvent]:
        publisher = frame.topic_id == TopicId.PUBLISHER
        direction = Direction.PUBLISHES if publisher else Direction.SUBSCRIBES
        try:
            info = TopicInfo.deserialize(frame.payload)
        except DeserializationError as error:
            return self._problem(f"a topic advertisement (TopicInfo) could not be decoded: {error}")
        self._advertisements += 1
        self._last_topic_info_s = now_s
        name, message_type = info.topic_name, info.message_type
        refusal = self._refusal(info)
        if refusal is not None:
            return [TopicRefused(name, message_type, refusal), *self._problem(refusal)]
        topic = RobotTopic(
            name=name,
            topic_id=info.topic_id,
            message_type=message_type,
            direction=direction,
            buffer_size=info.buffer_size,
            message_class=self._resolve_type(message_type),
        )
        table = self.publishers if direction is Direction.PUBLISHES else self.subscribers
        if table.get(name) == topic:
            if direction is Direction.PUBLISHES:
                self._forget_problem(f"unknown-id:{topic.topic_id}")
            return []  # advertised again after a new topic request: nothing changed
        old = table.get(name)
        if old is not None and direction is Direction.PUBLISHES:
            self._by_id.pop(old.topic_id, None)
        table[name] = topic
        if direction is Direction.PUBLISHES:
            self._by_id[topic.topic_id] = topic
            self._forget_problem(f"unknown-id:{topic.topic_id}")
        return [TopicRegistered(topic)]

    def _refusal(self, info: TopicInfo) -> str | None:
        name, message_type, theirs = info.topic_name, info.message_type, info.md5sum
        if info.topic_id < FIRST_DYNAMIC_TOPIC_ID:
            return (
                f"topic '{name}' was advertised on reserved id {info.topic_id} (ids below "
                f"{FIRST_DYNAMIC_TOPIC_ID} belong to the protocol); the topic is refused"
            )
        if info.buffer_size <= 0:
            return f"topic '{name}' was advertised with a buffer of {info.buffer_size} bytes"
        try:
            ours = self._resolve_type(message_type)._md5sum
        except UnknownMessageTypeError as error:
            # The error names close matches; the full list (140 types) would drown them.
            return (
                f"topic '{name}': RoboDojo has no message type {message_type!r} (the robot's "
                f"md5sum is {theirs}), so the topic is refused: {error}"
            )
        if ours != theirs:
            return (
                f"topic '{name}' ({message_type}): Checksum does not match: RoboDojo's md5sum is "
                f"{ours}, the robot's is {theirs}; the two definitions of {message_type} differ, "
                "so the topic is refused (rebuild the firmware's ros_lib from the standard "
                "message definitions)"
            )
        return None

    def _log(self, frame: Frame) -> list[SessionEvent]:
        try:
            log = Log.deserialize(frame.payload)
        except DeserializationError as error:
            return self._problem(f"a log frame from the robot could not be decoded: {error}")
        self.stats.log_lines += 1
        try:
            level = LogLevel(log.level)
        except ValueError:
            level = LogLevel.INFO
        return [LogLine(level, log.msg)]

    def _become_ready(self) -> list[SessionEvent]:
        self._transition(SessionState.READY)
        return [Ready()]

    # ------------------------------------------------------------------------------ output
    def encode(self, topic: str, message: Message) -> bytes:
        """The frame carrying `message` on `topic`, checked; no state changes (thread-safe to
        call while the connection thread runs the session, as it only reads topic tables)."""
        if self.state is SessionState.CLOSED:
            raise RobotDisconnected(
                f"the robot is disconnected ({self.close_reason}); wait for it to reconnect"
            )
        target = self.subscribers.get(topic)
        if target is None:
            subscribed = ", ".join(sorted(self.subscribers)) or "nothing yet"
            if topic in self.publishers:
                raise TopicError(
                    f"'{topic}' is a topic the robot publishes "
                    f"({self.publishers[topic].message_type}); send commands to a topic it "
                    f"subscribes to: {subscribed}"
                )
            raise TopicError(
                f"the robot does not subscribe to '{topic}'; it subscribes to: {subscribed}"
            )
        if not isinstance(message, target.message_class):
            got = getattr(message, "_type", type(message).__name__)
            raise TopicError(f"topic '{topic}' carries {target.message_type}, got {got}")
        payload = message.serialize()
        if len(payload) > target.buffer_size:
            raise TopicError(
                f"a {len(payload)}-byte {target.message_type} does not fit the robot's "
                f"{target.buffer_size}-byte receive buffer for '{topic}'; send a smaller message"
            )
        return encode_frame(target.topic_id, payload)

    def send(self, topic: str, message: Message) -> None:
        """Queue `message` for a topic the robot subscribes to (see ``encode`` for checks)."""
        self._queue(self.encode(topic, message))
        self.stats.messages_out += 1

    def queue_frame(self, frame: bytes) -> None:
        """Queue an already encoded frame (from ``encode``) unless the session has closed."""
        if self.state is not SessionState.CLOSED:
            self._queue(frame)
            self.stats.messages_out += 1

    def data_to_send(self) -> bytes:
        """The bytes queued for the robot since the last call."""
        data = bytes(self._outbox)
        self._outbox.clear()
        return data

    # ------------------------------------------------------------------------------ helpers
    def _request_topics(self, now_s: float) -> None:
        self.stats.topic_requests += 1
        self._last_request_s = now_s
        self._queue(REQUEST_TOPICS_FRAME)

    def _queue(self, frame: bytes) -> None:
        if len(self._outbox) + len(frame) > self.limits.max_outbox_bytes:
            self.stats.outbox_dropped += 1
            return
        self._outbox += frame

    def _problem(self, text: str, key: str | None = None) -> list[SessionEvent]:
        key = key or text
        if key in self._once:
            return []
        if len(self._once) < self.limits.max_problems:
            self._once.add(key)
            self._problems[key] = text
        return [Problem(text)]

    def _forget_problem(self, key: str) -> None:
        """The handshake explained it: drop it, and report it again if it comes back."""
        if self._problems.pop(key, None) is not None:
            self._once.discard(key)

    def _require_open(self, call: str) -> None:
        if self.state is SessionState.CONNECTING:
            raise SessionError(f"call start() before {call}: the topic request comes first")
        if self.state is SessionState.CLOSED:
            raise SessionError(
                f"{call} on a closed session ({self.close_reason}); a new connection needs a "
                "new RosserialSession"
            )

    def _transition(self, new: SessionState) -> None:
        if new not in _TRANSITIONS[self.state]:
            raise SessionError(f"a rosserial session cannot go from {self.state} to {new}")
        self.state = new


def _peek_string(payload: bytes, offset: int = 0) -> str:
    """A ROS string at `offset` (uint32 length + UTF-8), or '?' when it is not one."""
    if len(payload) < offset + 4:
        return "?"
    length = int.from_bytes(payload[offset : offset + 4], "little")
    raw = payload[offset + 4 : offset + 4 + length]
    if len(raw) != length:
        return "?"
    return raw.decode("utf-8", "replace")


def _peek_topic_name(payload: bytes) -> str:
    """The topic_name of a TopicInfo payload (after its uint16 topic_id)."""
    return _peek_string(payload, 2)
