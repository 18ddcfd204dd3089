"""The cluster's job queue: runs are Dramatiq messages on Redis (issue 16).

Why Dramatiq (read in its source, dramatiq 2.2 `brokers/redis.py` and `redis/dispatch.lua`):
a fetched message sits in a per-worker "acks" set until the actor returns, so a job is
acknowledged late; every broker command stamps the worker's heartbeat in a sorted set, and the
queue's maintenance puts the unacked messages of a worker unseen for `heartbeat_timeout` back on
their queue. There is no visibility timeout: a run of ten minutes is never handed to a second
worker because it is long (Celery over Redis redelivers what is unacked past its visibility
timeout). A worker embeds as `dramatiq.Worker(broker, worker_threads=N)` in our own process.

    broker = make_broker("redis://127.0.0.1:6379/0")
    enqueue(broker, job)                                  # web side: RunJob -> queue
    declare_actor(broker, JobTaker(store, worker_id, host.execute))   # worker side

Messages are JSON (Dramatiq's JSONEncoder, set explicitly): whoever can write to Redis must not
thereby run code on a worker. A job runs at most once: the actor claims the run's record (state
"created" -> "starting", atomically in SQL) before executing it, so a redelivered job of a run
that started elsewhere is dropped.
"""

from __future__ import annotations

import logging
import re
import threading
import time
from collections.abc import Callable
from typing import Any

import dramatiq
import redis
from dramatiq.brokers.redis import RedisBroker
from dramatiq.encoder import JSONEncoder
from dramatiq.message import Message
from dramatiq.middleware import Retries

from server.runs.state import RunState
from server.store import runs as run_store
from server.store.db import Store
from server.workers.seams import ExecutorUnavailableError
from server.workers.wire import RunJob, WireError, job_from_json, job_to_json

log = logging.getLogger("robodojo.workers.queue")

NAMESPACE = "robodojo"  # every Dramatiq key in Redis starts with "robodojo:"
RUNS_QUEUE = "runs"  # simulated runs: any worker takes them
ROBOT_QUEUE_PREFIX = "robot."  # robot.<name>: only the worker holding that robot consumes it
ACTOR_NAME = "execute_run"

# Limits of the queue, each with why.
HEARTBEAT_TIMEOUT_MS = 5_000  # [ms] a worker unseen this long is dead: its fetched, unstarted
# jobs go back to the queue (with the maintenance below: within ~6 s of a SIGKILL, not 60 s)
MAINTENANCE_CHANCE = 250_000  # of a million broker commands run the requeue maintenance; every
# idle worker polls about once a second, so a dead worker's jobs wait ~1 s past the timeout
HEARTBEAT_PERIOD_S = 1.0  # [s] a busy worker fetches nothing (its prefetch is full), so a
# thread stamps its heartbeat: without it a worker running long runs would look dead
WORKER_POLL_MS = 500  # [ms] longest idle poll of a consumer (Dramatiq's worker_timeout)
SOCKET_TIMEOUT_S = 5.0  # [s] a Redis command that takes longer means Redis is gone
CONNECT_TIMEOUT_S = 2.0  # [s] connecting to Redis
CLAIM_RETRY_DELAY_S = 2.0  # [s] a job whose record could not be read goes back after this

_QUEUE_NAME = re.compile(r"[a-zA-Z_][a-zA-Z0-9._-]*")  # what Dramatiq accepts as a queue name


def redis_client(url: str) -> redis.Redis:
    """A Redis client with timeouts: a dead Redis is an error within seconds, never a hang."""
    return redis.Redis.from_url(
        url,
        socket_timeout=SOCKET_TIMEOUT_S,
        socket_connect_timeout=CONNECT_TIMEOUT_S,
        health_check_interval=10,
    )


def make_broker(url: str) -> RedisBroker:
    """The broker every web process and worker of one lab shares (same URL, same namespace).
    No TimeLimit middleware (a run has its own duration limit) and no retries (a run that
    failed is the student's result, not something to do again)."""
    dramatiq.set_encoder(JSONEncoder())  # never pickle
    broker = RedisBroker(
        client=redis_client(url),
        namespace=NAMESPACE,
        heartbeat_timeout=HEARTBEAT_TIMEOUT_MS,
        maintenance_chance=MAINTENANCE_CHANCE,
        middleware=[Retries(max_retries=0)],
    )
    return broker


def close_broker(broker: RedisBroker) -> None:
    """Close the broker's Redis connections (at shutdown; its worker stopped first)."""
    broker.client.close()
    broker.client.connection_pool.disconnect()


def queue_for(job: RunJob) -> str:
    """`runs` for a simulated run; `robot.<name>` for a bench robot's run."""
    if job.hardware is None:
        return RUNS_QUEUE
    name = ROBOT_QUEUE_PREFIX + job.hardware
    if not _QUEUE_NAME.fullmatch(name):
        raise WireError(
            f"robot name {job.hardware!r} cannot name a queue; rename it with letters, digits, "
            "'.', '_' or '-' only"
        )
    return name


def robot_queue(robot: str) -> str:
    return ROBOT_QUEUE_PREFIX + robot


def enqueue(broker: RedisBroker, job: RunJob) -> None:
    """Queue a run for the workers; ExecutorUnavailableError (a sentence) when Redis is down."""
    message = Message(
        queue_name=queue_for(job),
        actor_name=ACTOR_NAME,
        args=(job_to_json(job),),
        kwargs={},
        options={},
    )
    try:
        broker.enqueue(message)
    except redis.RedisError as error:
        raise ExecutorUnavailableError(
            f"the run queue cannot be reached ({_short(error)}); the run was not started: try "
            "again in a minute, and tell your instructor if it keeps happening"
        ) from None


