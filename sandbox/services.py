"""ROS services between the nodes of one run, carried as two internal topics.

rospy serves each service on a TCP connection of its own, with a handler thread per call. In a
run every byte between nodes already travels on the topic bus, so a service is a pair of
internal topics: requests on `__srv__/<service>` (the server node subscribes and is woken by
them whatever it is doing, as rospy's handler threads run whenever a call comes), replies on
`__srv__reply/<caller>` (each calling node subscribes to its own). Neither is a legal ROS name
(a ROS name starts with a letter, '/' or '~'), so no student topic can collide with them.

A call returns within the same instant of simulated time when the server is idle or sleeping:
the server's handler runs at its next wake, which the request brings forward. The rules for
what a handler may return, and the sentences of the errors, follow rospy's
impl/tcpros_service.py (convert_return_to_response, ServiceProxy.call).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from sandbox.msgs import Message

if TYPE_CHECKING:
    from sandbox.runtime import NodeRuntime

REQUEST_PREFIX = "__srv__/"
REPLY_PREFIX = "__srv__reply/"
# [ns] a waiting caller looks this often whether its server is still there (a server that
# ended never answers); a live server answers long before.
SERVER_CHECK_NS = 1_000_000_000
# [ns] wait_for_service() looks at the run's graph this often
AVAILABILITY_POLL_NS = 10_000_000


class ServiceCall(Message):
    """One request to a service: which service, where to answer, and the request's bytes."""

    _type = "robodojo_msgs/ServiceCall"
    _definition = """
string service   # the service's name
string reply_to  # the topic the caller listens on for the answer
uint32 id        # chosen by the caller, repeated in the reply
uint8[] request  # the request message, ROS1-serialized
"""


class ServiceReply(Message):
    """The answer to one ServiceCall: the response's bytes, or the error rospy would raise."""

    _type = "robodojo_msgs/ServiceReply"
    _definition = """
uint32 id         # the ServiceCall's id
bool ok           # False: `error` says why there is no response
string error
uint8[] response  # the response message, ROS1-serialized
"""


class ServiceException(Exception):
    """rospy.ServiceException: the call could not be completed (defined here so the runtime and
    the rospy shim raise the same class)."""


def request_topic(service: str) -> str:
    return REQUEST_PREFIX + service


def is_internal(topic: str) -> bool:
    return topic.startswith(REQUEST_PREFIX) or topic.startswith(REPLY_PREFIX)


def to_response(value: Any, response_class: type[Message]) -> Message:
    """What a handler returned, as a response (rospy's rules: the response itself, a dict of
    fields, a tuple/list of field values, or a single value for the first field)."""
    if isinstance(value, Message) and value._type == response_class._type:
        return value
    if isinstance(value, dict):
        try:
            return response_class(**value)
        except (AttributeError, TypeError) as error:
            raise ServiceException(f"handler returned invalid value: {error}") from None
    if value is None:
        raise ServiceException("service handler returned None")
    if not isinstance(value, list | tuple):
        try:
            return response_class(value)
        except TypeError as error:
            raise ServiceException(f"handler returned invalid value: {error}") from None
    try:
        return response_class(*value)
    except TypeError as error:
        raise ServiceException(f"handler returned wrong number of values: {error}") from None


@dataclass(eq=False)
class ServedService:
    name: str
    service_class: Any
    handler: Callable[[Message], Any]
    subscription: Any = None


@dataclass
class NodeServices:
    """The services one node serves and the calls it is waiting on."""

    served: dict[str, ServedService] = field(default_factory=dict)
    replies: dict[int, ServiceReply] = field(default_factory=dict)
    _ids: itertools.count = field(default_factory=lambda: itertools.count(1))
    _listening: bool = False

    # ------------------------------------------------------------------ server side
    def serve(
        self, node: NodeRuntime, name: str, service_class: Any, handler: Callable[..., Any]
    ) -> ServedService:
        if name in self.served:
            raise ServiceException(f"service [/{name}] already registered")
        served = ServedService(name, service_class, handler)
        topic = request_topic(name)
        served.subscription = node.subscribe(
            topic, ServiceCall, lambda call: self._handle(node, served, call)
        )
        node.wake_topics.add(topic)
        self.served[name] = served
        return served

    def stop_serving(self, node: NodeRuntime, served: ServedService) -> None:
        if self.served.get(served.name) is served:
            del self.served[served.name]
            node.unsubscribe(served.subscription)
            node.wake_topics.discard(request_topic(served.name))

    def _handle(self, node: NodeRuntime, served: ServedService, call: ServiceCall) -> None:
        response_class = served.service_class._response_class
        reply = ServiceReply(id=call.id, ok=False)
        try:
            request = served.service_class._request_class.deserialize(call.request)
            response = to_response(served.handler(request), response_class)
            reply.response, reply.ok = response.serialize(), True
        except ServiceException as error:
            reply.error = f"service cannot process request: {error}"
        except Exception as error:  # the student's handler: logged, the node goes on
            node.log("ERROR", f"Error processing request: {error!r}")
            reply.error = f"error processing request: {error}"
        node.advertise(call.reply_to, ServiceReply)
        node.publish(call.reply_to, reply)

    # ------------------------------------------------------------------ client side
    def available(self, node: NodeRuntime, name: str) -> bool:
        topic = request_topic(name)
        return any(t.name == topic and t.subscribers for t in node.current_graph())

    def call(self, node: NodeRuntime, name: str, service_class: Any, request: Message) -> Message:
        own = self.served.get(name)
        if own is not None:  # the bus never routes a node's message back to it: answer here
            return to_response(own.handler(request), service_class._response_class)
        if not self.available(node, name):
            raise ServiceException(f"service [/{name}] unavailable")
        reply_to = REPLY_PREFIX + (node.node_name or "/unnamed").strip("/")
        if not self._listening:
            node.subscribe(reply_to, ServiceReply, self._collect)
            self._listening = True
        call_id = next(self._ids)
        node.advertise(request_topic(name), ServiceCall)
        node.publish(
            request_topic(name),
            ServiceCall(service=name, reply_to=reply_to, id=call_id, request=request.serialize()),
        )
        while call_id not in self.replies:
            node.wait_until(node.clock.now_ns() + SERVER_CHECK_NS, wake_on=[reply_to])
            if call_id not in self.replies and not self.available(node, name):
                raise ServiceException(f"service [/{name}] ended before it answered")
        reply = self.replies.pop(call_id)
        if not reply.ok:
            raise ServiceException(f"service [/{name}] responded with an error: {reply.error}")
        return service_class._response_class.deserialize(reply.response)

    def _collect(self, reply: ServiceReply) -> None:
        self.replies[reply.id] = reply
