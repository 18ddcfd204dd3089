"""rclpy.client.Client (rclpy/client.py) over the run's service topics (service.py).

call_async(request) sends the request and returns a Future; the response completes it when an
executor spins the client's node (rclpy's order). call(request) waits on the node's thread: it
works from the main loop and, with a MultiThreadedExecutor, from a callback whose group lets the
client's callbacks in; from a callback where rclpy would deadlock (a SingleThreadedExecutor, or
the client in the blocked callback's own MutuallyExclusive group) it raises RuntimeError with a
sentence instead of hanging. wait_for_service(timeout_sec) looks at the run's graph every
0.25 s of run time, as rclpy's sleeps do; a call whose server leaves the run before answering
fails with RuntimeError instead of waiting for ever.
"""

from __future__ import annotations

import itertools
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from sandbox.ros_errors import RunEndedInterrupt
from sandbox.services import REPLY_PREFIX, request_topic

from . import _state
from .exceptions import InvalidHandle
from .service import service_type_name, wrapper_classes
from .task import Future

if TYPE_CHECKING:
    from .callback_groups import CallbackGroup
    from .node import Node

AVAILABILITY_POLL_S = 0.25  # [s] rclpy's wait_for_service sleeps this long between looks
SERVER_CHECK_NS = 1_000_000_000  # [ns] call(): how often to look whether the server is gone


class _Router:
    """The process's reply topic and the calls waiting on it (one per node process)."""

    def __init__(self) -> None:
        self.ids = itertools.count(1)
        self.pending: dict[int, Client] = {}
        node_runtime = _state.runtime()
        self.reply_to = REPLY_PREFIX + node_runtime.info.node_name.strip("/")
        _, reply_class = wrapper_classes()
        node_runtime.subscribe(self.reply_to, reply_class, self._arrived)

    def _arrived(self, reply: Any) -> None:
        client = self.pending.pop(reply.id, None)
        if client is not None:
            client._replies.append((reply.id, reply))


def _router() -> _Router:
    current = _state.state()
    router = getattr(current, "service_router", None)
    if router is None:
        router = _Router()
        current.service_router = router  # type: ignore[attr-defined]
    return router


