"""Who is analysed when (server/editor/gate.py): one request per student at a time, a bounded
queue behind the turns, a student's newer request of a kind in the place of the older, and a
sentence (the route's 429) for every request that gets no turn."""

from __future__ import annotations

import dataclasses
import threading
from concurrent.futures import ThreadPoolExecutor

import pytest

from server.editor.gate import EditorBusy, EditorGate
from server.editor.limits import LIMITS
from tests.waiting import wait_until

WAIT_S = 10.0  # [s] for a thread to reach the gate on a loaded machine


def gate(**limits) -> EditorGate:
    return EditorGate(dataclasses.replace(LIMITS, **{"queue_wait_s": WAIT_S, **limits}))


class Holder:
    """A request that holds its turn until released."""

    def __init__(self, gate: EditorGate, user: str, kind: str = "complete") -> None:
        self.entered, self.release = threading.Event(), threading.Event()
        self.refused: EditorBusy | None = None
        self.thread = threading.Thread(target=self._run, args=(gate, user, kind), daemon=True)
        self.thread.start()

    def _run(self, gate: EditorGate, user: str, kind: str) -> None:
        try:
            with gate.turn(user, kind):
                self.entered.set()
                self.release.wait(WAIT_S)
        except EditorBusy as error:
            self.refused = error

    def done(self) -> bool:
        self.release.set()
        self.thread.join(WAIT_S)
        return not self.thread.is_alive()


def test_a_students_second_request_waits_for_the_first_while_another_student_goes_on():
    the_gate = gate(concurrent_requests=2)
    first = Holder(the_gate, "ada")
    assert first.entered.wait(WAIT_S)
    second = Holder(the_gate, "ada", "lint")
    wait_until(lambda: the_gate.waiting() == 1, WAIT_S, "ada's second request waits")
    other = Holder(the_gate, "bob")
    assert other.entered.wait(WAIT_S)  # the free turn is bob's, not ada's second
    assert not second.entered.is_set()
    assert first.done()
    assert second.entered.wait(WAIT_S)
    assert second.done() and other.done()


def test_a_newer_request_of_the_same_kind_takes_the_older_ones_place():
    the_gate = gate(concurrent_requests=1)
    running = Holder(the_gate, "ada", "lint")
    assert running.entered.wait(WAIT_S)
    older = Holder(the_gate, "ada", "complete")
    wait_until(lambda: the_gate.waiting() == 1, WAIT_S, "the older completion waits")
    newer = Holder(the_gate, "ada", "complete")
    older.thread.join(WAIT_S)
    assert "a newer request from this editor took this one's place" in str(older.refused)
    assert the_gate.waiting() == 1
    assert running.done()
    assert newer.entered.wait(WAIT_S) and newer.done()


def test_a_full_queue_is_answered_at_once_with_a_sentence():
    the_gate = gate(concurrent_requests=1, queue_length=2)
    running = Holder(the_gate, "ada")
    assert running.entered.wait(WAIT_S)
    waiting = [Holder(the_gate, name) for name in ("bob", "cy")]
    wait_until(lambda: the_gate.waiting() == 2, WAIT_S, "two requests wait")
    with (
        pytest.raises(EditorBusy, match="busy with other students' files"),
        the_gate.turn("dee", "complete"),
    ):
        pass
    assert running.done() and all(holder.done() for holder in waiting)


def test_a_request_that_waits_too_long_is_answered_with_a_sentence():
    the_gate = gate(concurrent_requests=1, queue_wait_s=0.2)
    running = Holder(the_gate, "ada")
    assert running.entered.wait(WAIT_S)
    with (
        pytest.raises(EditorBusy, match=r"waited 0.2 s for its turn"),
        the_gate.turn("bob", "complete"),
    ):
        pass
    assert the_gate.waiting() == 0
    assert running.done()


def test_many_students_at_once_never_exceed_the_turns():
    the_gate = gate(concurrent_requests=2, queue_length=100)
    inside, most = [0], [0]
    lock = threading.Lock()

    def request(user: str) -> None:
        with the_gate.turn(user, "complete"):
            with lock:
                inside[0] += 1
                most[0] = max(most[0], inside[0])
            with lock:
                inside[0] -= 1

    with ThreadPoolExecutor(16) as pool:
        list(pool.map(request, [f"student{i % 8}" for i in range(200)]))
    assert most[0] <= 2 and the_gate.waiting() == 0
