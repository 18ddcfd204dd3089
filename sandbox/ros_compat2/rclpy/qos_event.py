"""rclpy.qos_event: the old name of rclpy.event_handler (deprecated in rclpy too)."""

import warnings

from .event_handler import (  # noqa: F401
    PublisherEventCallbacks,
    QoSOfferedIncompatibleQoSInfo,
    QoSRequestedIncompatibleQoSInfo,
    SubscriptionEventCallbacks,
)

warnings.warn("importing 'qos_event' is deprecated; import 'event_handler' instead", stacklevel=2)
