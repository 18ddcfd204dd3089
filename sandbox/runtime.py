"""The node's side of the topic graph: its topic table, outbox, subscribers and sleeps.

One `NodeRuntime` exists per node, created by the host (sandbox/host.py) after `Load`. The rospy
shim (sandbox/ros_compat/rospy) and the step API (sandbox/step_api.py) are thin layers over it,
and all state lives here, so the shim holds none of its own.

A sleep is the only place the node talks to the parent: `wait_until()` sends a `Yield` with what
was published since the last one, blocks for the next frame, and on `Wake` sets the clock and
runs subscriber callbacks in delivery order (as rospy runs them inside sleep()/spin()); on
`Shutdown` it runs the on_shutdown hooks and raises `ROSInterruptException`.
"""

from __future__ import annotations

import difflib
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from sandbox.msgs import Message, get_message_class
from sandbox.protocol import (
    Envelope,
    NodeInfo,
    ProtocolError,
    Shutdown,
    TopicDecl,
    Wake,
    Yield,
)
from sandbox.vclock import NodeClock

WAKE_TOLERANCE_NS = 1_000  # [ns] a wake this close to the target counts as on time (float s)


# rospy's exception hierarchy (names and bases as in rospy.exceptions).
class ROSException(Exception):
    """Base of the errors the rospy API raises."""


class ROSInitException(ROSException):
    """The node is used before rospy.init_node() or initialised twice."""


class ROSSerializationException(ROSException):
    """A message could not be serialized (a field holds a value its type cannot encode)."""


class ROSInterruptException(ROSException, KeyboardInterrupt):
    """A sleep or wait was interrupted by shutdown."""


class NodeFailure(BaseException):
    """Student code raised inside a callback or hook; carries the original exception.

    A BaseException so a student's `except Exception:` around rate.sleep() cannot hide it.
    """

    def __init__(self, original: BaseException) -> None:
        super().__init__(original)
        self.original = original


class LinkLost(BaseException):
    """The pipe to the parent broke; carries the ProtocolError for the runner."""


@dataclass(eq=False)
class Subscription:
    topic: str
    data_class: type[Message]
    callback: Callable[..., Any] | None
    callback_args: Any = None

    def invoke(self, message: Message) -> None:
        if self.callback is None:
            return
        if self.callback_args is None:
            self.callback(message)
        else:
            self.callback(message, self.callback_args)


@dataclass
class _Shutdown:
    reason: str
    by_parent: bool


