"""rclpy.event_handler: the QoS event callbacks a publisher or subscription may be given.

Of rmw's events only incompatible QoS happens in a run (sandbox/ros_compat2/rclpy/qos.py): a
given `incompatible_qos` callback is called with the event instead of rclpy's default warning
(`use_default_callbacks=False` and no callback: nothing is said). Deadlines, liveliness, lost
messages and matching never fire: the run's bus loses nothing and has no liveliness.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


@dataclass
class QoSRequestedIncompatibleQoSInfo:
    """rmw_requested_qos_incompatible_event_status_t."""

    total_count: int = 0
    total_count_change: int = 0
    last_policy_kind: int = 0


QoSOfferedIncompatibleQoSInfo = QoSRequestedIncompatibleQoSInfo


class SubscriptionEventCallbacks:
    def __init__(
        self,
        *,
        deadline: Callable[[Any], None] | None = None,
        incompatible_qos: Callable[[Any], None] | None = None,
        liveliness: Callable[[Any], None] | None = None,
        message_lost: Callable[[Any], None] | None = None,
        incompatible_type: Callable[[Any], None] | None = None,
        matched: Callable[[Any], None] | None = None,
        use_default_callbacks: bool = True,
    ) -> None:
        self.deadline = deadline
        self.incompatible_qos = incompatible_qos
        self.liveliness = liveliness
        self.message_lost = message_lost
        self.incompatible_type = incompatible_type
        self.matched = matched
        self.use_default_callbacks = use_default_callbacks


class PublisherEventCallbacks:
    def __init__(
        self,
        *,
        deadline: Callable[[Any], None] | None = None,
        liveliness: Callable[[Any], None] | None = None,
        incompatible_qos: Callable[[Any], None] | None = None,
        incompatible_type: Callable[[Any], None] | None = None,
        matched: Callable[[Any], None] | None = None,
        use_default_callbacks: bool = True,
    ) -> None:
        self.deadline = deadline
        self.liveliness = liveliness
        self.incompatible_qos = incompatible_qos
        self.incompatible_type = incompatible_type
        self.matched = matched
        self.use_default_callbacks = use_default_callbacks


class IncompatibleQoSReporter:
    """Counts one endpoint's incompatible-QoS events and reports each new one."""

    def __init__(self, callbacks: Any, default: Callable[[int], None]) -> None:
        self._callback = getattr(callbacks, "incompatible_qos", None)
        self._use_default = getattr(callbacks, "use_default_callbacks", True)
        self._default = default
        self._count = 0

    def report(self, policy_kind: int) -> None:
        self._count += 1
        if self._callback is not None:
            self._callback(QoSRequestedIncompatibleQoSInfo(self._count, 1, int(policy_kind)))
        elif self._use_default:
            self._default(policy_kind)
