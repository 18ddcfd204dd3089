"""An rclpy-compatible API for RoboDojo nodes: ROS 2 course nodes run unchanged.

Behaviour follows rclpy (ros2/rclpy, rclpy/rclpy/*.py) where a student can observe it: init
and shutdown of the default context, Node subclassing, publishers and subscriptions with QoS,
timers, rates, services, parameters, executors and futures. The layer sits on the node's
NodeRuntime (sandbox/runtime.py): one thread, callbacks run inside its waits, time is the
run's. What differs from rclpy says so where it is used (executors.py, publisher.py,
context.py, timer.py, clock.py).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .context import Context
from .parameter import Parameter
from .signals import SignalHandlerOptions
from .task import Future
from .utilities import get_default_context, get_rmw_implementation_identifier, ok
from .utilities import shutdown as _shutdown
from .utilities import try_shutdown as _try_shutdown

if TYPE_CHECKING:
    from .executors import Executor
    from .node import Node

__all__ = [
    "Context",
    "Future",
    "InitContextManager",
    "Parameter",
    "SignalHandlerOptions",
    "create_node",
    "get_default_context",
    "get_global_executor",
    "get_rmw_implementation_identifier",
    "init",
    "ok",
    "shutdown",
    "spin",
    "spin_once",
    "spin_until_future_complete",
    "try_shutdown",
]


class InitContextManager:
    """What rclpy.init() returns: `with rclpy.init(): ...` shuts down at the end."""

    def __init__(
        self,
        args: list[str] | None,
        context: Context | None,
        domain_id: int | None,
        signal_handler_options: SignalHandlerOptions | None,
    ) -> None:
        self.context = get_default_context() if context is None else context
        self.context.init(args, domain_id=domain_id)

    def __enter__(self) -> InitContextManager:
        return self

    def __exit__(self, *exc_info: object) -> None:
        shutdown_context = None if self.context is get_default_context() else self.context
        try_shutdown(context=shutdown_context)


def init(
    *,
    args: list[str] | None = None,
    context: Context | None = None,
    domain_id: int | None = None,
    signal_handler_options: SignalHandlerOptions | None = None,
) -> InitContextManager:
    """Initialize ROS communications for a context (the default one unless given).

    `args`: the command line to read ROS arguments from (default sys.argv, which holds what
    the run gave this node)."""
    return InitContextManager(args, context, domain_id, signal_handler_options)


def get_global_executor() -> Executor:
    from . import _state
    from .executors import SingleThreadedExecutor

    current = _state.state()
    if current.global_executor is None:
        executor = SingleThreadedExecutor()
        current.global_executor = executor

        def reset_executor() -> None:
            executor.shutdown()
            if current.global_executor is executor:
                current.global_executor = None

        executor.context.on_shutdown(reset_executor)
    return current.global_executor


def shutdown(*, context: Context | None = None, uninstall_handlers: bool | None = None) -> None:
    """Shut down a context (the default one unless given) and the global executor."""
    _shutdown(context=context)


def try_shutdown(*, context: Context | None = None, uninstall_handlers: bool | None = None) -> None:
    """Shut down a context if it is not shut down already."""
    _try_shutdown(context=context)


def create_node(
    node_name: str,
    *,
    context: Context | None = None,
    cli_args: list[str] | None = None,
    namespace: str | None = None,
    use_global_arguments: bool = True,
    enable_rosout: bool = True,
    start_parameter_services: bool = True,
    parameter_overrides: list[Parameter] | None = None,
    allow_undeclared_parameters: bool = False,
    automatically_declare_parameters_from_overrides: bool = False,
    enable_logger_service: bool = False,
) -> Node:
    from .node import Node

    return Node(
        node_name,
        context=context,
        cli_args=cli_args,
        namespace=namespace,
        use_global_arguments=use_global_arguments,
        enable_rosout=enable_rosout,
        start_parameter_services=start_parameter_services,
        parameter_overrides=parameter_overrides,
        allow_undeclared_parameters=allow_undeclared_parameters,
        automatically_declare_parameters_from_overrides=(
            automatically_declare_parameters_from_overrides
        ),
        enable_logger_service=enable_logger_service,
    )


def _check_node(node: Any, function: str) -> None:
    from .node import Node

    if not isinstance(node, Node):
        raise TypeError(
            f"rclpy.{function}() takes a Node as its first argument, got {type(node).__name__}"
        )


def spin_once(
    node: Node, *, executor: Executor | None = None, timeout_sec: float | None = None
) -> None:
    """Run at most one callback, waiting up to `timeout_sec` for one (None: until there is
    one; 0: not at all)."""
    _check_node(node, "spin_once")
    executor = get_global_executor() if executor is None else executor
    try:
        executor.add_node(node)
        executor.spin_once(timeout_sec=timeout_sec)
    finally:
        executor.remove_node(node)


def spin(node: Node, executor: Executor | None = None) -> None:
    """Run callbacks until the context is shut down."""
    _check_node(node, "spin")
    executor = get_global_executor() if executor is None else executor
    try:
        executor.add_node(node)
        executor.spin()
    finally:
        executor.remove_node(node)


def spin_until_future_complete(
    node: Node,
    future: Future[Any],
    executor: Executor | None = None,
    timeout_sec: float | None = None,
) -> None:
    """Run callbacks until `future` is done (or `timeout_sec` passes, or shutdown)."""
    _check_node(node, "spin_until_future_complete")
    executor = get_global_executor() if executor is None else executor
    node_added = False
    try:
        node_added = executor.add_node(node)
        executor.spin_until_future_complete(future, timeout_sec)
    finally:
        if node_added:
            executor.remove_node(node)


_NOT_PROVIDED = {
    "lifecycle": "lifecycle (managed) nodes are not provided; use a plain rclpy.node.Node",
}


def __getattr__(name: str) -> object:
    import difflib
    import importlib

    if name in (
        "node",
        "executors",
        "qos",
        "time",
        "duration",
        "clock",
        "timer",
        "logging",
        "parameter",
        "exceptions",
        "callback_groups",
        "task",
        "utilities",
        "publisher",
        "subscription",
        "client",
        "service",
        "serialization",
        "clock_type",
        "constants",
        "context",
        "signals",
        "waitable",
        "guard_condition",
        "action",
        "impl",
    ):
        return importlib.import_module(f"{__name__}.{name}")
    reason = _NOT_PROVIDED.get(name)
    if reason is not None:
        raise AttributeError(f"rclpy.{name} is not available in RoboDojo nodes: {reason}")
    if name.startswith("__"):
        raise AttributeError(name)
    close = difflib.get_close_matches(name, __all__, n=2)
    hint = f"did you mean {' or '.join('rclpy.' + c for c in close)}? " if close else ""
    raise AttributeError(
        f"rclpy has no '{name}' in RoboDojo: {hint}docs/controllers.md lists what RoboDojo's "
        "rclpy provides"
    )
