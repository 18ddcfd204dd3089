"""rclpy.service.Service (rclpy/service.py) over the run's service topics.

A service is served as sandbox/services.py lays it out: requests arrive on the internal topic
`__srv__/<service>` wrapped in robodojo_msgs/msg/ServiceCall (the request in CDR), answers
leave on the caller's `__srv__reply/<caller>` in robodojo_msgs/msg/ServiceReply. The callback
runs when an executor spins the node, as `callback(request, response)`, and must return the
response: anything else raises TypeError out of spin (rclpy raises a bare TypeError; this one
says what to return). Requests from clients of the same process go to the service directly.
"""

from __future__ import annotations

import inspect
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from sandbox.services import request_topic

from . import _state
from .exceptions import InvalidHandle

if TYPE_CHECKING:
    from .callback_groups import CallbackGroup
    from .node import Node


def service_type_name(srv_type: Any) -> str:
    """ "example_interfaces/srv/AddTwoInts" for the AddTwoInts class (from its Request's
    `_type`, "example_interfaces/srv/AddTwoInts_Request")."""
    request = getattr(srv_type, "Request", None)
    response = getattr(srv_type, "Response", None)
    type_name = getattr(request, "_type", None)
    if not (isinstance(srv_type, type) and isinstance(type_name, str) and response is not None):
        raise TypeError(
            "a service type is a class such as example_interfaces.srv.AddTwoInts (with Request "
            f"and Response), got {srv_type!r}"
        )
    return type_name.removesuffix("_Request")


def wrapper_classes() -> tuple[Any, Any]:
    """robodojo_msgs/msg/ServiceCall and ServiceReply, the ROS 2 twins of sandbox/services.py's."""
    from sandbox.msgs import get_message_class

    return (
        get_message_class("robodojo_msgs/msg/ServiceCall"),
        get_message_class("robodojo_msgs/msg/ServiceReply"),
    )


class Service:
    """Answers requests of one service type under one name (made by Node.create_service)."""

    def __init__(
        self,
        node: Node,
        srv_type: Any,
        srv_name: str,
        bus_name: str,
        callback: Callable[[Any, Any], Any],
        callback_group: CallbackGroup,
    ) -> None:
        self._type_name = service_type_name(srv_type)
        if not callable(callback):
            raise TypeError(f"create_service() needs a callback function, got {callback!r}")
        self.srv_type = srv_type
        self.srv_name = "/" + bus_name
        self.callback = callback
        self.callback_group = callback_group
        self._node = node
        self._bus_name = bus_name
        self._topic = request_topic(bus_name)
        self._queue: deque[tuple[Any, Callable[[Any], None]]] = deque()
        self._destroyed = False
        call_class, _ = wrapper_classes()
        self._subscription = _state.runtime().subscribe(self._topic, call_class, self._arrived)

    @property
    def handle(self) -> Service:
        if self._destroyed:
            raise InvalidHandle("the service was destroyed")
        return self

    @property
    def service_name(self) -> str:
        return self.srv_name

    def destroy(self) -> None:
        if not self._destroyed:
            self._destroyed = True
            self._queue.clear()
            _state.runtime().unsubscribe(self._subscription)

    def __enter__(self) -> Service:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._node.destroy_service(self)

    # ------------------------------------------------------------------ requests
    def _arrived(self, call: Any) -> None:
        """A ServiceCall from another node of the run."""
        request = self.srv_type.Request.deserialize(bytes(call.request))
        reply_to, call_id = call.reply_to, call.id

        def answer(response: Any) -> None:
            _, reply_class = wrapper_classes()
            node_runtime = _state.runtime()
            node_runtime.advertise(reply_to, reply_class)
            reply = reply_class(id=call_id, ok=True, error="", response=response.serialize())
            node_runtime.publish(reply_to, reply)

        self._queue.append((request, answer))

    def _put_local(self, request: Any, answer: Callable[[Any], None]) -> None:
        """A request from a client of this process."""
        self._queue.append((type(request).deserialize(request.serialize()), answer))

    def send_response(self, response: Any, header: Any) -> None:
        if not isinstance(response, self.srv_type.Response):
            raise TypeError(
                f"the service '{self.srv_name}' must answer with a {self._type_name} response, "
                f"got {type(response).__name__}"
            )
        header(response)

    # ------------------------------------------------------------------ executor side
    def _ready(self) -> bool:
        return not self._destroyed and bool(self._queue)

    def _due_ns(self) -> int | None:
        return None

    def _wake_topics(self) -> set[str]:
        return set() if self._destroyed else {self._topic}

    def _take(self) -> Callable[[], Any] | None:
        if not self._queue:
            return None
        request, answer = self._queue.popleft()
        callback = self.callback

        def run() -> Any:
            result = callback(request, self.srv_type.Response())
            if inspect.iscoroutine(result):
                return _finish_async(self, result, answer)
            self._respond(result, answer)
            return None

        return run

    def _respond(self, result: Any, answer: Callable[[Any], None]) -> None:
        if not isinstance(result, self.srv_type.Response):
            got = "None" if result is None else type(result).__name__
            raise TypeError(
                f"the callback of service '{self.srv_name}' returned {got}: it must return the "
                f"response, e.g. `response.sum = request.a + request.b` then `return response`"
            )
        answer(result)


async def _finish_async(service: Service, coroutine: Any, answer: Callable[[Any], None]) -> None:
    service._respond(await coroutine, answer)
