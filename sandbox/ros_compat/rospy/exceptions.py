"""rospy.exceptions: the exception classes rospy raises (the same objects as `rospy.X`)."""

from sandbox.runtime import (
    ROSException,
    ROSInitException,
    ROSInterruptException,
    ROSSerializationException,
)


class ROSInternalException(Exception):
    """Base class of rospy's internal errors (kept for `except` clauses that name it)."""


class ROSTimeMovedBackwardsException(ROSInterruptException):
    """Raised by a sleep when time jumps backwards (a simulated clock restarting)."""

    def __init__(self, time: object = None) -> None:
        super().__init__("ROS time moved backwards")
        self.time = time


class TransportException(ROSException):
    """A connection to another node broke."""


__all__ = [
    "ROSException",
    "ROSInitException",
    "ROSInternalException",
    "ROSInterruptException",
    "ROSSerializationException",
    "ROSTimeMovedBackwardsException",
    "TransportException",
]
