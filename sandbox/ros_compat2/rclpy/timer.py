"""rclpy.timer: Timer and Rate, scheduled as rcl schedules them (rcl/src/rcl/timer.c).

A timer is ready once the clock reaches its next call time; calling it moves the next call time
on by exactly one period from the previous one (not from when the callback ran), and a timer
that fell behind skips the periods it missed instead of calling in a burst. cancel() stops it,
reset() restarts it from now. An executor that spins runs a ready timer's callback; the node's
thread sleeps until the earliest timer is due.

Rate.sleep() sleeps on the node's thread until the rate's next tick. In ROS 2 it only returns
while something spins the node in another thread (otherwise it blocks forever); here it always
returns, and says once how to write it for ROS 2 when nothing spins the node.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from sandbox.ros_errors import RunEndedInterrupt

from . import _state
from .clock import Clock
from .clock_type import ClockType
from .exceptions import InvalidHandle, ROSInterruptException
from .time import Time

if TYPE_CHECKING:
    from .callback_groups import CallbackGroup
    from .context import Context


class TimerInfo:
    """What a timer callback that asks for it (a parameter annotated TimerInfo) is told."""

    def __init__(
        self,
        *,
        expected_call_time: int = 0,
        actual_call_time: int = 0,
        clock_type: ClockType = ClockType.SYSTEM_TIME,
    ) -> None:
        if expected_call_time < 0 or actual_call_time < 0:
            raise ValueError("call time values must not be negative")
        self._expected_call_time = Time(nanoseconds=expected_call_time, clock_type=clock_type)
        self._actual_call_time = Time(nanoseconds=actual_call_time, clock_type=clock_type)

    @property
    def expected_call_time(self) -> Time:
        return self._expected_call_time

    @property
    def actual_call_time(self) -> Time:
        return self._actual_call_time


class Timer:
    """A periodic callback (made by Node.create_timer)."""

    def __init__(
        self,
        callback: Callable[..., Any] | None,
        callback_group: CallbackGroup | None,
        timer_period_ns: int,
        clock: Clock,
        *,
        context: Context | None = None,
        autostart: bool = True,
    ) -> None:
        if timer_period_ns < 0:
            raise ValueError(f"timer period must be non-negative, got {timer_period_ns} ns")
        self._clock = clock
        self._context = context
        self._period_ns = int(timer_period_ns)
        now = _state.now_ns()
        self._last_call_ns = now
        self._next_call_ns = now + self._period_ns
        self._canceled = not autostart
        self._destroyed = False
        self.callback = callback
        self.callback_group = callback_group

    @property
    def handle(self) -> Timer:
        if self._destroyed:
            raise InvalidHandle("the timer was destroyed")
        return self

    @property
    def clock(self) -> Clock:
        return self._clock

    @property
    def timer_period_ns(self) -> int:
        return self._period_ns

    @timer_period_ns.setter
    def timer_period_ns(self, value: int) -> None:
        self._period_ns = int(value)

    def destroy(self) -> None:
        self._destroyed = True
        self._canceled = True

    def is_ready(self) -> bool:
        return not self._canceled and not self._destroyed and _state.now_ns() >= self._next_call_ns

    def is_canceled(self) -> bool:
        return self._canceled

    def cancel(self) -> None:
        self._canceled = True

    def reset(self) -> None:
        now = _state.now_ns()
        self._canceled = False
        self._next_call_ns = now + self._period_ns

    def time_since_last_call(self) -> int:
        return _state.now_ns() - self._last_call_ns

    def time_until_next_call(self) -> int | None:
        if self._canceled:
            return None
        return self._next_call_ns - _state.now_ns()

    def __enter__(self) -> Timer:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.destroy()

    # ------------------------------------------------------------------ executor side
    def _due_ns(self) -> int | None:
        """When this timer is next ready (None: canceled)."""
        if self._canceled or self._destroyed:
            return None
        return self._next_call_ns

    def _ready(self) -> bool:
        return self.is_ready()

    def _take(self) -> Callable[[], Any] | None:
        """rcl_timer_call: move the schedule on and return the call to make."""
        now = _state.now_ns()
        expected = self._next_call_ns
        self._last_call_ns = now
        self._next_call_ns += self._period_ns
        if self._next_call_ns < now:
            if self._period_ns == 0:
                self._next_call_ns = now
            else:
                behind = now - self._next_call_ns
                self._next_call_ns += (1 + (behind - 1) // self._period_ns) * self._period_ns
        callback = self.callback
        if callback is None:
            return None
        info_arg = _timer_info_parameter(callback)
        if info_arg is None:
            return callback
        info = TimerInfo(
            expected_call_time=expected, actual_call_time=now, clock_type=self._clock.clock_type
        )
        return lambda: callback(**{info_arg: info})


def _timer_info_parameter(callback: Callable[..., Any]) -> str | None:
    """The name of the callback's parameter annotated TimerInfo, as rclpy looks it up."""
    try:
        parameters = inspect.signature(callback).parameters.values()
    except (TypeError, ValueError):
        return None
    for parameter in parameters:
        if parameter.annotation in (TimerInfo, "TimerInfo"):
            return parameter.name
    return None


class _RateInterrupted(ROSInterruptException, RunEndedInterrupt):
    """Rate.sleep() when the run ends the node: rclpy's ROSInterruptException, and also what
    every wait raises then (sandbox.ros_errors.RunEndedInterrupt)."""


class Rate:
    """Sleeps at a fixed rate (made by Node.create_rate)."""

    def __init__(self, timer: Timer, *, context: Context) -> None:
        self._timer = timer
        self._context = context
        self._is_shutdown = False
        self._is_destroyed = False
        context.on_shutdown(self._on_shutdown)

    def _on_shutdown(self) -> None:
        self._is_shutdown = True
        self.destroy()

    def destroy(self) -> None:
        self._is_destroyed = True

    def sleep(self) -> None:
        """Block until the rate's next tick."""
        if self._is_shutdown:
            raise _RateInterrupted()
        if self._is_destroyed:
            raise RuntimeError("Rate cannot sleep because it has been destroyed")
        if self._timer._destroyed:
            self.destroy()
            raise InvalidHandle("Rate cannot sleep because the timer has been destroyed")
        target = self._timer._next_call_ns
        if _state.now_ns() >= target:
            self._timer._take()  # the tick passed while the loop worked: return at once, as
            return  # rclpy's rate event is already set then
        from .clock import sleep_until_ns

        reached = sleep_until_ns(target, self._context)
        if not reached or self._is_shutdown:
            self._is_shutdown = True
            raise _RateInterrupted()
        self._timer._take()
        current = _state.state()  # looked at after a sleep: a spin thread has started by now
        if not current.background and current.on_node_thread():
            current.warn_once(
                "rate_without_spin",
                "Rate.sleep() works here without spinning, but in ROS 2 it returns only while "
                "the node is spun in another thread, e.g. threading.Thread(target=rclpy.spin, "
                "args=(node,), daemon=True).start()",
            )
