"""rclpy.guard_condition.GuardCondition: a callback an executor runs after trigger()."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


class GuardCondition:
    def __init__(
        self, callback: Callable[[], Any] | None, callback_group: Any, context: Any = None
    ) -> None:
        self.callback = callback
        self.callback_group = callback_group
        self._triggered = False
        self._destroyed = False

    def trigger(self) -> None:
        self._triggered = True

    def destroy(self) -> None:
        self._destroyed = True

    def _ready(self) -> bool:
        return self._triggered and not self._destroyed

    def _due_ns(self) -> int | None:
        return None

    def _take(self) -> Callable[[], Any] | None:
        self._triggered = False
        return self.callback
