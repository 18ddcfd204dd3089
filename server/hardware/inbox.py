"""`ReceivedInbox`: what a real robot sent since its run last looked, handed from the link's I/O
thread (rosserial's event loop, the Create driver's reader) to the run's loop.

    inbox.push(topic, message, received_s)   # the I/O thread, as each message arrives
    inbox.take()                             # the run's loop: [(topic, message, received_s)]
    inbox.clear()                            # a run starts: what came before is not its

Bounded: when no run is reading (or one falls behind), the oldest messages go first, so the
newest readings are always what a run gets.
"""

from __future__ import annotations

import threading
from collections import deque

Received = tuple[str, object, float]  # topic, message, monotonic receive time [s]


class ReceivedInbox:
    def __init__(self, max_messages: int) -> None:
        self._messages: deque[Received] = deque(maxlen=max_messages)
        self._lock = threading.Lock()

    def push(self, topic: str, message: object, received_s: float) -> None:
        with self._lock:
            self._messages.append((topic, message, received_s))

    def take(self) -> list[Received]:
        """Everything since the last call, oldest first."""
        with self._lock:
            taken = list(self._messages)
            self._messages.clear()
        return taken

    def clear(self) -> None:
        with self._lock:
            self._messages.clear()
