"""rclpy.clock: Clock, ROSClock and their sleeps (rclpy/clock.py).

Every clock of a RoboDojo node reads the run's clock: virtual time in a lockstep run, the wall
in a realtime one (sandbox/vclock.py); so ROS time, system time and steady time agree, and
`use_sim_time` changes nothing. The clock type still travels with every Time, and Times of
different types do not compare, as in rclpy. `sleep_until`/`sleep_for` sleep on the node's
thread (callbacks of executors spun elsewhere run meanwhile, as in ROS 2).
"""

from __future__ import annotations

from collections.abc import Callable
from enum import IntEnum
from typing import TYPE_CHECKING, Any

from . import _state
from .clock_type import ClockType
from .duration import Duration
from .exceptions import NotInitializedException
from .time import Time

if TYPE_CHECKING:
    from .context import Context


class ClockChange(IntEnum):
    ROS_TIME_NO_CHANGE = 1
    ROS_TIME_ACTIVATED = 2
    ROS_TIME_DEACTIVATED = 3
    SYSTEM_TIME_NO_CHANGE = 4


class JumpThreshold:
    def __init__(
        self,
        *,
        min_forward: Duration | None,
        min_backward: Duration | None,
        on_clock_change: bool = True,
    ) -> None:
        if min_forward is not None and min_forward.nanoseconds <= 0:
            raise ValueError("min_forward must be a positive non-zero duration")
        if min_backward is not None and min_backward.nanoseconds >= 0:
            raise ValueError("min_backward must be a negative non-zero duration")
        if min_forward is None and min_backward is None and not on_clock_change:
            raise ValueError("At least one jump threshold must be enabled")
        self.min_forward = min_forward
        self.min_backward = min_backward
        self.on_clock_change = on_clock_change


class JumpHandle:
    """A registered time-jump callback; the run's clock never jumps, so it is never called."""

    def __init__(
        self, *, clock: Clock, threshold: JumpThreshold, pre_callback: Any, post_callback: Any
    ) -> None:
        if pre_callback is None and post_callback is None:
            raise ValueError("One of pre_callback or post_callback must be callable")
        self.clock = clock

    def unregister(self) -> None:
        pass

    def __enter__(self) -> JumpHandle:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.unregister()


class Clock:
    """A clock of one type reading the run's time."""

    def __init__(self, *, clock_type: ClockType = ClockType.SYSTEM_TIME) -> None:
        if not isinstance(clock_type, ClockType):
            raise TypeError("Clock type must be a ClockType enum")
        if clock_type is ClockType.UNINITIALIZED:
            raise RuntimeError("Failed to initialize clock: clock type is UNINITIALIZED")
        self._clock_type = clock_type

    @property
    def clock_type(self) -> ClockType:
        return self._clock_type

    def __repr__(self) -> str:
        return f"Clock(clock_type={self._clock_type.name})"

    def now(self) -> Time:
        _state.poll()  # a loop on clock.now() alone still lets time pass (sandbox/busy_loop.py)
        return Time(nanoseconds=_state.now_ns(), clock_type=self._clock_type)

    def create_jump_callback(
        self,
        threshold: JumpThreshold,
        *,
        pre_callback: Callable[[], None] | None = None,
        post_callback: Callable[[Any], None] | None = None,
    ) -> JumpHandle:
        return JumpHandle(
            clock=self, threshold=threshold, pre_callback=pre_callback, post_callback=post_callback
        )

    def sleep_until(self, until: Time, context: Context | None = None) -> bool:
        """Sleep until this clock reads `until`; False if the context shut down first."""
        from .utilities import get_default_context

        context = get_default_context() if context is None else context
        if not context.ok():
            raise NotInitializedException()
        if until.clock_type != self._clock_type:
            raise ValueError("until's clock type does not match this clock's type")
        return sleep_until_ns(until.nanoseconds, context)

    def sleep_for(self, rel_time: Duration, context: Context | None = None) -> bool:
        return self.sleep_until(self.now() + rel_time, context)


class ROSClock(Clock):
    """The node's clock (ROS time); `ros_time_is_active` follows use_sim_time."""

    def __init__(self) -> None:
        super().__init__(clock_type=ClockType.ROS_TIME)
        self._ros_time_is_active = False

    @property
    def ros_time_is_active(self) -> bool:
        return self._ros_time_is_active

    def _set_ros_time_is_active(self, enabled: bool) -> None:
        self._ros_time_is_active = bool(enabled)

    def set_ros_time_override(self, time: Time) -> None:
        if not isinstance(time, Time):
            raise TypeError(
                f"Time must be specified as rclpy.time.Time. Received type: {type(time)}"
            )
        _state.state().warn_once(
            "ros_time_override",
            "set_ros_time_override() is ignored: a RoboDojo node's clock is the run's",
        )


def sleep_until_ns(target_ns: int, context: Context) -> bool:
    """Sleep on the node's thread until the run's time reaches `target_ns`; False when the
    context shut down meanwhile (then the run has ended the node)."""
    from sandbox.ros_errors import RunEndedInterrupt

    current = _state.state()
    if not current.on_node_thread():
        import time

        time.sleep(max(0.0, (target_ns - _state.now_ns()) / 1e9))  # the real sleep, see vclock
        return context.ok()
    try:
        while _state.now_ns() < target_ns - 1_000:
            _state.wait(target_ns, None)
    except RunEndedInterrupt:
        return False
    return context.ok()