@dataclass
class NodeRuntime:
    link: Any  # sandbox.host.Link
    info: NodeInfo
    clock: NodeClock
    node_name: str | None = None  # "/name" once init_node() ran (or the step API started)
    implicit_name: bool = False  # named by the step API; init_node() may rename it
    log_level: int = 2  # rospy.INFO
    params: dict[str, Any] = field(default_factory=dict)
    outbox: list[Envelope] = field(default_factory=list)
    latest: dict[str, Envelope] = field(default_factory=dict)
    failure: BaseException | None = None
    log_sites: dict[tuple[Any, ...], int] = field(default_factory=dict)  # throttle/once state
    shutdown: _Shutdown | None = None
    _types: dict[str, str] = field(default_factory=dict)  # topic -> type, robot's and new ones
    _robot: dict[str, tuple[str, str]] = field(default_factory=dict)  # name -> (type, direction)
    _advertised: set[str] = field(default_factory=set)
    _advertise_checked: dict[tuple[str, Any], str] = field(default_factory=dict)
    _subscribed: set[str] = field(default_factory=set)
    _new_advertised: list[TopicDecl] = field(default_factory=list)
    _new_subscribed: list[TopicDecl] = field(default_factory=list)
    _subscribers: dict[str, list[Subscription]] = field(default_factory=dict)
    _hooks: list[Callable[[], Any]] = field(default_factory=list)
    _callback_depth: int = 0

    def __post_init__(self) -> None:
        for topic in self.info.robot_topics:
            self._robot[topic.name] = (topic.type, topic.direction)
            self._types[topic.name] = topic.type
        self.params = {normalize_param(key): value for key, value in self.info.params.items()}

    # ------------------------------------------------------------------ state and contracts
    @property
    def is_shutdown(self) -> bool:
        return self.shutdown is not None

    def require_init(self, what: str) -> None:
        if self.node_name is None:
            raise ROSInitException(
                f"{what} needs a node: call rospy.init_node('my_node') first, once, near the "
                "top of the script"
            )

    def sensor_topics(self) -> list[str]:
        return [name for name, (_, way) in self._robot.items() if way == "publish"]

    def command_topics(self) -> list[str]:
        return [name for name, (_, way) in self._robot.items() if way == "subscribe"]

    def _unknown_topic(self, name: str) -> ROSException:
        names = list(self._types)
        by_lower = {topic.lower(): topic for topic in names}
        close = difflib.get_close_matches(name.lower(), list(by_lower), n=1)
        hint = f"did you mean '{by_lower[close[0]]}'? " if close else ""
        return ROSException(
            f"unknown topic '{name}' on robot {self.info.robot}; {hint}its topics are "
            f"{', '.join(self.sensor_topics())} (sensors) and "
            f"{', '.join(self.command_topics())} (commands)"
        )

    def _check_type(self, name: str, data_class: Any) -> str:
        type_name = getattr(data_class, "_type", None)
        if not (isinstance(data_class, type) and issubclass(data_class, Message)):
            raise ROSException(
                f"topic '{name}' needs a message class such as std_msgs.msg.Int32 as its type, "
                f"got {data_class!r}"
            )
        known = self._types.get(name)
        if known is not None and known != type_name:
            raise ROSException(f"topic '{name}' carries {known}, not {type_name}")
        return type_name

    def advertise(self, topic: str, data_class: Any) -> str:
        """Check that this node may publish `data_class` on `topic`; return the clean name."""
        # Hot path: the step API and many scripts publish the same topic every period.
        checked = self._advertise_checked.get((topic, data_class))
        if checked is not None:
            return checked
        name = normalize_topic(topic)
        robot = self._robot.get(name)
        if robot is not None and robot[1] == "publish":
            raise ROSException(
                f"'{name}' is published by the robot; command topics are "
                f"{', '.join(self.command_topics())}"
            )
        if name not in self._types and not self.info.allow_new_topics:
            raise self._unknown_topic(name)
        type_name = self._check_type(name, data_class)
        self._types[name] = type_name
        if name not in self._advertised:
            self._advertised.add(name)
            self._new_advertised.append(TopicDecl(name, type_name))
        if isinstance(topic, str):
            self._advertise_checked[(topic, data_class)] = name
        return name

    def subscribe(
        self, topic: str, data_class: Any, callback: Callable[..., Any] | None, args: Any = None
    ) -> Subscription:
        name = normalize_topic(topic)
        if name not in self._types:
            if not self.info.allow_new_topics:
                raise self._unknown_topic(name)
            self.warn(f"nothing is known to publish '{name}' yet; its callback may never run")
        elif (
            self._robot.get(name, ("", "publish"))[1] != "publish" and name not in self._advertised
        ):
            self.warn(f"'{name}' is a command topic the robot listens to; nothing publishes it")
        type_name = self._check_type(name, data_class)
        self._types[name] = type_name
        if name not in self._subscribed:
            self._subscribed.add(name)
            self._new_subscribed.append(TopicDecl(name, type_name))
        subscription = Subscription(name, data_class, callback, args)
        self._subscribers.setdefault(name, []).append(subscription)
        return subscription

    def unsubscribe(self, subscription: Subscription) -> None:
        handlers = self._subscribers.get(subscription.topic, [])
        if subscription in handlers:
            handlers.remove(subscription)

    def publish(self, topic: str, message: Message) -> None:
        """Queue `message` (already checked against the topic) for the next Yield."""
        if self.shutdown is not None:
            raise ROSException(f"publish() on '{topic}' after shutdown ({self.shutdown.reason})")
        try:
            data = message.serialize()
        except Exception as error:
            raise ROSSerializationException(f"publish() on '{topic}': {error}") from None
        self.outbox.append(Envelope(topic, message._type, data))

    def topic_class(self, topic: str) -> type[Message]:
        return get_message_class(self._types[topic])

    # ------------------------------------------------------------------ shutdown
    def on_shutdown(self, hook: Callable[[], Any]) -> None:
        self._hooks.append(hook)

    def signal_shutdown(self, reason: str, *, by_parent: bool = False) -> None:
        if self.shutdown is not None:
            return
        self.shutdown = _Shutdown(str(reason), by_parent)
        hooks, self._hooks = self._hooks, []
        for hook in hooks:
            self._run_student(hook)

    def _run_student(self, function: Callable[..., Any], *args: Any) -> None:
        """Call student code from inside a sleep; its exception ends the node."""
        self._callback_depth += 1
        try:
            function(*args)
        except Exception as error:
            self.failure = error
            raise NodeFailure(error) from None
        finally:
            self._callback_depth -= 1

    # ------------------------------------------------------------------ sleeping
    def take_outbox(self) -> list[Envelope]:
        sent, self.outbox = self.outbox, []
        return sent

    def wait_until(self, wake_at_ns: int | None) -> None:
        """One Yield and one frame from the parent: the node's only blocking point."""
        if self._callback_depth:
            raise ROSException(
                "sleeping inside a subscriber callback or shutdown hook would stall every "
                "other callback; keep callbacks short and sleep in the main loop"
            )
        if self.failure is not None:
            raise NodeFailure(self.failure)
        if self.shutdown is not None:
            raise ROSInterruptException(f"ROS shutdown request: {self.shutdown.reason}")
        sys.stdout.flush()
        sys.stderr.flush()
        frame = Yield(
            wake_at_s=None if wake_at_ns is None else wake_at_ns / 1e9,
            published=self.take_outbox(),
            advertised=self._new_advertised,
            subscribed=self._new_subscribed,
        )
        self._new_advertised, self._new_subscribed = [], []
        try:
            self.link.send(frame)
            reply = self.link.receive()
        except ProtocolError as error:
            raise LinkLost(error) from error
        if isinstance(reply, Shutdown):
            self.signal_shutdown(reply.reason, by_parent=True)
            raise ROSInterruptException(f"ROS shutdown request: {reply.reason}")
        if not isinstance(reply, Wake):
            raise LinkLost(ProtocolError(f"expected Wake or Shutdown, got {type(reply).__name__}"))
        self.clock.wake(reply.time_s)
        self._deliver(reply.deliveries)
        if self.shutdown is not None:  # a callback called signal_shutdown()
            raise ROSInterruptException(f"ROS shutdown request: {self.shutdown.reason}")

    def sleep_until(self, target_ns: int) -> None:
        """Sleep until the node's clock reaches `target_ns`, however often the parent wakes it."""
        while True:
            self.wait_until(target_ns)
            if self.clock.now_ns() >= target_ns - WAKE_TOLERANCE_NS:
                return

    def sleep_for(self, seconds: float) -> None:
        self.sleep_until(self.clock.now_ns() + max(0, round(seconds * 1e9)))

    def _deliver(self, deliveries: list[Envelope]) -> None:
        for envelope in deliveries:
            topic = envelope.topic  # the parent sends clean names
            self.latest[topic] = envelope
            decoded: dict[type, Message] = {}
            for subscription in list(self._subscribers.get(topic, ())):
                if self.shutdown is not None:
                    return
                if subscription.callback is None:
                    continue  # the step API reads `latest` instead
                data_class = subscription.data_class
                if data_class._type != envelope.type:
                    self.warn(
                        f"dropped a {envelope.type} on '{topic}': subscribed as {data_class._type}"
                    )
                    continue
                if data_class not in decoded:
                    decoded[data_class] = data_class.deserialize(envelope.data)
                self._run_student(subscription.invoke, decoded[data_class])

    # ------------------------------------------------------------------ logging
    def log(self, level_name: str, text: str) -> None:
        print(format_log_line(level_name, self.clock.now_ns() / 1e9, text), flush=True)

    def warn(self, text: str) -> None:
        self.log("WARN", text)


def format_log_line(level_name: str, time_s: float, text: str) -> str:
    """rospy's screen format: `[INFO] [12.300000]: text`."""
    return f"[{level_name}] [{time_s:.6f}]: {text}"


def normalize_topic(topic: Any) -> str:
    if not isinstance(topic, str) or not topic.strip("/"):
        raise ROSException(f"a topic name is a non-empty string such as 'Distance', got {topic!r}")
    return topic.lstrip("/")


def normalize_param(name: str) -> str:
    return str(name).lstrip("/~")


_current: NodeRuntime | None = None


def current() -> NodeRuntime:
    """The runtime of the node running in this process."""
    if _current is None:
        raise ROSInitException(
            "rospy works inside a RoboDojo node only: run this file as a controller"
        )
    return _current


def activate(runtime: NodeRuntime | None) -> None:
    global _current
    _current = runtime
