"""What a node has published since it last yielded, with rospy's publisher queues.

A rospy Publisher hands messages to a queue that a writer thread drains; with `queue_size=N`
the queue keeps the newest N and drops the oldest. A RoboDojo node has one thread, and its
messages leave when it yields, so the outbox applies the queue per *burst*: what one callback,
or the main loop between two waits, publishes. In rospy callbacks run as their messages arrive,
spread out in time, and the writer drains between them; within one burst it has no time to.
"""

from __future__ import annotations

from sandbox.protocol import Envelope


class Outbox:
    def __init__(self) -> None:
        self._slots: list[Envelope | None] = []  # None: dropped from a full queue
        self._by_topic: dict[tuple[str, int], list[int]] = {}  # (topic, burst) -> slots
        self._burst = 0

    def new_burst(self) -> None:
        """A callback starts, or the main loop goes on after a wait."""
        self._burst += 1

    def add(self, envelope: Envelope, queue_size: int | None) -> None:
        """Queue one message; keep at most `queue_size` of its topic's in this burst (None or
        0: all of them, as rospy's synchronous and unbounded publishers)."""
        key = (envelope.topic, self._burst)
        indexes = self._by_topic.get(key)
        if indexes is None:
            indexes = self._by_topic[key] = []
        indexes.append(len(self._slots))
        self._slots.append(envelope)
        if queue_size and len(indexes) > queue_size:
            self._slots[indexes.pop(0)] = None

    def take(self) -> list[Envelope]:
        """Everything queued, in publication order, and empty the outbox."""
        sent = [envelope for envelope in self._slots if envelope is not None]
        self._slots, self._by_topic = [], {}
        return sent
