"""Node life cycle, parameters and spin (rospy.client / rospy.core look-alikes)."""

from __future__ import annotations

import sys
import zlib
from collections.abc import Callable
from typing import Any

from sandbox import runtime as _runtime
from sandbox.runtime import ROSException, ROSInterruptException, normalize_param

# Log levels, with rospy's values.
DEBUG = 1
INFO = 2
WARN = 4
ERROR = 8
FATAL = 16

_UNSET = object()


def init_node(
    name: str,
    argv: list[str] | None = None,
    anonymous: bool = False,
    log_level: int | None = None,
    disable_rostime: bool = False,
    disable_rosout: bool = False,
    disable_signals: bool = False,
    xmlrpc_port: int = 0,
    tcpros_port: int = 0,
) -> None:
    """Name this node; required once before publishers, subscribers, rates and sleeps."""
    node = _runtime.current()
    if not isinstance(name, str) or not name.strip("/") or "/" in name.strip("/"):
        raise ValueError(f"init_node() takes a plain node name such as 'follower', got {name!r}")
    full = "/" + name.strip("/")
    if anonymous:
        # Deterministic, unlike rospy's pid/time suffix, so lockstep runs repeat exactly.
        full += f"_{zlib.crc32(node.info.node_name.encode()):08x}"
    if node.node_name is not None and node.node_name != full and not node.implicit_name:
        raise ROSException(
            f"rospy.init_node() has already been called with name {node.node_name!r}; "
            "call it once per node"
        )
    node.node_name = full
    node.implicit_name = False
    if log_level is not None:
        node.log_level = log_level


def get_name() -> str:
    name = _runtime.current().node_name
    return name if name is not None else "/unnamed"


def get_caller_id() -> str:
    return get_name()


def get_namespace() -> str:
    return "/"


def get_node_uri() -> str:
    return f"robodojo://{get_name().lstrip('/')}"


def myargv(argv: list[str] | None = None) -> list[str]:
    """argv without ROS remapping arguments (`name:=value`)."""
    return [arg for arg in (sys.argv if argv is None else argv) if ":=" not in arg]


def is_shutdown() -> bool:
    node = _runtime.current()
    node.poll()  # a loop that only polls this still lets time pass (sandbox.runtime)
    return node.is_shutdown


def is_shutdown_requested() -> bool:
    return is_shutdown()


def signal_shutdown(reason: str) -> None:
    """Stop the node: is_shutdown() becomes True, on_shutdown hooks run, sleeps raise."""
    _runtime.current().signal_shutdown(reason)


def on_shutdown(hook: Callable[[], Any]) -> None:
    if not callable(hook):
        raise TypeError(f"on_shutdown() takes a function, got {hook!r}")
    _runtime.current().on_shutdown(hook)


def spin() -> None:
    """Run callbacks as messages arrive until the node is shut down."""
    node = _runtime.current()
    node.require_init("rospy.spin()")
    try:
        while not node.is_shutdown:
            node.wait_until(None)
    except ROSInterruptException:
        return


# ---------------------------------------------------------------------- parameters
def _param_key(name: str) -> str:
    if not isinstance(name, str) or not name.strip("/~"):
        raise KeyError(f"a parameter name is a non-empty string, got {name!r}")
    key = normalize_param(name)
    node_name = (_runtime.current().node_name or "").strip("/")
    if node_name and key.startswith(node_name + "/"):
        key = key[len(node_name) + 1 :]
    return key


def get_param(param_name: str, default: Any = _UNSET) -> Any:
    """A run parameter; `~name` (private) and `name` read the same value here."""
    params = _runtime.current().params
    key = _param_key(param_name)
    if key in params:
        return params[key]
    if default is _UNSET:
        known = ", ".join(sorted(params)) or "none"
        raise KeyError(f"parameter {param_name!r} is not set (parameters of this run: {known})")
    return default


def get_param_cached(param_name: str, default: Any = _UNSET) -> Any:
    return get_param(param_name, default)


def set_param(param_name: str, param_value: Any) -> None:
    _runtime.current().params[_param_key(param_name)] = param_value


def has_param(param_name: str) -> bool:
    return _param_key(param_name) in _runtime.current().params


def delete_param(param_name: str) -> None:
    params = _runtime.current().params
    key = _param_key(param_name)
    if key not in params:
        raise KeyError(param_name)
    del params[key]


def search_param(param_name: str) -> str | None:
    return "/" + _param_key(param_name) if has_param(param_name) else None


def get_param_names() -> list[str]:
    return ["/" + key for key in sorted(_runtime.current().params)]
