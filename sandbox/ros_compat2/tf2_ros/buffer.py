"""tf2_ros.Buffer for ROS 2: the shared tf2 core (sandbox/tf2) in the ROS 2 dialect, plus
waiting, as ros2/geometry2's tf2_ros_py/tf2_ros/buffer.py does it.

lookup_transform(target, source, time, timeout=Duration()) first waits (can_transform with the
timeout), then looks up, so a transform that does not arrive in time raises the lookup's own
error. As in rclpy's tf2_ros, the wait polls the buffer every 20 ms with time.sleep on the
node's clock and runs no callbacks itself: the buffer fills only when the node spins (a
TransformListener's subscriptions are ordinary callbacks). A lookup at rclpy.time.Time() (time
0: the latest common time) after the node has spun needs no timeout; that is how the ROS 2
tutorials call it, from a timer callback. wait_for_transform_async / lookup_transform_async
give a Future (or an awaitable) that completes when the listener adds the missing transform.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from typing import Any

import rclpy.logging
from rclpy.duration import Duration
from rclpy.task import Future
from rclpy.time import Time

from sandbox.tf2 import dialect
from sandbox.tf2.buffer_core import BufferCore as SharedCore
from sandbox.tf2.buffer_interface import BufferInterface

POLL_PERIOD_S = 0.02  # [s] between checks while waiting, as rclpy's tf2_ros Buffer polls

ROS2 = dialect.ros2(
    time=lambda ns: Time(nanoseconds=ns), duration=lambda ns: Duration(nanoseconds=ns)
)


def _log(level: str, text: str) -> None:
    logger = rclpy.logging.get_logger("tf2_buffer")
    (logger.error if level == "ERROR" else logger.warning)(text)


def _timeout_ns(timeout: Any, what: str) -> int:
    if timeout is None:
        return 0
    if isinstance(timeout, int | float) and not isinstance(timeout, bool):
        raise TypeError(
            f"{what} takes its timeout as an rclpy.duration.Duration, e.g. "
            f"timeout=Duration(seconds={timeout}), not a number"
        )
    return ROS2.to_nsec(timeout, f"{what} timeout")


def _wait(ready: Callable[[], bool], timeout: Any, what: str) -> None:
    """Poll `ready` every POLL_PERIOD_S until it holds or `timeout` has passed."""
    timeout_s = _timeout_ns(timeout, what) / 1e9
    if timeout_s <= 0.0 or ready():
        return
    deadline = _time.monotonic() + timeout_s
    while not ready():
        remaining = deadline - _time.monotonic()
        if remaining <= 0.0:
            return
        _time.sleep(min(POLL_PERIOD_S, remaining))


class BufferCore(SharedCore):
    """tf2's frame tree without waiting (tf2_py.BufferCore): rclpy times in, ROS 2 messages
    out."""

    dialect = ROS2


class Buffer(BufferCore, BufferInterface):
    """The transform buffer a TransformListener fills: Buffer(cache_time=Duration(seconds=10))."""

    def __init__(self, cache_time: Any = None, node: Any = None) -> None:
        BufferCore.__init__(self, cache_time)
        BufferInterface.__init__(self)
        self._new_data_callbacks: list[Callable[[], None]] = []
        self._node = node  # rclpy's serves "tf2_frames" from it; not needed here
        self.log = _log  # tf2's complaints (TF_REPEATED_DATA, ...) reach the node's log

    # ------------------------------------------------------------------ filling
    def set_transform(self, transform: Any, authority: str) -> bool:
        stored = super().set_transform(transform, authority)
        self._call_new_data_callbacks()
        return stored

    def set_transform_static(self, transform: Any, authority: str) -> bool:
        stored = super().set_transform_static(transform, authority)
        self._call_new_data_callbacks()
        return stored

    def _call_new_data_callbacks(self) -> None:
        for callback in list(self._new_data_callbacks):
            callback()

    # ------------------------------------------------------------------ lookups
    def lookup_transform(
        self, target_frame: str, source_frame: str, time: Any, timeout: Any = None
    ) -> Any:
        """The pose of `source_frame` in `target_frame` at `time` (rclpy.time.Time(): the
        latest) as a geometry_msgs/msg/TransformStamped; waits up to `timeout` for it."""
        _timeout_ns(timeout, "lookup_transform()")
        self.can_transform(target_frame, source_frame, time, timeout)
        return self.lookup_transform_core(target_frame, source_frame, time)

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
    ) -> Any:
        """lookup_transform between two times, through `fixed_frame`."""
        _timeout_ns(timeout, "lookup_transform_full()")
        self.can_transform_full(
            target_frame, target_time, source_frame, source_time, fixed_frame, timeout
        )
        return self.lookup_transform_full_core(
            target_frame, target_time, source_frame, source_time, fixed_frame
        )

    def can_transform(
        self,
        target_frame: str,
        source_frame: str,
        time: Any,
        timeout: Any = None,
        return_debug_tuple: bool = False,
    ) -> Any:
        """Whether lookup_transform would succeed, polling up to `timeout` for it."""
        _wait(
            lambda: self.can_transform_core(target_frame, source_frame, time)[0],
            timeout,
            "can_transform()",
        )
        result = self.can_transform_core(target_frame, source_frame, time)
        return result if return_debug_tuple else result[0]

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
        return_debug_tuple: bool = False,
    ) -> Any:
        """Whether lookup_transform_full would succeed, polling up to `timeout` for it."""
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        _wait(lambda: self.can_transform_full_core(*args)[0], timeout, "can_transform_full()")
        result = self.can_transform_full_core(*args)
        return result if return_debug_tuple else result[0]

    # ------------------------------------------------------------------ futures
    def _future_when(self, ready: Callable[[], bool], result: Callable[[], Any]) -> Future:
        future = Future()
        if ready():
            future.set_result(result())
            return future

        def on_new_data() -> None:
            if future.done():
                return
            try:
                if ready():
                    future.set_result(result())
            except Exception as error:  # handed to the future's owner
                future.set_exception(error)
            if future.done() and on_new_data in self._new_data_callbacks:
                self._new_data_callbacks.remove(on_new_data)

        self._new_data_callbacks.append(on_new_data)
        return future

    def wait_for_transform_async(self, target_frame: str, source_frame: str, time: Any) -> Future:
        """A Future that completes with the transform once the buffer can give it."""
        return self._future_when(
            lambda: self.can_transform_core(target_frame, source_frame, time)[0],
            lambda: self.lookup_transform_core(target_frame, source_frame, time),
        )

    def wait_for_transform_full_async(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> Future:
        """wait_for_transform_async between two times, through `fixed_frame`."""
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        return self._future_when(
            lambda: self.can_transform_full_core(*args)[0],
            lambda: self.lookup_transform_full_core(*args),
        )

    async def lookup_transform_async(self, target_frame: str, source_frame: str, time: Any) -> Any:
        """await buffer.lookup_transform_async(...) in a coroutine callback."""
        await self.wait_for_transform_async(target_frame, source_frame, time)
        return self.lookup_transform_core(target_frame, source_frame, time)

    async def lookup_transform_full_async(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> Any:
        """await buffer.lookup_transform_full_async(...) in a coroutine callback."""
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        await self.wait_for_transform_full_async(*args)
        return self.lookup_transform_full_core(*args)
