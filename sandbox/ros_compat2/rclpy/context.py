"""rclpy.context.Context: the life of init() and shutdown() (rclpy/context.py).

`init(args)` parses the command line's ROS arguments (sandbox.ros2_args; unknown ones raise
UnknownROSArgsError as rclpy does); `shutdown()` destroys the nodes it tracks and calls the
on_shutdown callbacks. A second init() of one context raises RuntimeError, a shutdown() of one
never initialised raises RuntimeError, as in rclpy.

When the run ends the node (its Shutdown frame), every context is shut down: ok() turns False
and spins end with ExternalShutdownException, as a SIGINT does in ROS 2. A shutdown() the
student calls after that does nothing (in ROS 2 it would raise, because the signal handler got
there first; the end of a run is not the student's doing).
"""

from __future__ import annotations

import sys
import weakref
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from sandbox import ros2_args
from sandbox.ros2_args import RosArgumentError, RosArguments

from . import _state
from .exceptions import UnknownROSArgsError

if TYPE_CHECKING:
    from .node import Node


class Context:
    """Encapsulates the lifecycle of init and shutdown."""

    def __init__(self) -> None:
        self._initialized = False
        self._shut_down = False
        self._callbacks: list[Any] = []
        self._nodes: list[weakref.ReferenceType[Node]] = []
        self.arguments = RosArguments()
        self.argv: list[str] = []

    @property
    def handle(self) -> Context | None:
        return self if self._initialized else None

    def init(
        self,
        args: list[str] | None = None,
        *,
        initialize_logging: bool = True,
        domain_id: int | None = None,
    ) -> None:
        if domain_id is not None and domain_id < 0:
            raise RuntimeError(f"Domain id ({domain_id}) should not be lower than zero.")
        if self._initialized:
            raise RuntimeError("Context.init() must only be called once")
        current = _state.state()
        if current.runtime.shutdown is not None:
            raise RuntimeError(
                "rclpy.init() after this node shut down "
                f"({current.runtime.shutdown.reason}): a RoboDojo node starts rclpy once"
            )
        self.argv = list(sys.argv if args is None else args)
        self.arguments = parse_arguments(self.argv)
        self._initialized = True
        current.contexts.append(self)
        for warning in self.arguments.warnings:
            current.runtime.warn(warning)

    def track_node(self, node: Node) -> None:
        self._nodes.append(weakref.ref(node))

    def untrack_node(self, node: Node) -> None:
        self._nodes = [ref for ref in self._nodes if ref() is not None and ref() is not node]

    def ok(self) -> bool:
        return self._initialized and not self._shut_down

    def _call_on_shutdown_callbacks(self) -> None:
        callbacks, self._callbacks = self._callbacks, []
        for callback in callbacks:
            function = callback() if isinstance(callback, weakref.WeakMethod) else callback
            if function is not None:
                function()

    def _cleanup(self) -> None:
        for ref in list(self._nodes):
            node = ref()
            if node is not None:
                node.destroy_node()
        self._shut_down = True
        self._call_on_shutdown_callbacks()

    def shutdown(self) -> None:
        if not self._initialized:
            raise RuntimeError("Context must be initialized before it can be shutdown")
        if self._shut_down:
            if _state.state().run_ended:
                return  # the run ended the node first (module docstring)
            raise RuntimeError("Context.shutdown() called on a context that is already shut down")
        self._cleanup()
        _shut_down_the_node_if_done()

    def try_shutdown(self) -> None:
        if self._initialized and not self._shut_down:
            self._cleanup()
            _shut_down_the_node_if_done()

    def _ended_by_run(self) -> None:
        """The run ended the node: what SIGINT's handler does to every context."""
        if self._initialized and not self._shut_down:
            self._shut_down = True
            self._call_on_shutdown_callbacks()

    def on_shutdown(self, callback: Callable[[], Any]) -> None:
        if not callable(callback):
            raise TypeError(f"callback should be a callable, got {type(callback)}")
        if self._initialized and self._shut_down:
            callback()
            return
        if hasattr(callback, "__self__") and hasattr(callback, "__func__"):
            self._callbacks.append(weakref.WeakMethod(callback))  # type: ignore[arg-type]
        else:
            self._callbacks.append(callback)

    def get_domain_id(self) -> int:
        return 0

    def destroy(self) -> None:
        pass

    def __enter__(self) -> Context:
        self.init()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.try_shutdown()


def parse_arguments(argv: list[str]) -> RosArguments:
    """The ROS arguments of a command line; UnknownROSArgsError or ValueError when rcl would
    refuse them."""
    try:
        arguments = ros2_args.parse(argv)
    except RosArgumentError as error:
        raise ValueError(f"invalid ROS arguments: {error}") from None
    if arguments.unknown:
        raise UnknownROSArgsError(
            f"Found unknown ROS arguments or parameters: {arguments.unknown!r}"
        )
    return arguments


def _shut_down_the_node_if_done() -> None:
    """Every context is shut down: the node has ended its part in the run (its Finishing
    goes out, so what it does next - figures, files - gets the end budget)."""
    current = _state.state()
    if any(context.ok() for context in current.contexts):
        return
    node_runtime = current.runtime
    if node_runtime.shutdown is None:
        node_runtime.signal_shutdown("rclpy.shutdown()")
