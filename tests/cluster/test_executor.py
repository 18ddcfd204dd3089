"""The cluster's executor against a private Redis, with a stand-in for a worker's RunHost (it
publishes batches through a RedisOutlet and obeys commands through a CommandListener): a
queued run stopped before any worker took it ends interrupted and is never run, commands and
refusals reach the run, status and feed follow it on demand, a lost worker's run is ended for
its viewers, and a queued run Redis forgot fails with a sentence."""

from __future__ import annotations

import threading
import time

import pytest

from server.runs.commands import Button, CommandError, Pause, Stop
from server.runs.state import RunState
from server.store import runs as run_store
from server.store import workers as roster
from server.store.workers import WorkerReport
from server.workers import cluster as cluster_module
from server.workers.cluster import QueueExecutor, queued_key
from server.workers.queue import JobTaker, declare_actor, make_broker, make_worker, requeuer
from server.workers.redis_live import CommandListener, RedisOutlet, run_key
from server.workers.wire import CommandAnswer, LiveBatch, RunJob
from tests.cluster.conftest import queued_run
from tests.cluster.test_queue import job_for
from tests.cluster.test_redis_live import status
from tests.waiting import wait_until

pytestmark = pytest.mark.slow


class FakeMirror:
    """What the executor gives the web side's mirror, in order."""

    def __init__(self) -> None:
        self.batches: dict[str, list[LiveBatch]] = {}
        self.ends: dict[str, tuple[RunState, str]] = {}
        self.lock = threading.Lock()

    def apply(self, batch: LiveBatch) -> None:
        with self.lock:
            self.batches.setdefault(batch.run_id, []).append(batch)

    def expect(self, run_id: str) -> None:
        with self.lock:
            self.batches.setdefault(run_id, [])

    def feed(self, run_id: str):
        with self.lock:
            return self.batches.get(run_id)

    def status(self, run_id: str):
        with self.lock:
            found = [b.status for b in self.batches.get(run_id, []) if b.status is not None]
        return found[-1] if found else None

    def end(self, run_id: str, state: RunState, reason: str) -> bool:
        with self.lock:
            self.ends[run_id] = (state, reason)
        return True


class StandInHost:
    """A worker's RunHost reduced to its traffic: 'runs' until stopped, refuses Pause."""

    def __init__(self, client, worker_id: str) -> None:
        self.outlet = RedisOutlet(client)
        self.commands = CommandListener(client, self.answer)
        self.worker_id = worker_id
        self.stops: dict[str, threading.Event] = {}
        self.executed: list[str] = []

    def answer(self, request) -> CommandAnswer:
        if self.stops[request.run_id].is_set():  # over: not held here any more
            return CommandAnswer(request.request_id, False)
        if isinstance(request.command, Pause):
            return CommandAnswer(request.request_id, False, "a realtime run cannot pause")
        if isinstance(request.command, Stop):
            self.stops[request.run_id].set()
        return CommandAnswer(request.request_id, True)

    def execute(self, job: RunJob) -> None:
        self.executed.append(job.run_id)
        self.stops[job.run_id] = threading.Event()
        self.commands.hold(job.run_id)
        self.outlet.publish(LiveBatch(job.run_id, status=status(job.run_id)))
        while not self.stops[job.run_id].wait(0.05):
            self.outlet.publish(LiveBatch(job.run_id, events=({"type": "log", "line": "tick"},)))
        end = {"type": "state", "state": "interrupted", "reason": "interrupted: stopped"}
        self.outlet.publish(LiveBatch(job.run_id, events=(end,), final=True))
        self.commands.release(job.run_id)


@pytest.fixture
def executor(private_redis, sqlite_store):
    mirror = FakeMirror()
    made = QueueExecutor(sqlite_store, private_redis.url, mirror)
    made.fake_mirror = mirror  # type: ignore[attr-defined]
    yield made
    made.shutdown(5.0)


@pytest.fixture
def stand_in(private_redis, sqlite_store, executor):
    host = StandInHost(executor.client, "stand-in:1")
    host.commands.start()
    broker = make_broker(private_redis.url)
    taker = JobTaker(sqlite_store, host.worker_id, host.execute, requeuer(broker))
    declare_actor(broker, taker)
    worker = make_worker(broker, 2)
    worker.start()
    yield host
    for event in host.stops.values():
        event.set()
    worker.stop(timeout=10_000)
    host.commands.stop()
    broker.client.close()


