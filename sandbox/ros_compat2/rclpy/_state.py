"""What rclpy keeps for the node process, and its one way to wait: the NodeRuntime's.

A RoboDojo node has one thread that talks to the run (sandbox.runtime.NodeRuntime.wait_until).
rclpy's executors, rates and clients wait through `wait()` here. State lives on the runtime
(`runtime.rclpy_state`), not in module globals, so every node started in a process starts
afresh (the tests run many nodes in one interpreter).

Executors spun from a thread of the student's own (`threading.Thread(target=rclpy.spin,
args=(node,))`, the usual way to make Rate.sleep() or Client.call() work in ROS 2) do not run
there: that thread only waits until the context shuts down, and the executor's callbacks run on
the node's thread at every wake (NodeRuntime.after_wake), as a real spin thread would run them
between the main loop's statements. Their subscriptions and timers wake the node early, so a
main loop that sleeps for seconds still sees each message as it arrives.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from sandbox import runtime as sandbox_runtime
from sandbox.ros_errors import ROSInitException, ROSInterruptException, RunEndedInterrupt
from sandbox.runtime import NodeFailure, NodeRuntime

if TYPE_CHECKING:
    from .callback_groups import CallbackGroup
    from .context import Context
    from .executors import Executor
    from .node import Node


class ProcessState:
    """rclpy's state for the node process (one per NodeRuntime)."""

    def __init__(self, node_runtime: NodeRuntime) -> None:
        self.runtime = node_runtime
        self.default_context: Context | None = None
        self.contexts: list[Context] = []
        self.global_executor: Executor | None = None
        self.nodes: list[Node] = []
        self.background: list[Executor] = []  # spun from a thread of the student's
        self.spin_threads: set[threading.Thread] = set()
        # (group, executor) of each callback running now, innermost last
        self.executing: list[tuple[CallbackGroup | None, Executor | None]] = []
        self.logger_levels: dict[str, int] = {}
        self.warned: set[str] = set()  # one-time notes already printed
        self.run_ended = False  # the run ended the node (Shutdown from the parent)
        self._running_background = False
        self.main_thread = node_runtime._main_thread
        node_runtime.after_wake.append(self._check_graph_qos)
        node_runtime.after_wake.append(self._run_background)
        node_runtime.after_wake.append(self._run_interleaved)
        self._graph_seen: object = None
        node_runtime.due_hooks.append(self._background_due_ns)
        node_runtime.on_shutdown(self._on_runtime_shutdown)

    # ------------------------------------------------------------------ background spins
    def _interleaving(self) -> list[Executor]:
        """MultiThreadedExecutors with a callback running now: their other callbacks may run
        while it sleeps (_run_interleaved), so their timers and topics wake the node."""
        found: list[Executor] = []
        for _, executor in self.executing:
            if getattr(executor, "_num_threads", 1) >= 2 and executor not in found:
                found.append(executor)  # type: ignore[arg-type]
        return found

    def _background_due_ns(self) -> int | None:
        due = [executor._next_due_ns() for executor in (*self.background, *self._interleaving())]
        due = [value for value in due if value is not None]
        return min(due) if due else None

    def refresh_wake_topics(self) -> None:
        """The runtime wakes early for every topic a background executor's entities read."""
        wanted: set[str] = set()
        for executor in (*self.background, *self._interleaving()):
            wanted |= executor._wake_topics()
        previous: set[str] = getattr(self, "_background_topics", set())
        self.runtime.wake_topics -= previous - wanted
        self.runtime.wake_topics |= wanted
        self._background_topics = wanted

    def _run_background(self) -> None:
        """After a wake: run what the executors spinning "in another thread" have ready."""
        if self._running_background or self.executing or not self.background:
            return
        self._running_background = True
        try:
            for executor in list(self.background):
                executor._run_ready_in_background()
        finally:
            self._running_background = False

    def _check_graph_qos(self) -> None:
        """A new graph: subscriptions warn of incompatible publishers in other nodes."""
        graph = self.runtime.graph
        if graph is None or graph is self._graph_seen:
            return
        self._graph_seen = graph
        by_name = {topic.name: topic for topic in graph}
        own_label = self.runtime.info.node_name
        for node in self.nodes:
            for subscription in node._subscriptions:
                topic = by_name.get(subscription._bus_topic)
                if topic is not None:
                    subscription._check_graph(topic, own_label)

    def _run_interleaved(self) -> None:
        """A callback of a MultiThreadedExecutor is sleeping (time.sleep, a rate, a clock): at
        each wake meanwhile, the executor's other ready callbacks run where their callback
        groups allow, as rclpy's other worker threads would run them (at most as many at once
        as the executor has threads)."""
        if not self.executing:
            return
        _, executor = self.executing[-1]
        threads = getattr(executor, "_num_threads", 1)
        if executor is None or threads < 2:
            return
        if sum(1 for _, running in self.executing if running is executor) >= threads:
            return
        executor._run_ready_pass()

    def _on_runtime_shutdown(self) -> None:
        for context in list(self.contexts):
            context._ended_by_run()
        for executor in list(self.background):
            executor._release_background()

    # ------------------------------------------------------------------ this process's graph
    def _publishers(self, bus_topic: str) -> list[Any]:
        return [p for node in self.nodes for p in node._publishers if p._bus_topic == bus_topic]

    def _subscriptions(self, bus_topic: str) -> list[Any]:
        return [s for node in self.nodes for s in node._subscriptions if s._bus_topic == bus_topic]

    def local_count(self, bus_topic: str, *, subscribers: bool) -> int:
        if subscribers:
            return len(self._subscriptions(bus_topic))
        return len(self._publishers(bus_topic))

    def local_topics(self) -> list[tuple[str, str]]:
        found = []
        for node in self.nodes:
            for entity in (*node._publishers, *node._subscriptions):
                found.append((entity._bus_topic, entity.msg_type._type))
        return found

    def local_services(self) -> list[Any]:
        return [service for node in self.nodes for service in node._services]

    def deliver_locally(self, publisher: Any, message: Any) -> None:
        """A message published in this process reaches this process's subscriptions (the
        run's bus never sends a node's own messages back to it), each with its own copy."""
        for subscription in self._subscriptions(publisher._bus_topic):
            if subscription.msg_type._type != message._type:
                continue
            if self._incompatible(publisher, subscription) is not None:
                continue
            subscription._put(type(message).deserialize(message.serialize()))

    def _incompatible(self, publisher: Any, subscription: Any) -> int | None:
        from .qos import incompatible_policy

        return incompatible_policy(
            publisher.reliability, publisher.durability, subscription.qos_profile
        )

    def check_local_qos(self, publisher: Any = None, subscription: Any = None) -> None:
        """A new endpoint meets this process's others on its topic: incompatible QoS is
        logged on both sides, as rmw's events make rclpy log it; a TRANSIENT_LOCAL
        subscription gets the last message of each TRANSIENT_LOCAL publisher."""
        if publisher is not None:
            pairs = [(publisher, s) for s in self._subscriptions(publisher._bus_topic)]
        else:
            pairs = [(p, subscription) for p in self._publishers(subscription._bus_topic)]
        for pub, sub in pairs:
            kind = self._incompatible(pub, sub)
            if kind is not None:
                pub._incompatible_qos.report(kind)
                sub._warn_incompatible(pub._node.get_fully_qualified_name(), kind)
            elif subscription is not None and pub._last is not None and sub.transient_local:
                sub._put(type(pub._last).deserialize(pub._last.serialize()))

    # ------------------------------------------------------------------ callbacks
    @contextmanager
    def executing_callback(
        self, group: CallbackGroup | None, executor: Executor | None = None
    ) -> Iterator[None]:
        self.executing.append((group, executor))
        interleaving = getattr(executor, "_num_threads", 1) >= 2
        if interleaving:
            self.refresh_wake_topics()
        try:
            yield
        finally:
            self.executing.pop()
            if interleaving:
                self.refresh_wake_topics()

    def on_node_thread(self) -> bool:
        return threading.get_ident() == self.main_thread

    def warn_once(self, key: str, text: str) -> None:
        if key not in self.warned:
            self.warned.add(key)
            self.runtime.warn(text)


