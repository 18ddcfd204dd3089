"""The node's side of the topic graph: its topic table, outbox, subscribers and sleeps.

One `NodeRuntime` exists per node, created by the host (sandbox/host.py) after `Load`. The rospy
shim (sandbox/ros_compat/rospy) and the step API (sandbox/step_api.py) are thin layers over it,
and all state lives here, so the shim holds none of its own.

A sleep is the only place the node talks to the parent: `wait_until()` sends a `Yield` with what
was published since the last one, blocks for the next frame, and on `Wake` sets the clock, runs
subscriber callbacks in delivery order and then the timers that fell due (rospy runs both on
threads of their own; here they run inside the node's waits); on `Shutdown` it runs the
on_shutdown hooks and raises `ROSInterruptException`.

A node that never sleeps still sees time pass and callbacks run, as on a real robot: the
functions such a loop spins on call `poll()`, which yields now and then (sandbox/busy_loop.py).
"""

from __future__ import annotations

import contextlib
import sys
import threading
import traceback
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

from sandbox.busy_loop import BusyLoopModel
from sandbox.msgs import Message, get_message_class
from sandbox.names import InvalidName, Names
from sandbox.outbox import Outbox
from sandbox.protocol import (
    Drawing,
    Envelope,
    Finishing,
    GraphTopic,
    LibraryLoading,
    NodeInfo,
    ProtocolError,
    Shutdown,
    Wake,
    Yield,
)
from sandbox.ros2_names import BusNames
from sandbox.ros_errors import (
    ROSException,
    ROSInitException,
    ROSInterruptException,
    ROSSerializationException,
)
from sandbox.services import NodeServices
from sandbox.timers import TimerSchedule
from sandbox.topic_table import ANY_TYPE, TopicTable
from sandbox.vclock import NodeClock