def test_a_run_stopped_while_queued_ends_interrupted_and_never_runs(
    executor, sqlite_store, tmp_path
):
    run_id = queued_run(sqlite_store, tmp_path)
    assert executor.command(run_id, Stop("stopped by the teacher"))
    with sqlite_store.session() as db:
        record = run_store.get(db, run_id)
    assert (record.state, record.reason) == ("interrupted", "interrupted: stopped by the teacher")
    assert executor.fake_mirror.ends[run_id][0] == RunState.INTERRUPTED
    assert not executor.command(run_id, Button(pressed=True))  # over: nothing to press


def test_commands_status_and_feed_reach_a_run_on_a_worker(
    executor, stand_in, sqlite_store, tmp_path
):
    run_id = queued_run(sqlite_store, tmp_path)
    executor.submit(job_for(run_id, tmp_path))
    wait_until(lambda: executor.is_running(run_id), 20, "the worker started the run")
    assert executor.status(run_id).state == "running"
    assert executor.feed(run_id) is not None
    wait_until(lambda: len(executor.fake_mirror.batches[run_id]) > 3, 10, "batches followed")
    assert executor.command(run_id, Button(pressed=True))
    with pytest.raises(CommandError, match="cannot pause"):
        executor.command(run_id, Pause())
    assert executor.command(run_id, Stop("stopped by the test"))
    wait_until(lambda: executor.fake_mirror.batches[run_id][-1].final, 10, "the final batch")
    wait_until(lambda: not executor.is_running(run_id), 10, "it is no longer running")
    assert stand_in.executed == [run_id]
    assert not executor.command(run_id, Button(pressed=True))


def test_a_run_claimed_but_not_yet_published_can_be_watched(executor, sqlite_store, tmp_path):
    # Between a worker's claim and its first batch (the run being built, its nodes starting:
    # seconds on a loaded machine) a viewer must get a feed, not "the run is over".
    run_id = queued_run(sqlite_store, tmp_path)
    with sqlite_store.session() as db:
        assert run_store.claim(db, run_id, "busy:1")
        assert run_store.get(db, run_id).state == "starting"
    assert not executor.client.exists(run_key(run_id))
    assert executor.feed(run_id) is not None
    ended = queued_run(sqlite_store, tmp_path, state="finished")
    assert executor.feed(ended) is None  # over, and Redis knows nothing of it: no feed


def test_a_lost_workers_run_is_ended_for_its_viewers(executor, sqlite_store, tmp_path):
    run_id = queued_run(sqlite_store, tmp_path)
    with sqlite_store.session() as db:
        roster.report(db, WorkerReport("gone:9", "gone", 1, 1, "ready"), now=time.time() - 60)
        assert run_store.claim(db, run_id, "gone:9")
    RedisOutlet(executor.client).publish(LiveBatch(run_id, status=status(run_id)))
    assert executor.feed(run_id) is not None  # someone watches it here

    def heard() -> bool:
        batches = executor.fake_mirror.batches[run_id]
        return run_id in executor.fake_mirror.ends or any(b.final for b in batches)

    wait_until(heard, 15, "the viewers heard of the end")
    with sqlite_store.session() as db:
        record = run_store.get(db, run_id)
    assert (record.state, record.reason) == ("failed", roster.WORKER_LOST)
    assert not executor.is_running(run_id)


def test_a_queued_run_redis_forgot_fails_with_a_sentence(
    executor, sqlite_store, tmp_path, monkeypatch
):
    monkeypatch.setattr(cluster_module, "QUEUE_LOST_AFTER_S", 0.5)
    remembered = queued_run(sqlite_store, tmp_path)
    executor.client.set(queued_key(remembered), 1)
    forgotten = queued_run(sqlite_store, tmp_path)  # as if Redis restarted since it was queued

    def state(run_id: str) -> str:
        with sqlite_store.session() as db:
            return run_store.get(db, run_id).state

    wait_until(lambda: state(forgotten) == "failed", 15, "the forgotten run failed")
    with sqlite_store.session() as db:
        assert "start it again" in run_store.get(db, forgotten).reason
    assert state(remembered) == "created"