_original_join = threading.Thread.join


def _join(thread: threading.Thread, timeout: float | None = None) -> None:
    """Thread.join on a spin thread, from the node's thread: that thread only waits for the
    context to shut down while its callbacks run on the node's thread, so joining it means
    waiting here, letting the run's time pass and those callbacks run (in ROS 2 the spin
    thread would run them while the main thread waits in join)."""
    node_runtime = sandbox_runtime._current
    current = getattr(node_runtime, "rclpy_state", None)
    if (
        current is None
        or thread not in current.spin_threads
        or not current.on_node_thread()
        or node_runtime.shutdown is not None
    ):
        _original_join(thread, timeout)
        return
    deadline_ns = None if timeout is None else now_ns() + int(timeout * 1e9)
    try:
        while thread.is_alive() and current.background:
            if deadline_ns is not None and now_ns() >= deadline_ns:
                return
            wait(deadline_ns, None)
    except RunEndedInterrupt:
        pass
    _original_join(thread, 1.0)  # it ends within its next look at the context


def note_spin_thread(thread: threading.Thread) -> None:
    """A thread of the student's spins an executor (install the join above once)."""
    state().spin_threads.add(thread)
    if threading.Thread.join is not _join:
        threading.Thread.join = _join  # type: ignore[method-assign]


