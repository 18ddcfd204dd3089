"""rclpy.utilities: the default context, ok/shutdown, remove_ros_args (rclpy/utilities.py)."""

from __future__ import annotations

import sys
from collections.abc import Sequence

from sandbox import ros2_args

from . import _state
from .constants import S_TO_NS
from .context import Context


def get_default_context(*, shutting_down: bool = False) -> Context:
    """The process's default context (a new one after the previous was shut down)."""
    current = _state.state()
    if current.default_context is None:
        current.default_context = Context()
    context = current.default_context
    if shutting_down:
        current.default_context = None
    return context


def remove_ros_args(args: Sequence[str] | None = None) -> list[str]:
    """The command line without its ROS arguments (`--ros-args ... [--]` sections)."""
    return ros2_args.remove_ros_args(sys.argv if args is None else args)


def ok(*, context: Context | None = None) -> bool:
    if context is None:
        context = get_default_context()
    _state.poll()  # `while rclpy.ok():` without a sleep still lets time pass
    return context.ok()


def shutdown(*, context: Context | None = None) -> None:
    if context is None:
        context = get_default_context(shutting_down=True)
    context.shutdown()


def try_shutdown(*, context: Context | None = None) -> None:
    if context is None:
        current = _state.state()
        if current.default_context is None:
            current.default_context = Context()
        current.default_context.try_shutdown()
        if not current.default_context.ok():
            current.default_context = None
    else:
        context.try_shutdown()


def get_rmw_implementation_identifier() -> str:
    return "rmw_robodojo"


def timeout_sec_to_nsec(timeout_sec: float | None) -> int:
    """Seconds to rcl nanoseconds: None or negative -> -1 (forever)."""
    if timeout_sec is None or timeout_sec < 0:
        return -1
    return int(float(timeout_sec) * S_TO_NS)