def queued_count(broker: RedisBroker, queue_name: str = RUNS_QUEUE) -> int:
    """Jobs waiting on a queue (not yet fetched by a worker)."""
    return int(broker.client.llen(f"{NAMESPACE}:{queue_name}"))


# ------------------------------------------------------------------------------ worker side
class JobTaker:
    """The actor's body: decode the job, claim its run, execute it. Never raises: a job that
    fails is the run's failure (stored), not a message for Dramatiq to dead-letter."""

    def __init__(
        self,
        store: Store,
        worker_id: str,
        execute: Callable[[RunJob], None],
        requeue: Callable[[dict[str, Any]], None] | None = None,
    ) -> None:
        self.store = store
        self.worker_id = worker_id
        self.execute = execute
        self.requeue = requeue  # puts a job back when its record could not be read

    def __call__(self, data: dict[str, Any]) -> None:
        try:
            job = job_from_json(data)
        except WireError as error:
            self._refuse(data, error)
            return
        try:
            claimed = self._claim(job.run_id)
        except Exception as error:  # the database is unreachable: someone else may take it
            log.warning("run %s: could not claim it (%s); back on the queue", job.run_id, error)
            time.sleep(CLAIM_RETRY_DELAY_S)
            if self.requeue is not None:
                self.requeue(data)
            return
        if not claimed:
            log.info("run %s: already taken or ended; this delivery is dropped", job.run_id)
            return
        try:
            self.execute(job)
        except Exception as error:  # execute() stores its own failures; this is a last guard
            log.exception("run %s raised out of the worker's execute()", job.run_id)
            self._fail(job.run_id, f"failed: internal error on the worker ({error!r})")

    def _claim(self, run_id: str) -> bool:
        with self.store.session() as db:
            return run_store.claim(db, run_id, self.worker_id)

    def _refuse(self, data: Any, error: WireError) -> None:
        run_id = data.get("run_id") if isinstance(data, dict) else None
        log.error("a job this worker cannot read was dropped: %s", error)
        if isinstance(run_id, str):
            self._fail(run_id, f"failed: the worker could not read this run's job ({error})")

    def _fail(self, run_id: str, reason: str) -> None:
        try:
            with self.store.session() as db:
                run_store.end_if_active(db, run_id, str(RunState.FAILED), reason)
        except Exception:
            log.exception("run %s: could not store its failure", run_id)


def declare_actor(broker: RedisBroker, taker: Callable[[dict[str, Any]], None]) -> dramatiq.Actor:
    """Register the one actor on this worker's broker (queue `runs`; robot queues reach it by
    the message's queue name)."""
    return dramatiq.Actor(
        taker,
        broker=broker,
        actor_name=ACTOR_NAME,
        queue_name=RUNS_QUEUE,
        priority=0,
        options={"max_retries": 0},
    )


def requeuer(broker: RedisBroker) -> Callable[[dict[str, Any]], None]:
    """Puts a job's JSON back on its queue (for JobTaker when the database is away)."""

    def requeue(data: dict[str, Any]) -> None:
        try:
            enqueue(broker, job_from_json(data))
        except (WireError, ExecutorUnavailableError) as error:
            log.error("a job could not go back on the queue: %s", error)

    return requeue


class Heartbeat:
    """Stamps this worker's Dramatiq heartbeat every HEARTBEAT_PERIOD_S while it lives, even
    when every slot is busy (its consumers then fetch nothing, and fetching is what stamps it).
    Each stamp is a broker command, so it also gives the requeue maintenance its chance."""

    def __init__(self, broker: RedisBroker, queues: Callable[[], set[str]]) -> None:
        self.broker = broker
        self.queues = queues
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="dramatiq-heartbeat", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)

    def _loop(self) -> None:
        while not self._stop.wait(HEARTBEAT_PERIOD_S):
            for queue_name in sorted(self.queues()):
                try:
                    self.broker.do_qsize(queue_name)  # any dispatch stamps the heartbeat
                except redis.RedisError:
                    break  # Redis is away; Dramatiq's consumers say so and reconnect


def make_worker(broker: RedisBroker, capacity: int, robots: tuple[str, ...] = ()):
    """A Dramatiq Worker taking at most `capacity` simulated runs at once (its prefetch is its
    capacity: jobs it fetched but cannot start yet would wait here instead of on another
    worker), plus one thread per bench robot it holds (a robot runs one run at a time)."""
    from dramatiq import Worker

    for robot in robots:
        broker.declare_queue(robot_queue(robot))
    worker = Worker(broker, worker_threads=capacity + len(robots), worker_timeout=WORKER_POLL_MS)
    worker.queue_prefetch = capacity
    return worker


def pause_taking(worker) -> None:
    """Stop fetching jobs without waiting for running ones (Worker.pause() waits for every
    thread to finish its job: a ten-minute run). Prefetched jobs still start."""
    for consumer in list(worker.consumers.values()):
        consumer.pause()


def resume_taking(worker) -> None:
    for consumer in list(worker.consumers.values()):
        consumer.resume()


def _short(error: Exception) -> str:
    text = str(error).strip() or type(error).__name__
    return text if len(text) <= 160 else text[:157] + "..."