def state() -> ProcessState:
    """rclpy's state for this node process."""
    try:
        node_runtime = sandbox_runtime.current()
    except ROSInitException:
        raise RuntimeError(
            "rclpy works inside a RoboDojo node only: run this file as a controller"
        ) from None
    found = getattr(node_runtime, "rclpy_state", None)
    if found is None:
        found = ProcessState(node_runtime)
        node_runtime.rclpy_state = found  # type: ignore[attr-defined]
    return found


def runtime() -> NodeRuntime:
    return state().runtime


def now_ns() -> int:
    """The run's time [ns] (the node's clock: virtual in lockstep, the wall in realtime)."""
    return sandbox_runtime.current().clock.now_ns()


def wait(deadline_ns: int | None, topics: set[str] | None) -> None:
    """Sleep until `deadline_ns` (None: no deadline) or until a message arrives on one of
    `topics` (None or empty with no deadline: any message). When the run ends the node, its
    contexts shut down and RunEndedInterrupt is raised (rclpy.executors.
    ExternalShutdownException, also a KeyboardInterrupt)."""
    current = state()
    node_runtime = current.runtime
    if not current.on_node_thread():
        raise RuntimeError("only the node's main thread may wait here")
    try:
        node_runtime.wait_until(deadline_ns, sorted(topics) if topics else None)
    except ROSInterruptException:
        ended_by_run(current)
        raise RunEndedInterrupt("the run ended this node") from None


def ended_by_run(current: ProcessState) -> None:
    if current.runtime.shutdown is not None and current.runtime.shutdown.by_parent:
        current.run_ended = True


def poll() -> None:
    """One poll of a loop that does not sleep (spin_once with timeout 0): past the free polls
    it costs simulated time and now and then yields (sandbox/busy_loop.py)."""
    node_runtime = runtime()
    node_runtime.poll()
    if node_runtime.shutdown is not None and node_runtime.shutdown.by_parent:
        ended_by_run(state())


def fail(error: BaseException) -> NodeFailure:
    """An exception from student code run where it cannot propagate to the student's own
    frames (a background spin's callback): it ends the node, as an uncaught exception in a
    real spin thread ends what that thread was doing."""
    sandbox_runtime.current().failure = error
    return NodeFailure(error)