class Client:
    """Calls one service (made by Node.create_client)."""

    def __init__(
        self,
        node: Node,
        srv_type: Any,
        srv_name: str,
        bus_name: str,
        callback_group: CallbackGroup,
    ) -> None:
        self._type_name = service_type_name(srv_type)
        self.srv_type = srv_type
        self.srv_name = "/" + bus_name
        self.callback_group = callback_group
        self.context = node.context
        self._node = node
        self._bus_name = bus_name
        self._topic = request_topic(bus_name)
        self._pending_requests: dict[int, Future[Any]] = {}
        self._replies: deque[tuple[int, Any]] = deque()
        self._destroyed = False
        self._router = _router()

    @property
    def handle(self) -> Client:
        if self._destroyed:
            raise InvalidHandle("the client was destroyed")
        return self

    @property
    def service_name(self) -> str:
        return self.srv_name

    def destroy(self) -> None:
        self._destroyed = True
        self._replies.clear()

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._node.destroy_client(self)

    # ------------------------------------------------------------------ calls
    def _local_service(self) -> Any:
        for service in _state.state().local_services():
            if service._bus_name == self._bus_name and not service._destroyed:
                return service
        return None

    def call_async(self, request: Any) -> Future[Any]:
        """Send `request`; the returned Future completes with the response."""
        if not isinstance(request, self.srv_type.Request):
            raise TypeError(
                f"call_async() takes a {self._type_name} request ({self._type_name}.Request()), "
                f"got {type(request).__name__}"
            )
        if self._destroyed:
            raise InvalidHandle("call_async() on a client that was destroyed")
        call_id = next(self._router.ids)
        future: Future[Any] = Future()
        future._client = self  # type: ignore[attr-defined]  # executors check deadlocks by it
        self._pending_requests[call_id] = future
        future.add_done_callback(self.remove_pending_request)
        local = self._local_service()
        if local is not None:
            local._put_local(
                request,
                lambda response: self._replies.append(
                    (call_id, type(response).deserialize(response.serialize()))
                ),
            )
            return future
        call_class, _ = wrapper_classes()
        node_runtime = _state.runtime()
        self._router.pending[call_id] = self
        node_runtime.advertise(self._topic, call_class)
        node_runtime.publish(
            self._topic,
            call_class(
                service=self._bus_name,
                reply_to=self._router.reply_to,
                id=call_id,
                request=request.serialize(),
            ),
        )
        return future

    def call(self, request: Any, timeout_sec: float | None = None) -> Any:
        """Send `request` and wait for the response (TimeoutError after `timeout_sec`)."""
        if not isinstance(request, self.srv_type.Request):
            raise TypeError(
                f"call() takes a {self._type_name} request ({self._type_name}.Request()), got "
                f"{type(request).__name__}"
            )
        current = _state.state()
        nested_executor = None
        if current.executing:
            _, executor = current.executing[-1]
            from .executors import MultiThreadedExecutor

            if not isinstance(
                executor, MultiThreadedExecutor
            ) or not self.callback_group.can_execute(self):
                raise RuntimeError(
                    f"Client.call() on '{self.srv_name}' inside a callback would block for ever "
                    "in ROS 2: the response is handled by the same executor thread that is "
                    "waiting. Use call_async() and add_done_callback(), or create the client "
                    "with callback_group=ReentrantCallbackGroup() (or a group of its own) and "
                    "spin a MultiThreadedExecutor"
                )
            nested_executor = executor
        future = self.call_async(request)
        deadline_ns = None if timeout_sec is None else _state.now_ns() + int(timeout_sec * 1e9)
        checked_ns = _state.now_ns()
        while not future.done():
            if self._ready():
                call = self._take()
                if call is not None:
                    call()
                continue
            if nested_executor is not None:
                work = nested_executor._next_work()
                if work is not None:
                    nested_executor._execute(work)
                    continue
            elif self._serve_locally():
                continue
            now = _state.now_ns()
            if deadline_ns is not None and now >= deadline_ns:
                self.remove_pending_request(future)
                raise TimeoutError()
            if now - checked_ns >= SERVER_CHECK_NS:
                checked_ns = now
                if not self.service_is_ready():
                    self.remove_pending_request(future)
                    raise RuntimeError(
                        f"the service '{self.srv_name}' left the run before it answered"
                    )
            wake_ns = now + SERVER_CHECK_NS
            if deadline_ns is not None:
                wake_ns = min(wake_ns, deadline_ns)
            topics = {self._router.reply_to}
            if nested_executor is not None:
                topics |= nested_executor._wake_topics()
                due = nested_executor._next_due_ns()
                if due is not None:
                    wake_ns = min(wake_ns, due)
            _state.wait(wake_ns, topics)
        exception = future.exception()
        if exception is not None:
            raise exception
        return future.result()

    def _serve_locally(self) -> bool:
        """From the main loop, a service of this process answers at once, as the spin thread
        a ROS 2 program of that shape runs would answer it (with nothing spinning, rclpy would
        wait for ever). True if it ran."""
        local = self._local_service()
        if local is None or not local._ready():
            return False
        call = local._take()
        if call is not None:
            with _state.state().executing_callback(local.callback_group):
                call()
        return True

    def get_pending_request(self, sequence_number: int) -> Future[Any]:
        return self._pending_requests[sequence_number]

    def remove_pending_request(self, future: Future[Any]) -> None:
        for sequence, pending in list(self._pending_requests.items()):
            if pending is future:
                del self._pending_requests[sequence]
                self._router.pending.pop(sequence, None)
                break

    # ------------------------------------------------------------------ availability
    def service_is_ready(self) -> bool:
        if self._local_service() is not None:
            return True
        node_runtime = _state.runtime()
        own = node_runtime.info.node_name
        return any(
            topic.name == self._topic and any(name != own for name in topic.subscribers)
            for topic in node_runtime.current_graph()
        )

    def wait_for_service(self, timeout_sec: float | None = None) -> bool:
        """Wait until a server of this service is in the run (False after `timeout_sec`)."""
        remaining = float("inf") if timeout_sec is None else timeout_sec
        while self.context.ok() and not self.service_is_ready() and remaining > 0.0:
            try:
                _state.wait(_state.now_ns() + int(AVAILABILITY_POLL_S * 1e9), None)
            except RunEndedInterrupt:
                return False
            remaining -= AVAILABILITY_POLL_S
        return self.service_is_ready()

    # ------------------------------------------------------------------ executor side
    def _ready(self) -> bool:
        return not self._destroyed and bool(self._replies)

    def _due_ns(self) -> int | None:
        return None

    def _wake_topics(self) -> set[str]:
        return set() if self._destroyed or not self._pending_requests else {self._router.reply_to}

    def _take(self) -> Callable[[], Any] | None:
        if not self._replies:
            return None
        call_id, reply = self._replies.popleft()
        future = self._pending_requests.get(call_id)
        if future is None:
            return None  # the request was given up (remove_pending_request)
        if hasattr(reply, "response") and hasattr(reply, "ok"):  # a ServiceReply from the bus
            response = self.srv_type.Response.deserialize(bytes(reply.response))
        else:
            response = reply
        executor = self._node.executor

        def complete() -> None:
            future._set_executor(executor)
            future.set_result(response)

        return complete
