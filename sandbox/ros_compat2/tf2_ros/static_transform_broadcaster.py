"""tf2_ros.static_transform_broadcaster (the module ROS 2 tutorials import from)."""

from .transform_broadcaster import StaticTransformBroadcaster

__all__ = ["StaticTransformBroadcaster"]
