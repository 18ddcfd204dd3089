"""The worker side of runs (issue 16): a `RunHost` executes `RunJob`s, keeps the store up to date
as each run changes state, judges exercise runs when they end, and sends every run's live traffic
out through a `LiveOutlet` (server/workers/seams.py) as `LiveBatch`es. It knows nothing of HTTP
or of where its outlet leads (straight into mirrors in this process, a pipe to the web process,
Redis): whoever holds it calls `execute(job)` on a thread of its own, one per run.

    host = RunHost(store, settings, launcher, outlet, worker_id="host:pid", hardware=hub)
    host.execute(job)              # blocks until the run ended, was stored and its final batch sent
    host.command(run_id, Pause())  # from any thread: True taken, False not here, CommandError
    host.status(run_id)            # a fresh RunStatus, or None

Live traffic goes out from ONE publisher thread per host, never from a run's thread: a run only
swaps its newest sample per topic into its outbox (latest wins, the overwritten ones counted as
`skipped`) and appends its events. The publisher wakes when something arrives, waits out FLUSH_S
since its previous round (so a busy host coalesces, an idle one sends at once), and sends each
run's batch; a running run's status goes with it every STATUS_EVERY_S (outbox.py) and at each
state change.
A run's end is stored and judged first, then its check results and end state go out in the
`final` batch: a viewer never sees "finished" without its score.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import os
import socket
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sandbox.launcher import Launcher
from server.exercises.grading import judge_run
from server.hardware.backend import HardwareRobot
from server.hardware.safety import MotionLimits
from server.runs.commands import CommandError, RunCommand, Stop
from server.runs.recorder import json_safe
from server.runs.result import RunResult
from server.runs.run import Run
from server.runs.state import RunState
from server.service import disk
from server.service import exercises as exercise_store
from server.store import robots as inventory
from server.store import runs as run_store
from server.store.db import Store
from server.store.models import RunRecord
from server.workers.outbox import Outbox
from server.workers.seams import LiveOutlet
from server.workers.wire import LiveBatch, RunJob, RunStatus

log = logging.getLogger("robodojo.workers")

# Limits and rhythms of the live traffic, each bounding latency, memory or bytes on the wire.
# [s] least time between two publisher rounds: a sample waits at most this (telemetry delivery
# p99 under 100 runs: 41-46 ms at 10 ms, 50-51 ms at 20 ms). A round is one write for all runs,
# so 10 ms costs no more CPU measurably (20 runs at 100 Hz: 3.3-3.5% of a core per run either
# way); when each run's batch was a write of its own, 20 ms halved that cost.
FLUSH_S = 0.010
IDLE_WAIT_S = 0.05  # [s] the publisher's longest sleep (statuses fall due while it sleeps)
STATUS_LOG_LINES = 50  # per node, in a published status: mirrors keep the lines from log events
# [s] a status's measured figures (each node's recent loop periods, the topic graph with its
# rates) are recomputed at most this often; the statuses between reuse them. Computing them
# was a third of a worker's CPU at 100 runs with a status every 0.2 s each (py-spy, issue 16).
FIGURES_EVERY_S = 1.0
FINAL_WAIT_S = 10.0  # [s] execute() waits this long for its final batch to be sent


def default_worker_id() -> str:
    """ "host:pid": names this process in runs.worker_id and on the admin page."""
    return f"{socket.gethostname()}:{os.getpid()}"


@dataclass
class _Hosted:
    job: RunJob
    outbox: Outbox
    run: Run | None = None  # None until made (and when making it failed)
    stop_reason: str | None = None  # a Stop that came before the run was made
    exercise: Any = None  # server/service/catalog.py ExerciseEntry, judged at the end
    failure: str | None = None  # why the run could not be made (a stored reason)
    state: RunState = RunState.CREATED  # its end, once known (the run's own state before)
    reason: str = ""
    published: threading.Event = field(default_factory=threading.Event)
    figures: tuple[dict, dict] | None = None  # (node periods, graph), JSON-safe, as last computed
    figures_due_s: float = 0.0  # [s] monotonic: when `figures` is next recomputed


class RunHost:
    """Executes runs on this worker and publishes their live traffic (see the module doc)."""

    def __init__(
        self,
        store: Store,
        settings,
        launcher: Launcher,
        outlet: LiveOutlet,
        worker_id: str,
        hardware=None,
    ) -> None:
        self.store = store
        self.settings = settings
        self.launcher = launcher
        self.outlet = outlet
        self.worker_id = worker_id
        self.hardware = hardware  # server/service/hardware.py HardwareHub holding robot links
        self._runs: dict[str, _Hosted] = {}
        self._lock = threading.Lock()
        self._closing = False
        self._wakeup = threading.Event()
        self._publisher_stop = False
        self._publisher = threading.Thread(
            target=self._publish_loop, name="live-publisher", daemon=True
        )
        self._publisher.start()

    # ------------------------------------------------------------------------------ running
    def accept(self, job: RunJob) -> bool:
        """Take the job and make its run now, without starting it (quick: the simulation and
        the sandboxes start in `execute`), so that commands sent right after reach it. Never
        raises; False when this run is held here already (a job delivered twice)."""
        hosted = _Hosted(job, Outbox(self.store, job.run_id, self._wake))
        with self._lock:
            if job.run_id in self._runs:
                log.warning("run %s is already held by this worker; job ignored", job.run_id)
                return False
            self._runs[job.run_id] = hosted
        try:
            if self._closing:
                raise _NotStarted("failed: the server was shutting down when the run was due")
            with self.store.session() as db:
                db.query(RunRecord).filter(RunRecord.id == job.run_id).update(
                    {RunRecord.worker_id: self.worker_id}
                )
                if job.exercise_id is not None:
                    hosted.exercise = exercise_store.find(db, job.exercise_id)
            backend = self._robot(job) if job.hardware is not None else None
            run_dir = Path(job.run_dir)
            run = Run(job.spec, self.launcher, run_dir, run_id=job.run_id, backend=backend)
            run.observer = hosted.outbox
            with self._lock:
                hosted.run = run
        except _NotStarted as error:
            hosted.failure = str(error)
        except Exception as error:
            log.exception("run %s could not be made", job.run_id)
            hosted.failure = f"failed: the run could not start ({error})"
        return True

    def execute(self, job: RunJob) -> None:
        """Run the job to its end on this thread (accepting it first unless `accept(job)` was
        called); store, judge and publish it. Never raises for what the run does: anything that
        goes wrong ends this run, with the reason stored."""
        hosted = self._runs.get(job.run_id)
        if hosted is None or hosted.job is not job:
            if not self.accept(job):
                return
            hosted = self._runs[job.run_id]
        result: RunResult | None = None
        state, reason = RunState.FAILED, hosted.failure or "failed: the run was not made"
        if hosted.run is not None:
            with self._lock:
                early_stop = hosted.stop_reason
            if early_stop is not None:
                hosted.run.command(Stop(early_stop))
            try:
                result = hosted.run.execute()
                state, reason = result.state, result.reason
            except Exception as error:  # execute() does not raise; if it does, this run ends
                log.exception("run %s raised out of execute()", job.run_id)
                state, reason = RunState.FAILED, f"failed: internal error ({error!r})"
        if result is None and hosted.outbox.end is None:
            hosted.outbox.end = (state, reason, 0.0)
        self._finish(hosted, hosted.exercise, result, state, reason)

    def _robot(self, job: RunJob) -> HardwareRobot:
        """The bench robot for a hardware run, on the connection this worker holds (its turn
        in the robot's queue was claimed by the web process that accepted the run)."""
        name = job.hardware
        link = self.hardware.link(name) if self.hardware is not None else None
        if link is None:
            raise _NotStarted(f"failed: '{name}' is not connected to this worker")
        with self.store.session() as db:
            entry = inventory.by_name(db, name)
            if entry is None:
                raise _NotStarted(f"failed: no robot named '{name}' on the bench any more")
            kind, limits, watchdog_s = entry.kind, dict(entry.limits), entry.watchdog_s
        link.drain()
        return HardwareRobot(kind, link, MotionLimits(**limits), watchdog_s)

    def _finish(self, hosted: _Hosted, exercise, result, state: RunState, reason: str) -> None:
        run_id = hosted.job.run_id
        checks, score = [], None
        try:
            checks, score = self._store_end(hosted, exercise, result, state, reason)
        except Exception:
            log.exception("run %s: could not store its end", run_id)
        finally:
            if hosted.job.hardware is not None and self.hardware is not None:
                # The robot's slot goes to the next in line.
                self.hardware.queue(hosted.job.hardware).finish(run_id, time.monotonic())
            events: list[dict[str, Any]] = []
            if checks:
                events.append({"type": "checks", "checks": json_safe(checks), "score": score})
            end_state, end_reason, time_s = hosted.outbox.end or (state, reason, 0.0)
            if result is None:
                end_state, end_reason = state, reason
            with self._lock:
                hosted.state, hosted.reason = end_state, end_reason
            events.append(
                {"type": "state", "state": str(end_state), "reason": end_reason, "time_s": time_s}
            )
            hosted.outbox.finish(events)
            if not hosted.published.wait(FINAL_WAIT_S):
                log.warning("run %s: its final batch was not sent in %g s", run_id, FINAL_WAIT_S)
            with self._lock:
                self._runs.pop(run_id, None)

    def _store_end(
        self, hosted: _Hosted, exercise, result: RunResult | None, state: RunState, reason: str
    ) -> tuple[list[dict], float | None]:
        checks: list[dict] = []
        score = None
        out_dir = hosted.run.out_dir if hosted.run is not None else Path(hosted.job.run_dir)
        if result is not None and exercise is not None:
            try:
                checks, score = judge_run(exercise.exercise, result, out_dir)
            except Exception as error:
                log.exception("run %s: judging failed", hosted.job.run_id)
                checks = [{"name": "judging", "passed": False, "error": repr(error)}]
                score = 0.0
        with self.store.session() as db:
            record = run_store.get(db, hosted.job.run_id)
            if record is None:
                return checks, score
            record.state = str(state)
            record.reason = reason
            record.ended_at = time.time()
            if result is not None:
                record.sim_time_s = result.duration_s
                record.wall_s = result.wall_s
                record.metrics = json_safe(result.metrics)
                record.nodes = json_safe(result.summary()["nodes"])
            record.checks = json_safe(checks)
            record.score = score
            record.disk_bytes = disk.dir_bytes(out_dir)  # once, for the budgets
        return checks, score

    # ------------------------------------------------------------------------------ reaching
    def command(self, run_id: str, command: RunCommand) -> bool:
        """Deliver a command to a run held here: True taken, False not held here; raises
        CommandError when the run's state refuses it now."""
        with self._lock:
            hosted = self._runs.get(run_id)
            if hosted is None:
                return False
            run = hosted.run
            if run is None:  # not made yet: a stop waits for it, anything else is too early
                if isinstance(command, Stop):
                    hosted.stop_reason = command.reason
                    return True
                return False
        run.command(command)
        with hosted.outbox._lock:  # a pause, a moved light: viewers see it in the next round
            hosted.outbox.status_due = True
        self._wake()
        return True

    def status(self, run_id: str, log_lines: int | None = None) -> RunStatus | None:
        """A running run read now (None: not held here). `log_lines`: keep each node's newest
        lines only (a published status; mirrors rebuild the rest from log events)."""
        hosted = self._runs.get(run_id)
        return self._read_status(hosted, log_lines) if hosted is not None else None

    def running(self) -> list[str]:
        """The ids of the runs held here (going, or being judged and stored)."""
        with self._lock:
            return list(self._runs)

    def stop_all(self, reason: str) -> int:
        """Ask every run held here to stop; returns how many were asked."""
        count = 0
        for run_id in self.running():
            with contextlib.suppress(CommandError):  # refused: it is ending already
                count += self.command(run_id, Stop(reason))
        return count

    def close(self, grace_s: float) -> None:
        """Take no more runs, stop those held (robots commanded to zero as each ends), wait up
        to `grace_s` for them to end, then stop the publisher."""
        self._closing = True
        self.stop_all("the server is shutting down")
        deadline = time.monotonic() + grace_s
        while self.running() and time.monotonic() < deadline:
            time.sleep(0.02)
        self._publisher_stop = True
        self._wake()
        self._publisher.join(timeout=2.0)

    # ------------------------------------------------------------------------------ publishing
    def _wake(self) -> None:
        if not self._wakeup.is_set():
            self._wakeup.set()

    def _publish_loop(self) -> None:
        last_round_s = 0.0
        while not self._publisher_stop:
            self._wakeup.wait(IDLE_WAIT_S)
            wait_s = last_round_s + FLUSH_S - time.monotonic()
            if wait_s > 0:  # busy: let more arrive and send it together
                time.sleep(wait_s)
            self._wakeup.clear()
            last_round_s = now_s = time.monotonic()
            with self._lock:
                hosted_runs = list(self._runs.values())
            self._publish_round(hosted_runs, now_s)

    def _publish_round(self, hosted_runs: list[_Hosted], now_s: float) -> None:
        """Every run's batch of this round, sent together (one pipe message, one Redis round
        trip: per run, a loaded cluster worker's rounds took 100+ ms for 50 runs)."""
        batches: list[LiveBatch] = []
        ending: list[_Hosted] = []
        for hosted in hosted_runs:
            try:
                batch = self._take_batch(hosted, now_s)
            except Exception:  # one run's bad batch must not stop the others' traffic
                log.exception("run %s: live batch not sent", hosted.job.run_id)
                if hosted.outbox.finished:
                    hosted.published.set()
                continue
            if batch is not None:
                batches.append(batch)
                if batch.final:
                    ending.append(hosted)
        if not batches:
            return
        try:
            self.outlet.publish_round(batches)
        except Exception:  # an outlet must not raise; if one does, the runs still end
            log.exception("a round of %d live batches was not sent", len(batches))
        finally:
            for hosted in ending:
                hosted.published.set()

    def _take_batch(self, hosted: _Hosted, now_s: float) -> LiveBatch | None:
        if hosted.published.is_set():
            return None
        samples, events, status_due, final = hosted.outbox.take(now_s)
        status = self._read_status(hosted, STATUS_LOG_LINES) if status_due else None
        if not (samples or events or status or final):
            return None
        return LiveBatch(hosted.job.run_id, samples, events, status, final)

    def _read_status(self, hosted: _Hosted, log_lines: int | None) -> RunStatus:
        run = hosted.run
        base = RunStatus(
            run_id=hosted.job.run_id,
            state=str(hosted.state),
            reason=hosted.reason,
            time_s=0.0,
            ros_version=1,
            node_periods={},
            sandbox_processes=0,
            logs={},
            graph={"nodes": [], "topics": []},
            lights=None,
            worker=self.worker_id,
            wall_s=time.time(),
        )
        if run is None or hosted.outbox.finished:
            if run is None:
                return base
            return dataclasses.replace(base, time_s=run.time_s, ros_version=run.dialect.ros_version)
        slots = dict(run.slots)
        robot = run.sim
        periods, graph = self._figures(hosted, slots)
        return dataclasses.replace(
            base,
            state=str(run.state),
            reason=run.reason,
            time_s=run.time_s,
            ros_version=run.dialect.ros_version,
            node_periods=periods,
            sandbox_processes=sum(1 for slot in slots.values() if slot.process is not None),
            logs={name: _tail(slot.logs, log_lines) for name, slot in slots.items()},
            graph=graph,
            lights=[dataclasses.asdict(light) for light in robot.lights]
            if robot is not None
            else None,
        )

    @staticmethod
    def _figures(hosted: _Hosted, slots: dict) -> tuple[dict, dict]:
        """The run's measured figures, recomputed once FIGURES_EVERY_S has passed (or a node
        has come or gone), else the last ones."""
        now_s = time.monotonic()
        cached = hosted.figures
        if cached is None or now_s >= hosted.figures_due_s or cached[0].keys() != slots.keys():
            run = hosted.run
            periods = {name: slot.metrics.period.recent_summary() for name, slot in slots.items()}
            # JSON on the wire: no NaN
            hosted.figures = cached = (json_safe(periods), json_safe(run.bus.graph()))
            hosted.figures_due_s = now_s + FIGURES_EVERY_S
        return cached


class _NotStarted(Exception):
    """The run could not be made; the message is the reason stored (a sentence)."""


def _tail(lines, count: int | None) -> list[str]:
    lines = list(lines)
    return lines if count is None else lines[-count:]
