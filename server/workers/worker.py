"""One worker process of the cluster (`robodojo worker`, issue 16): a Dramatiq worker taking run
jobs from Redis, a RunHost executing them (state, results and judging into the shared
database; live traffic out through a RedisOutlet), a command listener for the runs it holds,
and a roster thread that reports it every REPORT_PERIOD_S, reaps lost workers' runs, and stops
taking jobs while the database cannot be reached (and says so).

    process = WorkerProcess(settings, capacity=8)
    process.run()          # until SIGTERM/SIGINT; its runs are stopped cleanly first
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import os
import signal
import socket
import threading
import time

from sandbox.launcher import Launcher
from server.runs.commands import CommandError
from server.runs.state import RunState
from server.service.hardware import HardwareHub
from server.sim.registry import topic_types
from server.store import robots as inventory
from server.store import workers as roster
from server.store.db import Store
from server.workers import queue
from server.workers.bench import BenchDesk
from server.workers.cluster import queued_key, worker_key
from server.workers.redis_live import CommandListener, RedisOutlet, publish_end
from server.workers.wire import CommandAnswer, CommandRequest, RunJob

log = logging.getLogger("robodojo.worker")
# Threads a bench worker keeps beyond its capacity and one per robot of the inventory at its
# start, for robots registered later (simulated runs never take them: the `runs` queue
# prefetches no more than the capacity).
BENCH_SPARE_THREADS = 4


def worker_id() -> str:
    """host:pid, as the runs table and the admin page show it."""
    return f"{socket.gethostname()}:{os.getpid()}"


class WorkerProcess:
    def __init__(
        self, settings, capacity: int, launcher: Launcher | None = None, bench: bool = False
    ) -> None:
        from server.workers.host import RunHost  # the worker side of the seam (runhost)

        if not settings.redis_url:
            raise ValueError("a worker needs --redis-url (the queue's Redis)")
        self.settings = settings
        self.capacity = capacity
        self.id = worker_id()
        self.host_name = socket.gethostname()
        self.started_at = time.time()
        self.store = Store.open(settings.store_url)
        self.client = queue.redis_client(settings.redis_url)
        self.broker = queue.make_broker(settings.redis_url)
        self.own_launcher = launcher is None
        self.launcher = launcher or Launcher(
            pool_size=settings.sandbox_pool,
            unsafe_no_sandbox=settings.unsafe_no_sandbox,
            message_types=topic_types(),
        )
        self.outlet = RedisOutlet(self.client)
        # A bench worker (`--rosserial-port`) holds the robots' connections and runs their runs.
        self.hub = HardwareHub(self.store, settings) if bench else None
        extra = {"hardware": self.hub} if self.hub is not None else {}
        self.host = RunHost(self.store, settings, self.launcher, self.outlet, self.id, **extra)
        self.commands = CommandListener(self.client, self._answer)
        taker = queue.JobTaker(self.store, self.id, self._execute, queue.requeuer(self.broker))
        queue.declare_actor(self.broker, taker)
        # A robot's queue is taken when the robot connects here (`_take_robot`), never before:
        # a second bench worker must not take the runs of a robot connected to the first.
        self.worker = queue.make_worker(self.broker, capacity)
        if self.hub is not None:  # a thread for each robot's run (`runs` takes <= capacity)
            self.worker.worker_threads += self._robot_count() + BENCH_SPARE_THREADS
        self.bench: BenchDesk | None = None
        if self.hub is not None:
            self.hub.listen(self._tell)  # a run past its robot's slot stops here, where it runs
            self.bench = BenchDesk(self.client, self.hub, self.id, self._take_robot)
        self.heartbeat = queue.Heartbeat(self.broker, lambda: set(self.worker.consumers))
        self.state = roster.WorkerState.READY
        self.message = ""
        self._held: set[str] = set()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._roster = threading.Thread(target=self._keep_roster, name="roster", daemon=True)

    # ------------------------------------------------------------------------------ lifecycle
    def start(self) -> None:
        self._report()  # in the roster before the first job can be claimed
        self.commands.start()
        if self.hub is not None and self.bench is not None:
            self.hub.start()
            self.bench.start()
            where = self.hub.listen_error or f"{self.settings.rosserial_host}:{self.hub.port}"
            print(f"RoboDojo bench {self.id}: CrowBots connect to {where}", flush=True)
        self.worker.start()
        self.heartbeat.start()
        self._roster.start()
        log.info("worker %s: taking up to %d runs at once", self.id, self.capacity)
        print(f"RoboDojo worker {self.id}: taking up to {self.capacity} runs", flush=True)

    def run(self) -> None:
        """Start, then serve until SIGTERM or SIGINT; then stop cleanly."""
        stopping = threading.Event()
        for sig in (signal.SIGTERM, signal.SIGINT):
            signal.signal(sig, lambda *_: stopping.set())
        self.start()
        stopping.wait()
        self.stop()

    def stop(self) -> None:
        """Take no more jobs, stop the runs held here (each stored as ended by the shutdown),
        give back what was fetched and not started, and leave the roster."""
        self.state = roster.WorkerState.STOPPING
        queue.pause_taking(self.worker)
        self.host.close(self.settings.shutdown_grace_s)
        if self.hub is not None and self.bench is not None:
            self.bench.stop()
            self.hub.stop()
        self._stop.set()
        self.worker.stop(timeout=int(self.settings.shutdown_grace_s * 1000))
        self.heartbeat.stop()
        self.commands.stop()
        self._roster.join(timeout=5)
        self.state = roster.WorkerState.STOPPED
        try:
            self._report()
            self.client.delete(worker_key(self.id))
        except Exception:
            log.warning("worker %s: could not say it stopped", self.id)
        queue.close_broker(self.broker)
        self.client.close()
        if self.own_launcher:
            self.launcher.close()
        self.store.close()

    # ------------------------------------------------------------------------------ runs
    def _execute(self, job: RunJob) -> None:  # a Dramatiq worker thread, after the claim
        with self._lock:
            self._held.add(job.run_id)
        with contextlib.suppress(Exception):  # only the lost-queue check reads the mark
            self.client.delete(queued_key(job.run_id))
        self.commands.hold(job.run_id)
        try:
            self.host.execute(job)
        finally:
            self.commands.release(job.run_id)
            with self._lock:
                self._held.discard(job.run_id)

    def _robot_count(self) -> int:
        with self.store.session() as db:
            return len(inventory.listing(db))

    def _take_robot(self, name: str) -> None:
        """A robot connected here: take its runs' queue (Dramatiq starts a consumer)."""
        self.broker.declare_queue(queue.robot_queue(name))

    def _tell(self, run_id: str, command) -> None:
        with contextlib.suppress(CommandError):  # refused: the run is ending anyway
            self.host.command(run_id, command)

    def _answer(self, request: CommandRequest) -> CommandAnswer:
        try:
            taken = self.host.command(request.run_id, request.command)
        except CommandError as error:
            return CommandAnswer(request.request_id, False, str(error))
        if isinstance(taken, CommandAnswer):
            return CommandAnswer(request.request_id, taken.taken, taken.refusal, taken.extra)
        return CommandAnswer(request.request_id, bool(taken))

    @property
    def running(self) -> int:
        with self._lock:
            return len(self._held)

    # ------------------------------------------------------------------------------ roster
    def _keep_roster(self) -> None:
        while not self._stop.wait(roster.REPORT_PERIOD_S):
            self._report()

    def _report(self) -> None:
        """Report to Redis (alive even without the database) and to the database; reap lost
        workers; pause taking jobs while the database is away."""
        report = roster.WorkerReport(
            self.id,
            self.host_name,
            self.capacity,
            self.running,
            str(self.state),
            self.message,
            [],
            self.started_at,
        )
        try:
            self.client.set(
                worker_key(self.id),
                json.dumps(dataclasses.asdict(report)),
                ex=int(roster.LOST_AFTER_S),
            )
        except Exception as error:
            log.debug("worker %s: Redis is away (%s)", self.id, error)
        try:
            with self.store.session() as db:
                if self.state == roster.WorkerState.PAUSED:  # it answers again: say so now
                    self._database_back()
                    report = dataclasses.replace(report, state=str(self.state), message="")
                roster.report(db, report)
                ended = roster.reap(db, alive=self._alive)
        except Exception as error:
            self._database_lost(error)
            return
        for run_id in ended:
            with contextlib.suppress(Exception):  # else web processes look it up when silent
                publish_end(self.client, run_id, str(RunState.FAILED), roster.WORKER_LOST)

    def _alive(self, other: str) -> bool:
        try:
            return bool(self.client.exists(worker_key(other)))
        except Exception:
            return False

    def _database_lost(self, error: Exception) -> None:
        if self.state == roster.WorkerState.READY:
            self.state = roster.WorkerState.PAUSED
            self.message = (
                f"cannot reach the database ({str(error).strip()[:200]}); taking no runs until "
                "it is back"
            )
            log.error("worker %s: %s", self.id, self.message)
            queue.pause_taking(self.worker)

    def _database_back(self) -> None:
        if self.state == roster.WorkerState.PAUSED:
            self.state = roster.WorkerState.READY
            self.message = ""
            log.warning("worker %s: the database is back; taking runs again", self.id)
            queue.resume_taking(self.worker)
