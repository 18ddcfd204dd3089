"""rclpy.executors: SingleThreadedExecutor and MultiThreadedExecutor on the node's one thread.

As rclpy/executors.py, where a student can observe it:
- spin_once(timeout_sec) runs at most one callback: tasks first, then per node its timers,
  subscriptions, clients and services; one pass over what was ready serves each entity once
  before any is served twice (rclpy's wait-set generator). timeout_sec None or negative
  blocks until there is work, 0 does not wait.
- spin() runs callbacks until the context is shut down; spin_until_future_complete() until the
  future is done, the timeout passes or the context is shut down.
- When the run ends the node (what SIGINT is to a ROS 2 process) the context shuts down and a
  SingleThreadedExecutor's spin raises ExternalShutdownException (here also a
  KeyboardInterrupt, sandbox.ros_errors.RunEndedInterrupt); a MultiThreadedExecutor's spin
  returns, as rclpy's swallows it.
- An exception in a callback comes out of spin, as in rclpy.

Where this differs from real threads: a MultiThreadedExecutor runs its callbacks one at a time
on the node's thread. While one blocks in Client.call(), spin_until_future_complete() or a
sleep (time.sleep, a Rate: _state.ProcessState._run_interleaved), the others run in between if
their callback group allows (a ReentrantCallbackGroup, or another group than the blocked
callback's), as rclpy's worker threads would run them. Under a SingleThreadedExecutor a
callback that sleeps lets time pass and no other callback run, as in rclpy.
An executor spun from a thread of the student's runs its callbacks on the node's thread at each
of the node's waits (rclpy/_state.py).
"""

from __future__ import annotations

import inspect
import os
import threading
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from sandbox.ros_errors import ExternalShutdownException, RunEndedInterrupt

from . import _state
from .context import Context
from .task import Future, Task
from .utilities import get_default_context

if TYPE_CHECKING:
    from .node import Node

__all__ = [
    "ConditionReachedException",
    "Executor",
    "ExternalShutdownException",
    "MultiThreadedExecutor",
    "ShutdownException",
    "SingleThreadedExecutor",
    "TimeoutException",
]


class TimeoutException(Exception):
    """Signal that a timeout occurred."""


class ShutdownException(Exception):
    """Signal that executor was shut down."""


class ConditionReachedException(Exception):
    """Future has been completed."""


_Work = tuple[Callable[[], Any], Any, Any]  # (call, entity, node)


