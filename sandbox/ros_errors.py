"""rospy's exception hierarchy (names and bases as in rospy.exceptions), defined once for the
node runtime and the rospy shim, and the rclpy exception the node host must recognise
(rclpy.executors.ExternalShutdownException)."""

from __future__ import annotations


class ROSException(Exception):
    """Base of the errors the rospy API raises."""


class ROSInitException(ROSException):
    """The node is used before rospy.init_node() or initialised twice."""


class ROSSerializationException(ROSException):
    """A message could not be serialized (a field holds a value its type cannot encode)."""


class ROSInterruptException(ROSException, KeyboardInterrupt):
    """A sleep or wait was interrupted by shutdown."""


class ExternalShutdownException(Exception):
    """rclpy.executors.ExternalShutdownException: the context was shut down while a node was
    spinning (in ROS 2, what SIGINT or a launch's shutdown does)."""


class RunEndedInterrupt(ExternalShutdownException, ROSInterruptException):
    """What rclpy's waits raise when the run ends the node. A real Ctrl-C makes rclpy.spin
    raise either KeyboardInterrupt or ExternalShutdownException; this is both, so the cleanup
    of course code written for either (`except KeyboardInterrupt:`, `except
    (KeyboardInterrupt, ExternalShutdownException):`) runs, and the host counts it as the
    parent's shutdown, like rospy's ROSInterruptException."""
