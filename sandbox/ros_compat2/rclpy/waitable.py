"""rclpy.waitable: the base for entities an executor serves besides timers, subscriptions,
clients and services (rclpy.action builds on it).

Here a Waitable tells the executor, by these methods, when it has work:
- `is_ready(wait_set=None) -> bool`, `take_data() -> data`, `execute(data)` (a function or a
  coroutine function), as in rclpy;
- optional `_wake_topics() -> set[str]` (bus topics whose messages should wake the node) and
  `_due_ns() -> int | None` (a run time it must wake at).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


class NumberOfEntities:
    def __init__(
        self,
        num_subs: int = 0,
        num_gcs: int = 0,
        num_timers: int = 0,
        num_clients: int = 0,
        num_services: int = 0,
        num_events: int = 0,
    ) -> None:
        self.num_subscriptions = num_subs
        self.num_guard_conditions = num_gcs
        self.num_timers = num_timers
        self.num_clients = num_clients
        self.num_services = num_services
        self.num_events = num_events


class Waitable:
    def __init__(self, callback_group: Any) -> None:
        self.callback_group = callback_group
        self.callback_group.add_entity(self)

    def is_ready(self, wait_set: Any = None) -> bool:
        raise NotImplementedError("Must be implemented by subclass")

    def take_data(self) -> Any:
        raise NotImplementedError("Must be implemented by subclass")

    async def execute(self, taken_data: Any) -> None:
        raise NotImplementedError("Must be implemented by subclass")

    def get_num_entities(self) -> NumberOfEntities:
        return NumberOfEntities()

    def add_to_wait_set(self, wait_set: Any) -> None:
        pass

    def destroy(self) -> None:
        pass

    def __enter__(self) -> Waitable:
        return self

    def __exit__(self, *exc_info: object) -> None:
        pass

    # ------------------------------------------------------------------ executor side
    def _ready(self) -> bool:
        return bool(self.is_ready(None))

    def _take(self) -> Callable[[], Any] | None:
        data = self.take_data()
        execute = self.execute
        return lambda: execute(data)  # a coroutine's result runs as a task of the executor
