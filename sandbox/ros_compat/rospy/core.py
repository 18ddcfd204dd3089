"""Node life cycle, names, parameters and spin (rospy.client / rospy.core look-alikes).

Names resolve as in rospy (sandbox.names: namespaces, `~private`, remapping, `__name:=`);
parameters live in the node's own copy of the parameter server (sandbox.params), filled from
the run's parameters (global) and the node's private ones (`~x`, `_x:=value`) at init_node."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

from sandbox import runtime as _runtime
from sandbox.names import InvalidName, Names, check_name, namespace_of, resolve
from sandbox.names import myargv as myargv_of
from sandbox.params import ParamNotSet, ParamServer, initial_params
from sandbox.runtime import ROSException, ROSInitException, ROSInterruptException

# Log levels, with rospy's values.
DEBUG = 1
INFO = 2
WARN = 4
ERROR = 8
FATAL = 16

_UNSET = object()


def _names(node: Any = None) -> Names:
    """The node's names (sandbox.names.Names), made from its NodeInfo on first use."""
    node = node or _runtime.current()
    names = getattr(node, "names", None)
    if names is None:
        try:
            names = Names.from_info(node.info)
        except InvalidName as error:
            raise ROSInitException(f"this node's command line or launch file: {error}") from None
        node.names = names
    return names


def _params(node: Any = None) -> ParamServer:
    """The node's copy of the parameter server, filled from the run's parameters."""
    node = node or _runtime.current()
    server = getattr(node, "param_server", None)
    if server is None:
        global_params, _ = initial_params(node.info.params)
        try:
            server = ParamServer(global_params)
        except (TypeError, OverflowError) as error:
            raise ROSInitException(f"the run's parameters: {error}") from None
        node.param_server = server
    return server


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
    """Name this node (`__name:=` on its command line wins, as in rospy); required once before
    rates and sleeps. Its private parameters (`_x:=value`, a launch file's ~params) are set."""
    node = _runtime.current()
    names = _names(node)
    call = (name, None if argv is None else list(argv), anonymous, log_level)
    if node.node_name is not None and not node.implicit_name:
        if getattr(node, "init_call", None) == call:
            return  # rospy allows a repeated call with the same arguments
        raise ROSException(
            f"rospy.init_node() has already been called with name {node.node_name!r}; "
            "call it once per node"
        )
    try:
        full = names.init(name, anonymous, argv)
    except InvalidName as error:
        raise ValueError(str(error)) from None
    node.node_name = full
    node.implicit_name = False
    node.init_call = call
    server = _params(node)
    _, private = initial_params(node.info.params)
    try:
        for key, value in {**private, **names.private_params()}.items():
            server.set(names.param(key), value)
    except (InvalidName, TypeError, OverflowError) as error:
        raise ROSInitException(f"invalid command-line parameters: {error}") from None
    if log_level is not None:
        node.log_level = log_level


def get_name() -> str:
    """The node's full name (`/ns/name`); `<namespace>unnamed` before init_node, as rospy."""
    node = _runtime.current()
    return node.node_name or _names(node).caller_id


def get_caller_id() -> str:
    return get_name()


def get_namespace() -> str:
    """The node's namespace with a trailing slash: `/` or `/robot1/`."""
    node = _runtime.current()
    if node.node_name is not None:
        return namespace_of(node.node_name)
    return _names(node).namespace


def resolve_name(name: str, caller_id: str | None = None) -> str:
    """The global name `name` stands for in this node, remapping applied (rospy.resolve_name)."""
    names = _names()
    try:
        if caller_id:
            return resolve(check_name(name), caller_id, names.resolved_mappings)
        return names.resolve(name)
    except InvalidName as error:
        raise ValueError(str(error)) from None


def get_node_uri() -> str:
    return f"robodojo://{get_name().lstrip('/')}"


def myargv(argv: list[str] | None = None) -> list[str]:
    """argv without ROS's `name:=value` arguments (remappings, `_param:=`, `__name:=`)."""
    return myargv_of(sys.argv if argv is None else argv)


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
def _param_name(name: Any) -> str:
    """The absolute name of a parameter for this node (private, relative, global, remapped)."""
    return _names().param(name)


def get_param(param_name: str, default: Any = _UNSET) -> Any:
    """A parameter's value (a dict for a namespace); KeyError if unset and no default."""
    server = _params()
    resolved = _param_name(param_name)
    try:
        return server.get(resolved)
    except ParamNotSet:
        if default is not _UNSET:
            return default
        raise ParamNotSet(server.missing_sentence(resolved, param_name)) from None


def get_param_cached(param_name: str, default: Any = _UNSET) -> Any:
    return get_param(param_name, default)


def set_param(param_name: str, param_value: Any) -> None:
    """Set a parameter; a dict sets (and replaces) the namespace under `param_name`."""
    _params().set(_param_name(param_name), param_value)


def has_param(param_name: str) -> bool:
    return _params().has(_param_name(param_name))


def delete_param(param_name: str) -> None:
    """Delete a parameter or a namespace; KeyError if it is not set."""
    server = _params()
    resolved = _param_name(param_name)
    try:
        server.delete(resolved)
    except ParamNotSet:
        raise ParamNotSet(server.missing_sentence(resolved, param_name)) from None


def search_param(param_name: str) -> str | None:
    """The full name of the closest parameter called `param_name`, looking in this node's
    private namespace, then each enclosing namespace up to the root (rospy.search_param)."""
    names = _names()
    if not isinstance(param_name, str) or not param_name or param_name.startswith("~"):
        raise ValueError(f"search_param() takes a relative or global name, got {param_name!r}")
    key = names.mappings.get(param_name, param_name)  # rospy searches with unresolved mappings
    return _params().search(names.search_start(), key)


def get_param_names() -> list[str]:
    """Every parameter's full name."""
    return _params().names()