WAKE_TOLERANCE_NS = 1_000  # [ns] a wake this close to the target counts as on time (float s)


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
    queue_size: int | None = None  # [messages] a callback sees at most the newest this many

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
    filename: str = ""  # the student's file, as tracebacks name it
    node_name: str | None = None  # "/name" once init_node() ran (or the step API started)
    implicit_name: bool = False  # named by the step API; init_node() may rename it
    log_level: int = 2  # rospy.INFO
    latest: dict[str, Envelope] = field(default_factory=dict)
    failure: BaseException | None = None
    log_sites: dict[tuple[Any, ...], int] = field(default_factory=dict)  # throttle/once state
    shutdown: _Shutdown | None = None
    _subscribers: dict[str, list[Subscription]] = field(default_factory=dict)
    _hooks: list[Callable[[], Any]] = field(default_factory=list)
    _callback_depth: int = 0
    _in_hooks: bool = False
    outbox: Outbox = field(default_factory=Outbox)  # what leaves at the next yield
    graph: list[GraphTopic] | None = None  # the run's topics, as of the last wake that sent it
    timers: TimerSchedule = field(default_factory=TimerSchedule)
    services: NodeServices = field(default_factory=NodeServices)
    wake_topics: set[str] = field(default_factory=set)  # always wake early (service requests)
    names: Names | None = None  # ROS name resolution for this node (sandbox.names)
    topics: TopicTable = field(init=False)
    _drawing_noted: bool = False
    _libraries_loading: int = 0  # deferred modules loading now, one inside another's load
    _waiting: bool = False
    _main_thread: int = field(default_factory=threading.get_ident)
    busy: BusyLoopModel = field(init=False)
    # Run after each wake's deliveries and timers, outside callbacks: rclpy runs the
    # callbacks of executors spinning "in another thread" here (sandbox/ros_compat2/rclpy).
    after_wake: list[Callable[[], None]] = field(default_factory=list)
    delivering: Envelope | None = None  # the envelope whose callbacks run now
    # More times the node must wake at (rclpy's timers of those executors), besides its own.
    due_hooks: list[Callable[[], int | None]] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.names is None and self.info.ros_version == 2:
            self.names = BusNames()  # rclpy resolves names itself (sandbox.ros2_names)
        if self.names is None:
            try:
                self.names = Names.from_info(self.info)
            except InvalidName as error:  # a bad remap or __ns on the node's command line
                self.failure = ROSInitException(f"this node's command line or launch file: {error}")
                self.names = Names(run_name=self.info.node_name)
        self.topics = TopicTable(self.info, self.names, self.warn)
        self.busy = BusyLoopModel(self.clock)

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

    # The run's topic names and types this node knows (sandbox.topic_table).
    def advertise(
        self, topic: str, data_class: Any, latch: bool = False, best_effort: bool = False
    ) -> str:
        """Check that this node may publish `data_class` on `topic`; return the bus name."""
        return self.topics.advertise(topic, data_class, latch, best_effort)

    def bus_name(self, topic: Any) -> str:
        return self.topics.bus_name(topic)

    def robot_direction(self, topic: str) -> str | None:
        return self.topics.robot_direction(topic)

    def sensor_topics(self) -> list[str]:
        return self.topics.sensor_topics()

    def command_topics(self) -> list[str]:
        return self.topics.command_topics()

    def unknown_topic(self, name: str) -> ROSException:
        return self.topics.unknown_topic(name)

    def subscribe(
        self,
        topic: str,
        data_class: Any,
        callback: Callable[..., Any] | None,
        args: Any = None,
        queue_size: int | None = None,
        **qos: bool,
    ) -> Subscription:
        """`qos`: a ROS 2 subscription's best_effort, transient_local, volatile."""
        name = self.topics.subscribe(topic, data_class, **qos)
        subscription = Subscription(name, data_class, callback, args, queue_size)
        self._subscribers.setdefault(name, []).append(subscription)
        return subscription

    def unsubscribe(self, subscription: Subscription) -> None:
        handlers = self._subscribers.get(subscription.topic, [])
        if subscription in handlers:
            handlers.remove(subscription)
        if not handlers and subscription.topic in self._subscribers:
            # Nothing here listens any more: the parent stops queueing the topic for us.
            self.topics.unsubscribe(subscription.topic)
            self._subscribers.pop(subscription.topic, None)

    def publish(self, topic: str, message: Message, queue_size: int | None = None) -> None:
        """Queue `message` (already checked against the topic) for the next Yield, keeping at
        most `queue_size` of this topic's messages (None or 0: all of them)."""
        if self.shutdown is not None and not self._in_hooks:
            raise ROSException(f"publish() on '{topic}' after shutdown ({self.shutdown.reason})")
        try:
            data = message.serialize()
        except Exception as error:
            raise ROSSerializationException(f"publish() on '{topic}': {error}") from None
        self.outbox.add(Envelope(topic, message._type, data), queue_size)
        self.poll()

    def topic_class(self, topic: str) -> type[Message]:
        return get_message_class(self.topics.types[topic])

    def topic_type(self, topic: str) -> str | None:
        return self.topics.types.get(topic)

    def current_graph(self) -> list[GraphTopic]:
        """The run's topic graph; before the first wake the node has none yet, so it asks for
        it with a zero-length wait (the parent sends it with that wake)."""
        if self.graph is None:
            self.wait_until(self.clock.now_ns())
        return self.graph or []

    # ------------------------------------------------------------------ busy loops
    def poll(self) -> None:
        """One call of a function a busy loop spins on (module docstring): past the free
        polls it costs time, and now and then the node yields as if it slept."""
        if self._callback_depth or self.shutdown is not None:
            return
        if self._waiting:
            return  # a clock read inside our own wait (the link, logging) is not the student's
        if threading.get_ident() != self._main_thread:
            return  # only the node's own thread may talk to the parent
        if not self.busy.count():
            return
        # The run may end meanwhile: is_shutdown() says so from now on.
        with contextlib.suppress(ROSInterruptException):
            self.wait_until(self.clock.now_ns())

    @contextlib.contextmanager
    def library_loading(self) -> Iterator[None]:
        """The student's code has just used a library whose import was deferred (sandbox/host.py)
        and it loads now: the parent stops the step's clock meanwhile (protocol.LibraryLoading),
        as the load is the library's cost, paid once, not the controller's."""
        if threading.get_ident() != self._main_thread or self._libraries_loading:
            yield  # only the main thread's wake has a clock, stopped once for nested loads
            return
        self._libraries_loading += 1
        self._send_frame(LibraryLoading(done=False))
        try:
            yield
        finally:
            self._libraries_loading -= 1
            self._send_frame(LibraryLoading(done=True))

    def _send_frame(self, frame: object) -> None:
        try:
            self.link.send(frame)
        except ProtocolError as error:
            raise LinkLost(error) from error

    def note_drawing(self) -> None:
        """The student's code is saving a figure (or, in a node started cold, importing a heavy
        library: sandbox/host.py): tell the parent once per wake, so the step gets the end
        budget (a 2400x1200 PNG, or `import matplotlib.pyplot` on a loaded machine, can take
        longer than a control step may)."""
        if self._drawing_noted or threading.get_ident() != self._main_thread:
            return
        self._drawing_noted = True
        self._send_frame(Drawing())

    # ------------------------------------------------------------------ shutdown
    def on_shutdown(self, hook: Callable[[], Any]) -> None:
        self._hooks.append(hook)

    def signal_shutdown(self, reason: str, *, by_parent: bool = False) -> None:
        """Shut the node down: hooks run first and may still publish (the usual zero Twist), as
        rospy's on_shutdown hooks run before its topics close; an error in a hook is logged and
        the next hook runs. Unless the parent asked, the parent is told the node is finishing,
        so what it does next (figures, files) gets the end budget, not the step budget."""
        if self.shutdown is not None:
            return
        self.shutdown = _Shutdown(str(reason), by_parent)
        hooks, self._hooks = self._hooks, []
        self._in_hooks = True
        try:
            for hook in hooks:
                self._run_hook(hook)
        finally:
            self._in_hooks = False
        self.timers.clear()
        if not by_parent:
            try:
                self.link.send(Finishing(reason=self.shutdown.reason, published=self.take_outbox()))
            except ProtocolError as error:
                raise LinkLost(error) from error

    def _run_hook(self, hook: Callable[[], Any]) -> None:
        self._callback_depth += 1
        try:
            hook()
        except Exception as error:
            self.log("ERROR", f"error in shutdown hook {_callable_name(hook)}: {error!r}")
            print(_student_traceback(error, self.filename), file=sys.stderr, end="", flush=True)
        finally:
            self._callback_depth -= 1

    def _run_student(self, function: Callable[..., Any], *args: Any) -> None:
        """Call student code from inside a sleep; its exception ends the node."""
        self.outbox.new_burst()
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
        return self.outbox.take()

    def _effective_wake(
        self, wake_at_ns: int | None, wake_on: list[str] | None
    ) -> tuple[int | None, list[str] | None]:
        """What to ask the parent for, with timers and services counted in."""
        timer_ns = self.timers.next_due_ns()
        for hook in self.due_hooks:
            due_ns = hook()
            if due_ns is not None:
                timer_ns = due_ns if timer_ns is None else min(timer_ns, due_ns)
        if wake_at_ns is None and wake_on is None:  # spinning: any message wakes the node
            if timer_ns is None:
                return None, None
            return timer_ns, sorted(self.topics.subscribed)
        topics = set(wake_on or ()) | self.wake_topics
        if timer_ns is not None:
            wake_at_ns = timer_ns if wake_at_ns is None else min(wake_at_ns, timer_ns)
        return wake_at_ns, sorted(topics) if topics else None

    def wait_until(self, wake_at_ns: int | None, wake_on: list[str] | None = None) -> None:
        """One Yield and one frame from the parent: the node's only blocking point.

        Wakes at `wake_at_ns`, or earlier when a message arrives on a topic of `wake_on`; both
        None: when any message arrives (spin). Timers and service requests wake it too."""
        if self._callback_depth:
            raise ROSException(
                "sleeping inside a subscriber callback, timer, service handler or shutdown hook "
                "would stall every other callback; keep callbacks short and sleep in the main "
                "loop"
            )
        if self.failure is not None:
            raise NodeFailure(self.failure)
        if self.shutdown is not None:
            raise ROSInterruptException(f"ROS shutdown request: {self.shutdown.reason}")
        sys.stdout.flush()
        sys.stderr.flush()
        wake_at_ns, wake_on = self._effective_wake(wake_at_ns, wake_on)
        advertised, subscribed, unsubscribed = self.topics.take_declarations()
        frame = Yield(
            wake_at_s=None if wake_at_ns is None else wake_at_ns / 1e9,
            published=self.take_outbox(),
            advertised=advertised,
            subscribed=subscribed,
            wake_on=wake_on,
            unsubscribed=unsubscribed,
        )
        self._waiting = True
        try:
            self.link.send(frame)
            reply = self.link.receive()
        except ProtocolError as error:
            raise LinkLost(error) from error
        finally:
            self._waiting = False
        if isinstance(reply, Shutdown):
            self.signal_shutdown(reply.reason, by_parent=True)
            raise ROSInterruptException(f"ROS shutdown request: {reply.reason}")
        if not isinstance(reply, Wake):
            raise LinkLost(ProtocolError(f"expected Wake or Shutdown, got {type(reply).__name__}"))
        self.clock.wake(reply.time_s)
        self.busy.woke()
        self._drawing_noted = False
        if reply.graph is not None:
            self.graph = reply.graph
        self._deliver(reply.deliveries)
        if self.shutdown is None:
            for timer in self.timers.take_due(self.clock.now_ns()):
                if not timer.stopped:  # an earlier callback may have stopped it
                    self._run_student(timer.fire, self.clock.now_ns())
                if self.shutdown is not None:
                    break
        if self.shutdown is None:
            for hook in list(self.after_wake):
                hook()
        self.outbox.new_burst()  # back in the main loop
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
        counts: dict[str, int] = {}
        for envelope in deliveries:
            counts[envelope.topic] = counts.get(envelope.topic, 0) + 1
        seen: dict[str, int] = {}
        for envelope in deliveries:
            topic = envelope.topic  # the parent sends clean names
            self.latest[topic] = envelope
            seen[topic] = index = seen.get(topic, 0) + 1
            newer = counts[topic] - index  # messages of this topic still to come in this wake
            decoded: dict[type, Message] = {}
            self.delivering = envelope  # rclpy's subscriptions read its QoS marks
            for subscription in list(self._subscribers.get(topic, ())):
                if self.shutdown is not None:
                    return
                if subscription.callback is None:
                    continue  # the step API reads `latest` instead
                if subscription.queue_size and newer >= subscription.queue_size:
                    continue  # rospy's subscriber queue: only the newest queue_size wait
                data_class = subscription.data_class
                if data_class._type == ANY_TYPE:  # rospy.AnyMsg: the bytes, undecoded
                    message = data_class.from_envelope(envelope.data, envelope.type)
                    self._run_student(subscription.invoke, message)
                    continue
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
        if self.info.ros_version == 2:  # as rclpy prints: [WARN] [1.500000000] [node]: text
            seconds, nanoseconds = divmod(self.clock.now_ns(), 1_000_000_000)
            name = (self.node_name or self.info.node_name).strip("/").replace("/", ".")
            line = f"[{level_name}] [{seconds}.{nanoseconds:09d}] [{name}]: {text}"
            print(line, flush=True)
            return
        print(format_log_line(level_name, self.clock.now_ns() / 1e9, text), flush=True)

    def warn(self, text: str) -> None:
        self.log("WARN", text)


def _callable_name(function: Any) -> str:
    return getattr(function, "__qualname__", None) or repr(function)


def _student_traceback(error: BaseException, filename: str) -> str:
    """The traceback of an error in student code, cut to the student's frames."""
    from sandbox.student_errors import from_exception

    try:
        return from_exception(error, filename).traceback
    except Exception:
        return "".join(traceback.format_exception(error))


def format_log_line(level_name: str, time_s: float, text: str) -> str:
    """rospy's screen format: `[INFO] [12.300000]: text`."""
    return f"[{level_name}] [{time_s:.6f}]: {text}"


_current: NodeRuntime | None = None


def current() -> NodeRuntime:
    """The runtime of the node running in this process."""
    if _current is None:
        raise ROSInitException(
            "rospy works inside a RoboDojo node only: run this file as a controller"
        )
    return _current


def active() -> NodeRuntime | None:
    """The runtime of the node running in this process, None between nodes."""
    return _current


def activate(runtime: NodeRuntime | None) -> None:
    global _current
    _current = runtime