class Executor:
    """Runs the callbacks of the nodes added to it."""

    _swallows_external_shutdown = False

    def __init__(self, *, context: Context | None = None) -> None:
        self._context = get_default_context() if context is None else context
        self._nodes: list[Node] = []
        self._tasks: list[Task[Any]] = []
        self._is_shutdown = False
        self._snapshot: list[tuple[Any, Any]] = []
        self._background_release: threading.Event | None = None
        self._context.on_shutdown(self.wake)

    @property
    def context(self) -> Context:
        return self._context

    def create_task(self, callback: Any, *args: Any, **kwargs: Any) -> Task[Any]:
        """Run `callback` (a function or a coroutine function) during spin; returns its Task."""
        task: Task[Any] = Task(callback, args, kwargs, executor=self)
        self._tasks.append(task)
        return task

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        self._is_shutdown = True
        for node in list(self._nodes):
            self.remove_node(node)
        self._release_background()
        return True

    def add_node(self, node: Node) -> bool:
        if node in self._nodes:
            return False
        self._nodes.append(node)
        node.executor = self
        _state.state().refresh_wake_topics()
        return True

    def remove_node(self, node: Node) -> None:
        if node in self._nodes:
            self._nodes.remove(node)
            if node._executor is self:
                node._executor = None
            # The node's entries stay in the pass: rclpy.spin_once(node) adds and removes the
            # node each call, and its next call serves what this pass had not served yet.
            _state.state().refresh_wake_topics()

    def wake(self) -> None:
        """The executor looks afresh at every wait; a spin "in another thread" ends once its
        context has shut down."""
        if not self._context.ok():
            self._release_background()

    def get_nodes(self) -> list[Node]:
        return list(self._nodes)

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.shutdown()

    # ------------------------------------------------------------------ spinning
    def spin(self) -> None:
        """Execute callbacks until the context is shut down."""
        if not _state.state().on_node_thread():
            self._spin_in_background()
            return
        while self._context.ok() and not self._is_shutdown:
            self.spin_once()

    def spin_once(self, timeout_sec: float | None = None) -> None:
        """Wait for and execute at most one callback."""
        self._spin_once_impl(timeout_sec)

    def spin_until_future_complete(
        self, future: Future[Any], timeout_sec: float | None = None
    ) -> None:
        """Execute callbacks until `future` is done, `timeout_sec` passes or the context ends."""
        if timeout_sec is None or timeout_sec < 0:
            while self._context.ok() and not future.done() and not self._is_shutdown:
                self._check_not_deadlocked(future)
                self._spin_once_impl(None, future.done)
            return
        end_ns = _state.now_ns() + int(timeout_sec * 1e9)
        while self._context.ok() and not future.done() and not self._is_shutdown:
            self._check_not_deadlocked(future)
            remaining_ns = end_ns - _state.now_ns()
            self._spin_once_impl(max(0, remaining_ns) / 1e9, future.done)
            if _state.now_ns() >= end_ns:
                return

    def spin_once_until_future_complete(
        self, future: Future[Any], timeout_sec: float | None = None
    ) -> None:
        self._spin_once_impl(timeout_sec, future.done)

    def _spin_once_impl(
        self, timeout_sec: float | None = None, condition: Callable[[], bool] = lambda: False
    ) -> None:
        if not _state.state().on_node_thread():
            raise RuntimeError(
                "spin_once() from a thread of your own: in RoboDojo only rclpy.spin(node) / "
                "executor.spin() may run in another thread; call spin_once in the main thread"
            )
        start_ns = _state.now_ns()
        deadline_ns = None
        if timeout_sec is not None and timeout_sec >= 0:
            deadline_ns = start_ns + int(timeout_sec * 1e9)
        polled = False
        while True:
            if self._is_shutdown:
                return
            if not self._context.ok():
                if self._swallows_external_shutdown:
                    return
                raise RunEndedInterrupt("the context was shut down while spinning")
            work = self._next_work()
            if work is not None:
                self._execute(work)
                # An executor that always has work (a timer of period 0) is a busy loop: past
                # the free polls its callbacks cost time, so a lockstep run moves on.
                self._poll()
                return
            if condition():
                return
            if deadline_ns is not None and _state.now_ns() >= deadline_ns:
                if deadline_ns == start_ns and not polled:
                    polled = True  # timeout 0: one look after the busy-loop poll
                    self._poll()
                    continue
                return
            self._wait(deadline_ns)

    def _poll(self) -> None:
        try:
            _state.poll()
        except RunEndedInterrupt:
            if not self._swallows_external_shutdown:
                raise

    def _wait(self, deadline_ns: int | None) -> None:
        due = self._next_due_ns()
        if due is not None:
            deadline_ns = due if deadline_ns is None else min(deadline_ns, due)
        try:
            _state.wait(deadline_ns, self._wake_topics())
        except RunEndedInterrupt:
            if not self._swallows_external_shutdown:
                raise

    # ------------------------------------------------------------------ work
    def _next_due_ns(self) -> int | None:
        due = [  # a timer whose group is busy (its callback sleeping) cannot run: no wake
            entity._due_ns()
            for node in self._nodes
            for entity in node._entities()
            if hasattr(entity, "_due_ns") and _group_allows(entity)
        ]
        due = [value for value in due if value is not None]
        return min(due) if due else None

    def _wake_topics(self) -> set[str]:
        topics: set[str] = set()
        for node in self._nodes:
            for entity in node._entities():
                wake_topics = getattr(entity, "_wake_topics", None)
                if wake_topics is not None:
                    topics |= wake_topics()
        return topics

    def _collect_ready(self) -> list[tuple[Any, Any]]:
        ready: list[tuple[Any, Any]] = [(task, None) for task in self._tasks if task.ready()]
        for node in self._nodes:
            for entity in node._entities():
                if entity._ready() and _group_allows(entity):
                    ready.append((entity, node))
        return ready

    def _next_work(self) -> _Work | None:
        """The next callback to run: rclpy serves what one wait found ready, each entity once,
        before it looks again."""
        self._tasks = [task for task in self._tasks if not task.done()]
        for attempt in range(2):
            if not self._snapshot:
                if attempt:
                    return None
                self._snapshot = self._collect_ready()
            while self._snapshot:
                entity, node = self._snapshot.pop(0)
                if isinstance(entity, Task):
                    if entity.ready():
                        return (entity, entity, None)
                    continue
                if node not in self._nodes:
                    continue  # dropped from the pass: the node left the executor
                if not entity._ready() or not _group_allows(entity):
                    continue
                call = entity._take()
                if call is not None:
                    return (call, entity, node)
        return None

    def _execute(self, work: _Work) -> None:
        call, entity, _ = work
        if isinstance(entity, Task):
            with _state.state().executing_callback(None, self):
                entity()
            if entity.done() and entity.exception() is not None:
                raise entity.exception()  # type: ignore[misc]
            return
        group = entity.callback_group
        group.beginning_execution(entity)
        try:
            with _state.state().executing_callback(group, self):
                result = call()
            if inspect.iscoroutine(result):  # an `async def` callback: a task of its own
                task: Task[Any] = Task(result, executor=self)
                self._tasks.append(task)
                with _state.state().executing_callback(group, self):
                    task()
                if task.done() and task.exception() is not None:
                    raise task.exception()  # type: ignore[misc]
        finally:
            group.ending_execution(entity)

    def _check_not_deadlocked(self, future: Future[Any]) -> None:
        """Waiting inside a callback for a future only a blocked callback group could complete
        would hang rclpy for ever; say so instead."""
        current = _state.state()
        if not current.executing:
            return
        client = getattr(future, "_client", None)
        if client is not None and not _group_allows(client):
            raise RuntimeError(
                "waiting inside a callback for a service response that can only arrive through "
                "the same callback group would block for ever in ROS 2 (the response callback "
                "cannot run while this one does): create the client with callback_group="
                "ReentrantCallbackGroup() (or another group) and spin a MultiThreadedExecutor, "
                "or use call_async() with future.add_done_callback() instead of waiting"
            )

    # ------------------------------------------------------------------ spun from a thread
    def _spin_in_background(self) -> None:
        """spin() from a thread of the student's: the node's thread runs our callbacks at its
        waits; this thread waits until the context shuts down or the executor is shut down."""
        current = _state.state()
        release = threading.Event()
        self._background_release = release
        _state.note_spin_thread(threading.current_thread())
        current.background.append(self)
        current.refresh_wake_topics()
        try:
            while self._context.ok() and not self._is_shutdown:
                release.wait(0.5)  # [s] wall time; the release comes with shutdown
        finally:
            if self in current.background:
                current.background.remove(self)
            current.refresh_wake_topics()

    def _release_background(self) -> None:
        if self._background_release is not None:
            self._background_release.set()

    def _run_ready_in_background(self) -> None:
        """At a wake of the node's thread: run what was ready (one pass)."""
        if not self._context.ok() or self._is_shutdown:
            self._release_background()
            return
        self._run_ready_pass()

    def _run_ready_pass(self) -> None:
        """Run each callback that is ready now and whose group allows it, once; an exception
        ends the node (it has no caller of the student's to go to)."""
        if not self._context.ok() or self._is_shutdown:
            return
        self._snapshot = self._collect_ready()
        while self._snapshot:
            work = self._next_work()
            if work is None:
                break
            try:
                self._execute(work)
            except RunEndedInterrupt:
                raise
            except Exception as error:
                raise _state.fail(error) from None


def _group_allows(entity: Any) -> bool:
    group = getattr(entity, "callback_group", None)
    return group is None or group.can_execute(entity)


class SingleThreadedExecutor(Executor):
    """Runs callbacks in the thread that calls spin()."""


class MultiThreadedExecutor(Executor):
    """Runs callbacks "in a pool of threads": here one at a time on the node's thread, with
    blocked callbacks letting the others in (module docstring)."""

    _swallows_external_shutdown = True

    def __init__(self, num_threads: int | None = None, *, context: Context | None = None) -> None:
        super().__init__(context=context)
        if num_threads is None:  # rclpy: the CPUs this process may use
            num_threads = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 2
            num_threads = max(num_threads, 2)
        if num_threads == 1:
            warnings.warn(
                "MultiThreadedExecutor is used with a single thread.\n"
                "Use the SingleThreadedExecutor instead.",
                stacklevel=2,
            )
        self._num_threads = num_threads
