"""tf2_ros.Buffer: BufferCore plus waiting for transforms, in the node's time.

As in ros/geometry2 (tf2_ros/src/tf2_ros/buffer.py): lookup_transform(target, source, time,
timeout) first waits (can_transform with the timeout), then looks up, so a transform that does
not arrive in time raises the lookup's own error. Waiting sleeps the node in small steps with
rospy.sleep, so callbacks (the TransformListener's among them) run meanwhile and simulated
time advances; inside a callback a wait cannot let new transforms in, so it checks once.
"""

from __future__ import annotations

import contextlib
from typing import Any

import rospy

from .buffer_core import BufferCore, to_nsec
from .buffer_interface import BufferInterface

POLL_PERIOD_S = 0.01  # [s] between checks while waiting (tf2_ros polls at timeout/100)


def _log(level: str, text: str) -> None:
    """Into the node's log as rospy would print it; dropped when no node runs (pure use)."""
    with contextlib.suppress(rospy.ROSInitException):
        {"ERROR": rospy.logerr, "WARN": rospy.logwarn}.get(level, rospy.loginfo)(text)


def wait_until(ready: Any, timeout: Any, what: str) -> bool:
    """Sleep in POLL_PERIOD_S steps until ready() or `timeout` (Duration or seconds) of node
    time has passed; ready()'s last answer."""
    if isinstance(timeout, int | float) and not isinstance(timeout, bool):
        timeout_ns = round(float(timeout) * 1e9)
    else:
        timeout_ns = to_nsec(timeout, f"{what} timeout")
    if timeout_ns <= 0:
        return ready()
    if ready():
        return True
    deadline = rospy.get_rostime().to_nsec() + timeout_ns
    while True:
        remaining = deadline - rospy.get_rostime().to_nsec()
        if remaining <= 0:
            return ready()
        try:
            rospy.sleep(min(POLL_PERIOD_S, remaining / 1e9))
        except rospy.ROSInterruptException:
            raise
        except rospy.ROSException:  # asked to wait inside a callback: nothing new can arrive
            return ready()
        if ready():
            return True


class Buffer(BufferCore, BufferInterface):
    """The transform buffer a TransformListener fills: Buffer(cache_time=rospy.Duration(10))."""

    def __init__(self, cache_time: Any = None, debug: bool = True) -> None:
        BufferCore.__init__(self, cache_time)
        BufferInterface.__init__(self)
        self.log = _log

    def lookup_transform(
        self, target_frame: str, source_frame: str, time: Any, timeout: Any = None
    ) -> Any:
        """The pose of `source_frame` in `target_frame` at `time` (rospy.Time(0): the latest
        common time) as a TransformStamped; waits up to `timeout` for it."""
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
        """Whether lookup_transform would succeed, waiting up to `timeout` for it."""
        if timeout is not None:
            wait_until(
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
        """Whether lookup_transform_full would succeed, waiting up to `timeout` for it."""
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        if timeout is not None:
            wait_until(
                lambda: self.can_transform_full_core(*args)[0], timeout, "can_transform_full()"
            )
        result = self.can_transform_full_core(*args)
        return result if return_debug_tuple else result[0]
