"""rospy's exception hierarchy (names and bases as in rospy.exceptions), defined once for the
node runtime and the rospy shim."""

from __future__ import annotations


class ROSException(Exception):
    """Base of the errors the rospy API raises."""


class ROSInitException(ROSException):
    """The node is used before rospy.init_node() or initialised twice."""


class ROSSerializationException(ROSException):
    """A message could not be serialized (a field holds a value its type cannot encode)."""


class ROSInterruptException(ROSException, KeyboardInterrupt):
    """A sleep or wait was interrupted by shutdown."""
