"""rospy.Service, ServiceProxy and wait_for_service between the nodes of one run.

Behaviour and error sentences as rospy's (impl/tcpros_service.py); the transport is the run's
topic bus (sandbox/services.py says how). A handler runs while its node sleeps, spins or waits,
woken by the request as rospy's handler thread would be.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from sandbox import runtime as _runtime
from sandbox.msgs import Message
from sandbox.runtime import ROSException, ROSSerializationException
from sandbox.services import AVAILABILITY_POLL_NS, ServiceException

from .timing import duration_ns


def _service_name(name: Any) -> str:
    """The service's name in the run, resolved and remapped as rospy does (no leading '/')."""
    if not isinstance(name, str) or not name.strip("/"):
        raise ValueError(f"a service name is a non-empty string such as 'reset', got {name!r}")
    return _runtime.current().names.service(name)


def _check_class(service_class: Any, what: str) -> None:
    if not (hasattr(service_class, "_request_class") and hasattr(service_class, "_response_class")):
        raise ValueError(
            f"{what} needs a service class such as std_srvs.srv.SetBool (from "
            f"`from std_srvs.srv import SetBool`), got {service_class!r}"
        )


def wait_for_service(service: str, timeout: Any = None) -> None:
    """Wait until some node of the run serves `service`; ROSException after `timeout` [s]."""
    node = _runtime.current()
    name = _service_name(service)
    deadline = None
    if timeout is not None:
        timeout_ns = duration_ns(timeout, "rospy.wait_for_service()")
        if timeout_ns == 0:
            raise ValueError("timeout must be non-zero")
        deadline = node.clock.now_ns() + timeout_ns
    while not node.services.available(node, name):
        now = node.clock.now_ns()
        if deadline is not None and now >= deadline:
            raise ROSException(f"timeout exceeded while waiting for service /{name}")
        step = now + AVAILABILITY_POLL_NS
        node.wait_until(step if deadline is None else min(step, deadline))


class ServiceProxy:
    """Call a service like a function: `proxy(request)` or `proxy(field1, field2, ...)`."""

    def __init__(
        self,
        name: str,
        service_class: Any,
        persistent: bool = False,
        headers: Any = None,
    ) -> None:
        _check_class(service_class, f"rospy.ServiceProxy('{name}', ...)")
        self.resolved_name = "/" + _service_name(name)
        self._name = self.resolved_name[1:]
        self.service_class = service_class
        self.request_class = service_class._request_class
        self.response_class = service_class._response_class

    def wait_for_service(self, timeout: Any = None) -> None:
        wait_for_service(self._name, timeout)

    def __call__(self, *args: Any, **kwds: Any) -> Message:
        return self.call(*args, **kwds)

    def call(self, *args: Any, **kwds: Any) -> Message:
        node = _runtime.current()
        node.require_init("calling a service")
        request = _request(self.request_class, args, kwds)
        try:
            request.serialize()
        except Exception as error:
            raise ROSSerializationException(str(error)) from None
        return node.services.call(node, self._name, self.service_class, request)

    def close(self) -> None:
        """Persistent connections are not kept here; nothing to close."""


def _request(request_class: type[Message], args: tuple, kwds: dict) -> Message:
    if len(args) == 1 and not kwds and isinstance(args[0], Message):
        if args[0]._type != request_class._type:
            raise TypeError(f"expected a {request_class._type} as the request, got {args[0]._type}")
        return args[0]
    try:
        return request_class(*args, **kwds)
    except (TypeError, ValueError) as error:
        raise TypeError(
            f"could not build a {request_class._type} from the arguments: {error}"
        ) from None


class Service:
    """Serve `name` with `handler(request) -> response` (or a dict/tuple/value, as rospy)."""

    def __init__(
        self,
        name: str,
        service_class: Any,
        handler: Callable[[Message], Any],
        buff_size: int = 65536,
        error_handler: Any = None,
    ) -> None:
        _check_class(service_class, f"rospy.Service('{name}', ...)")
        if not callable(handler):
            raise TypeError(f"rospy.Service('{name}', ...): handler must be a function")
        node = _runtime.current()
        self.resolved_name = "/" + _service_name(name)
        self.service_class = service_class
        self.request_class = service_class._request_class
        self.response_class = service_class._response_class
        self.handler = handler
        self._node = node
        self._served = node.services.serve(node, self.resolved_name[1:], service_class, handler)

    def shutdown(self, reason: str = "") -> None:
        self._node.services.stop_serving(self._node, self._served)

    def spin(self) -> None:
        from .core import spin

        spin()


__all__ = ["Service", "ServiceException", "ServiceProxy", "wait_for_service"]
