"""The run queue on a private Redis: a queued job runs once on a worker that claims its record,
a delivery of a run that started (or ended) elsewhere is dropped, a job a worker cannot read
fails its run with a sentence, queueing with Redis down is a sentence, and the jobs a SIGKILLed
worker had fetched but not started go to another worker within ~10 s."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from sandbox.protocol import Clock
from server.runs.spec import NodeSpec, RunSpec
from server.store import runs as run_store
from server.workers.queue import (
    JobTaker,
    close_broker,
    declare_actor,
    enqueue,
    make_broker,
    make_worker,
    queued_count,
    requeuer,
)
from server.workers.seams import ExecutorUnavailableError
from server.workers.wire import RunJob, job_to_json
from tests.cluster.conftest import queued_run
from tests.waiting import wait_until

pytestmark = pytest.mark.slow
REQUEUE_WITHIN_S = 10.0  # [s] the bound for a killed worker's runs


def job_for(run_id: str, run_dir: Path) -> RunJob:
    spec = RunSpec(
        robot="crowbot",
        world="empty",
        nodes=(NodeSpec("controller", "print('hi')\n", "controller.py"),),
        clock=Clock.LOCKSTEP,
        duration_s=1.0,
    )
    return RunJob(run_id, "user", spec, str(run_dir / run_id), queued_wall_s=time.time())


class Executed:
    def __init__(self) -> None:
        self.jobs: list[RunJob] = []
        self.lock = threading.Lock()

    def __call__(self, job: RunJob) -> None:
        with self.lock:
            self.jobs.append(job)

    def ids(self) -> list[str]:
        with self.lock:
            return [job.run_id for job in self.jobs]


@pytest.fixture
def brokers(private_redis):
    """Brokers made by a test, closed after it (each holds Redis connections)."""
    made = []

    def make():
        made.append(make_broker(private_redis.url))
        return made[-1]

    yield make
    for broker in made:
        close_broker(broker)


@pytest.fixture
def workers(brokers):
    """Start a worker in this process: (broker, worker); stopped and closed after the test."""
    started = []

    def start(store, worker_id: str, execute, capacity: int = 2):
        broker = brokers()
        declare_actor(broker, JobTaker(store, worker_id, execute, requeuer(broker)))
        worker = make_worker(broker, capacity)
        worker.start()
        started.append(worker)
        return broker, worker

    yield start
    for worker in started:
        worker.stop(timeout=10_000)


def test_a_job_runs_once_on_the_worker_that_claims_it(brokers, workers, sqlite_store, tmp_path):
    executed = Executed()
    broker, _worker = workers(sqlite_store, "here:1", executed)
    run_id = queued_run(sqlite_store, tmp_path)
    job = job_for(run_id, tmp_path)
    enqueue(brokers(), job)
    wait_until(lambda: executed.ids() == [run_id], 20, "the worker executed the job")
    assert executed.jobs[0] == job  # the whole job crossed as JSON
    with sqlite_store.session() as db:
        assert run_store.get(db, run_id).state == "starting"  # claimed
    # The same job delivered again (a redelivery after a lost worker) is not run twice.
    enqueue(brokers(), job)
    wait_until(lambda: queued_count(broker) == 0, 20, "the duplicate was fetched")
    time.sleep(0.5)  # a second execution would show here: the wait is the test
    assert executed.ids() == [run_id]


def test_a_stopped_runs_job_is_dropped(brokers, workers, sqlite_store, tmp_path):
    executed = Executed()
    workers(sqlite_store, "here:2", executed)
    ended = queued_run(sqlite_store, tmp_path, state="interrupted")  # stopped while queued
    fresh = queued_run(sqlite_store, tmp_path)
    sender = brokers()
    enqueue(sender, job_for(ended, tmp_path))
    enqueue(sender, job_for(fresh, tmp_path))
    wait_until(lambda: fresh in executed.ids(), 20, "the fresh job ran")
    time.sleep(0.3)  # the other must not run: the wait is the test
    assert executed.ids() == [fresh]


def test_a_job_the_worker_cannot_read_fails_its_run_with_a_sentence(
    workers, sqlite_store, tmp_path
):
    executed = Executed()
    broker, _worker = workers(sqlite_store, "here:3", executed)
    run_id = queued_run(sqlite_store, tmp_path)
    data = job_to_json(job_for(run_id, tmp_path))
    data["wire"] = 999  # a web process of another RoboDojo version
    from dramatiq.message import Message

    broker.enqueue(Message(queue_name="runs", actor_name="execute_run", args=(data,),
                           kwargs={}, options={}))  # fmt: skip

    def failed() -> str:
        with sqlite_store.session() as db:
            record = run_store.get(db, run_id)
            return record.reason if record.state == "failed" else ""

    reason = wait_until(failed, 20, "the run failed")
    assert "same RoboDojo version" in reason
    assert executed.ids() == []


def test_queueing_with_redis_down_is_a_sentence(private_redis, brokers, tmp_path):
    broker = brokers()
    private_redis.stop()
    with pytest.raises(ExecutorUnavailableError, match="try again"):
        enqueue(broker, job_for("abc", tmp_path))


VICTIM = textwrap.dedent(
    """
    import sys, threading
    from pathlib import Path
    from server.workers.queue import declare_actor, make_broker, make_worker
    url, marker = sys.argv[1], Path(sys.argv[2])
    broker = make_broker(url)
    # Fetches a job and never acknowledges it, as a worker killed before it claimed the run.
    def hold(data):
        marker.write_text(data["run_id"])
        threading.Event().wait()
    declare_actor(broker, hold)
    make_worker(broker, 1).start()
    threading.Event().wait()
    """
)


def test_a_killed_workers_fetched_jobs_go_to_another_worker(
    private_redis, brokers, workers, sqlite_store, tmp_path
):
    marker = tmp_path / "fetched"
    victim = subprocess.Popen([sys.executable, "-c", VICTIM, private_redis.url, str(marker)],
                              cwd=Path(__file__).resolve().parents[2])  # fmt: skip
    try:
        run_id = queued_run(sqlite_store, tmp_path)
        enqueue(brokers(), job_for(run_id, tmp_path))
        wait_until(marker.exists, 60, "the victim worker fetched the job")
        os.kill(victim.pid, signal.SIGKILL)
        victim.wait(10)
        killed_at = time.monotonic()
        executed = Executed()
        workers(sqlite_store, "here:4", executed)
        wait_until(lambda: executed.ids() == [run_id], REQUEUE_WITHIN_S + 20,
                   "another worker ran the killed worker's job")  # fmt: skip
        took_s = time.monotonic() - killed_at
        print(f"requeued and started {took_s:.1f} s after the SIGKILL")
        assert took_s < REQUEUE_WITHIN_S + 5, f"requeued after {took_s:.1f} s"
    finally:
        if victim.poll() is None:
            victim.kill()
            victim.wait(10)
