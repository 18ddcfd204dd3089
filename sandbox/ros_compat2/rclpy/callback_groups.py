"""rclpy.callback_groups: which callbacks may run while another is running.

As rclpy/callback_groups.py: a MutuallyExclusiveCallbackGroup lets one of its callbacks run at
a time, a ReentrantCallbackGroup any number. On a RoboDojo node callbacks run one at a time on
the node's thread; a group matters when a callback blocks (Client.call, or
spin_until_future_complete inside a callback of a MultiThreadedExecutor): then other callbacks
run meanwhile only where their group allows, as rclpy's worker threads would.
"""

from __future__ import annotations

import weakref
from typing import Any


class CallbackGroup:
    """Base class: can_execute, beginning_execution, ending_execution."""

    def __init__(self) -> None:
        self.entities: set[weakref.ReferenceType[Any]] = set()

    def add_entity(self, entity: Any) -> None:
        self.entities.add(weakref.ref(entity))

    def has_entity(self, entity: Any) -> bool:
        return weakref.ref(entity) in self.entities

    def can_execute(self, entity: Any) -> bool:
        raise NotImplementedError()

    def beginning_execution(self, entity: Any) -> bool:
        raise NotImplementedError()

    def ending_execution(self, entity: Any) -> None:
        raise NotImplementedError()


class ReentrantCallbackGroup(CallbackGroup):
    """Callbacks of this group may run while others of it are running."""

    def can_execute(self, entity: Any) -> bool:
        return True

    def beginning_execution(self, entity: Any) -> bool:
        return True

    def ending_execution(self, entity: Any) -> None:
        pass


class MutuallyExclusiveCallbackGroup(CallbackGroup):
    """One callback of this group at a time."""

    def __init__(self) -> None:
        super().__init__()
        self._active_entity: Any = None

    def can_execute(self, entity: Any) -> bool:
        return self._active_entity is None

    def beginning_execution(self, entity: Any) -> bool:
        if self._active_entity is None:
            self._active_entity = entity
            return True
        return False

    def ending_execution(self, entity: Any) -> None:
        self._active_entity = None
