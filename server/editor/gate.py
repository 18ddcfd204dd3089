"""Who is analysed when: at most `concurrent_requests` requests at once, at most one of them a
given student's, and a bounded queue behind them (limits.py says why each number).

A student's newer request of the same kind (a completion while their previous completion still
waits) takes the older one's place in the queue, and the older is answered with `EditorBusy`:
the editor asks again as the student types, and only the newest text matters. A request that
finds the queue full, or waits longer than `queue_wait_s`, is answered with `EditorBusy` too
(the route's 429); nothing waits without bound.

    with gate.turn(user_id, "complete"):      # EditorBusy, or the turn
        ... analyse ...
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from enum import StrEnum

from server.editor.limits import EditorLimits


class EditorBusy(RuntimeError):
    """No turn for this request; the message is a sentence saying what to do."""


class TicketState(StrEnum):
    WAITING = "waiting"
    GRANTED = "granted"
    SUPERSEDED = "superseded"  # a newer request of the same student and kind took its place


@dataclass
class _Ticket:
    user: str
    kind: str
    state: TicketState = TicketState.WAITING


class EditorGate:
    def __init__(self, limits: EditorLimits) -> None:
        self.limits = limits
        self._changed = threading.Condition()
        self._running: set[str] = set()  # users with a request being analysed
        self._waiting: list[_Ticket] = []  # in arrival order

    @contextlib.contextmanager
    def turn(self, user: str, kind: str) -> Iterator[None]:
        self._wait_for_turn(user, kind)
        try:
            yield
        finally:
            with self._changed:
                self._running.discard(user)
                self._grant()

    def _wait_for_turn(self, user: str, kind: str) -> None:
        limits = self.limits
        with self._changed:
            ticket = _Ticket(user, kind)
            for older in self._waiting:
                if older.user == user and older.kind == kind:
                    older.state = TicketState.SUPERSEDED
            self._waiting = [t for t in self._waiting if t.state is TicketState.WAITING]
            if len(self._waiting) >= limits.queue_length:
                self._changed.notify_all()
                raise EditorBusy(
                    "the editor's analysis is busy with other students' files; it answers "
                    "again in a moment"
                )
            self._waiting.append(ticket)
            self._grant()
            deadline = time.monotonic() + limits.queue_wait_s
            while ticket.state is TicketState.WAITING:
                left_s = deadline - time.monotonic()
                if left_s <= 0:
                    self._waiting.remove(ticket)
                    raise EditorBusy(
                        "the editor's analysis is busy (this request waited "
                        f"{limits.queue_wait_s:g} s for its turn); it answers again in a moment"
                    )
                self._changed.wait(left_s)
            if ticket.state is TicketState.SUPERSEDED:
                raise EditorBusy(
                    "a newer request from this editor took this one's place; its answer comes "
                    "instead"
                )

    def _grant(self) -> None:
        """Give free turns to the first waiting requests whose student has none running."""
        granted = False
        for ticket in list(self._waiting):
            if len(self._running) >= self.limits.concurrent_requests:
                break
            if ticket.user in self._running:
                continue
            ticket.state = TicketState.GRANTED
            self._running.add(ticket.user)
            self._waiting.remove(ticket)
            granted = True
        if granted or self._waiting:
            self._changed.notify_all()

    def waiting(self) -> int:
        """Requests waiting for their turn now (for the lab's status and the tests)."""
        with self._changed:
            return len(self._waiting)
