"""The run service: starts runs for users, enforces the lab's limits, and is the one door to a
running run. It knows nothing of HTTP: the API calls it, the CLI could too.

A run is stored as "created" and handed as a `RunJob` to an executor (server/workers): in this
process's threads, on worker processes of this machine, or on a cluster's workers. Wherever it
runs, a `RunHost` there stores its state changes and its end, judges it, and sends its live
traffic back; this service reads it only through the executor, as data.

Routes, the websocket, the 3D view and the hardware hub tell a run things with typed commands
(`command(run_id, Stop(...))`, server/runs/commands.py) and read it through plain snapshots
(`live`, `logs`, `graph`, `lights`, `feed`); none of them holds the `Run`. The limits count the
DATABASE's active runs, so every web process of a lab agrees on them.
"""

from __future__ import annotations

import contextlib
import dataclasses
import logging
import threading
import time
import uuid
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from sandbox.launcher import Launcher
from sandbox.limits import DEFAULT_LIMITS
from sandbox.protocol import Clock
from server.exercises.grading import cases_of, run_spec
from server.hardware.queue import QueueError
from server.runs.commands import CommandError, RunCommand, Stop
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState
from server.service import disk
from server.service.catalog import ExerciseEntry
from server.service.sandbox_budget import SandboxBudget
from server.service.telemetry import RunTelemetry
from server.sim.world import LightSource
from server.store import robots as inventory
from server.store import runs as run_store
from server.store import sandbox_leases
from server.store.db import Store
from server.store.models import RunRecord
from server.store.runs import RunFilter
from server.workers.choose import make_executor
from server.workers.seams import ExecutorUnavailableError
from server.workers.wire import RunJob

log = logging.getLogger("robodojo.service")


class RunLimitError(Exception):
    """Too many runs at once; `retry_after_s` says when to try again."""

    def __init__(self, message: str, retry_after_s: int) -> None:
        super().__init__(message)
        self.retry_after_s = retry_after_s


class RunRequestError(ValueError):
    """The run cannot start as asked; the message says what to change."""


@dataclass(frozen=True, slots=True)
class RunRequest:
    robot: str | None
    world: str | None
    exercise: ExerciseEntry | None
    nodes: tuple[NodeSpec, ...]  # code, parameters, remappings, arguments, namespace
    clock: Clock | None
    duration_s: float | None
    seed: int | None
    teleop: bool = False  # the teleop built-in: arrow keys from the browser drive the robot
    hardware: str | None = None  # a robot on the bench (inventory name) instead of simulation
    simulation_run: str | None = None  # a hardware run: the simulation run that passed its gate
    params: dict[str, object] = field(default_factory=dict)  # a launch file's global <param>s
    files: tuple[tuple[str, bytes], ...] = ()  # workspace data files, into every node's folder
    case: int | None = None  # an exercise's grading case (seed and start), as `robodojo check`


@dataclass(frozen=True, slots=True)
class LiveRun:
    """What a running run looks like now, read once: routes show this, never the run itself."""

    run_id: str
    state: RunState
    time_s: float  # [s] the run's clock (simulated time for a lockstep run)
    ros_version: int  # 1 or 2: the dialect the nodes speak
    node_periods: dict[str, dict]  # node -> its recent loop periods (metrics.recent_summary)
    sandbox_processes: int  # nodes with a live sandbox process


class RunService:
    def __init__(
        self, store: Store, settings, launcher: Launcher, hardware=None, executor=None
    ) -> None:
        """`executor`: where runs execute (server/workers/seams.py RunExecutor); None: the one
        the settings choose (server/workers/choose.py)."""
        self.hardware = hardware  # server/service/hardware.py HardwareHub, or None
        self.store = store
        self.settings = settings
        self.launcher = launcher
        if executor is None:
            executor = make_executor(settings, store, launcher, hardware)
        self.executor = executor
        # Every sandbox job of a student counts against one budget (server/service/
        # sandbox_budget.py); a launch file's job holds its lease for at most its sandbox's
        # start, first step and end budgets (a web process that died frees it then).
        limits = launcher.limits if launcher is not None else DEFAULT_LIMITS
        self.sandbox_budget = SandboxBudget.from_settings(settings, limits.memory_bytes)
        self._launch_lease_s = (
            limits.startup_budget_s + limits.first_step_budget_s + limits.shutdown_budget_s
        )
        self._lock = threading.Lock()  # one start at a time here: counted, then stored
        self._closing = False
        if hardware is not None:  # a run past its robot's time slot is told to stop
            hardware.listen(self.command)

    # ------------------------------------------------------------------------------ starting
    def build_spec(self, request: RunRequest) -> RunSpec:
        """The RunSpec a request describes, checked against the lab's limits."""
        settings = self.settings
        if not request.nodes:
            raise RunRequestError("a run needs at least one node: send nodes=[{name, code}]")
        total = 0
        for node in request.nodes:
            size = len(node.code.encode())
            total += size
            if size > settings.max_code_bytes_per_file:
                raise RunRequestError(
                    f"node '{node.name}' has {size} bytes of code; the limit per file is "
                    f"{settings.max_code_bytes_per_file} bytes"
                )
        if total > settings.max_code_bytes_per_run:
            raise RunRequestError(
                f"the nodes have {total} bytes of code in all; the limit per run is "
                f"{settings.max_code_bytes_per_run} bytes"
            )
        duration = request.duration_s
        if duration is not None and duration > settings.max_run_duration_s:
            raise RunRequestError(
                f"duration {duration:g} s is longer than this lab allows "
                f"({settings.max_run_duration_s:g} s)"
            )
        nodes = request.nodes
        if request.case is not None and request.exercise is None:
            raise RunRequestError("a case is one of an exercise's grading runs: name the exercise")
        if request.exercise is not None:
            exercise = request.exercise.exercise
            seed = request.seed if request.seed is not None else exercise.seeds[0]
            start = exercise.starts[0] if exercise.starts else None
            if request.case is not None:
                seed, start = _case(exercise, request.case, request.seed)
            spec = run_spec(exercise, nodes, seed, start)
            if duration is not None:  # a shorter try of an exercise is fine; it is judged as is
                spec = _replace(spec, duration_s=duration)
            if request.clock is not None:
                spec = _replace(spec, clock=request.clock)
        else:
            spec = RunSpec(
                robot=request.robot or "",
                world=request.world or "",
                nodes=nodes,
                clock=request.clock or Clock.LOCKSTEP,
                duration_s=duration if duration is not None else 30.0,
                seed=request.seed or 0,
            )
        if request.params:  # the exercise's own parameters win: its checks depend on them
            spec = _replace(spec, params={**request.params, **spec.params})
        if request.files:
            spec = _replace(spec, files=request.files)
        if request.teleop and "teleop" not in spec.builtin_nodes:
            spec = _replace(spec, builtin_nodes=(*spec.builtin_nodes, "teleop"))
        spec.validate()  # RunSpecError: the caller turns it into a 422
        return spec

    def start(self, user_id: str, request: RunRequest) -> RunRecord:
        spec = self.build_spec(request)
        if request.hardware is not None:
            spec = _replace(spec, clock=Clock.REALTIME)  # a real robot lives in real time
        with self._lock:
            if self._closing:
                raise RunLimitError("the server is shutting down; try again in a minute", 60)
            run_id = uuid.uuid4().hex
            claimed = False
            try:
                # Counted from the database and stored in one transaction under its write lock
                # (an advisory lock on PostgreSQL): every web process of the lab agrees, and two
                # admitting at once cannot both pass a count neither has added to yet.
                with self.store.exclusive_session() as db:
                    self._check_limits(db, user_id, sandboxes=len(spec.nodes))
                    record = self._record(run_id, user_id, request, spec)
                    # The robot's turn is claimed before the run is stored: a refused run (not
                    # your turn, not connected) leaves no record, like any other refused
                    # request, instead of a run "created" forever in the student's history. The
                    # worker holding the robot's connection gives the slot back when it ends.
                    if request.hardware is not None:
                        self._claim_robot(request.hardware, user_id, run_id, spec)
                        claimed = True
                    run_store.add(db, record)
            except BaseException:
                if claimed:
                    self._release_robot(request.hardware, run_id)
                raise
            job = RunJob(
                run_id=run_id,
                user_id=user_id,
                spec=spec,
                run_dir=record.run_dir,
                exercise_id=record.exercise_id,
                hardware=request.hardware,
                queued_wall_s=time.time(),
            )
            try:
                self.executor.submit(job)
            except BaseException as error:
                self._release_robot(request.hardware, run_id)
                with self.store.session() as db:
                    stored = run_store.get(db, run_id)
                    stored.state, stored.ended_at = str(RunState.FAILED), time.time()
                    stored.reason = (
                        f"failed: {error}"
                        if isinstance(error, ExecutorUnavailableError)
                        else f"failed: the run could not be queued ({error!r})"
                    )
                if isinstance(error, ExecutorUnavailableError):
                    raise RunLimitError(str(error), self.settings.retry_after_s) from None
                raise
        return record

    @contextlib.contextmanager
    def launch_file_job(self, user_id: str) -> Iterator[None]:
        """Hold one of the student's sandbox jobs while a Python launch file is read in the
        sandbox for a run (server/runs/launch_py.py): refused, before any sandbox starts, when
        the run that follows could not start either or the student's sandbox budget is full."""
        with self.store.exclusive_session() as db:
            self._check_limits(db, user_id, sandboxes=0)  # the run's own limits first
            self._check_sandboxes(db, user_id, 1, "reading a Python launch file")
            lease = sandbox_leases.take(
                db, user_id, "launch file", 1, time.time(), self._launch_lease_s
            )
        try:
            yield
        finally:
            with self.store.session() as db:
                sandbox_leases.give_back(db, lease)

    def _check_sandboxes(self, db, user_id: str, sandboxes: int, what: str) -> None:
        """Raises RunLimitError (RunRequestError for a job too large for any wait to help)
        when a job of `sandboxes` sandboxes does not fit the student's sandbox budget."""
        held = sandbox_leases.holding(db, user_id, time.time())
        refusal = self.sandbox_budget.refusal(held, sandboxes, what)
        if refusal is None:
            return
        if not refusal.waiting_helps:
            raise RunRequestError(refusal.sentence)
        raise RunLimitError(refusal.sentence, self.settings.retry_after_s)

    def _check_limits(self, db, user_id: str, sandboxes: int) -> None:
        """Raises RunLimitError (or DiskBudgetError) when this student or the lab is full; with
        `sandboxes`, when a run of that many nodes does not fit the student's sandbox budget."""
        mine = run_store.active_count(db, user_id)
        total = run_store.active_count(db)
        disk.check_budgets(db, user_id, self.settings)  # measured sizes, summed
        if mine >= self.settings.max_runs_per_student:
            raise RunLimitError(
                f"you already have {mine} runs going (the limit is "
                f"{self.settings.max_runs_per_student}); stop one or wait for it to end",
                self.settings.retry_after_s,
            )
        if total >= self.settings.max_runs_total:
            raise RunLimitError(
                f"the lab is running its maximum of {self.settings.max_runs_total} runs; "
                f"try again in {self.settings.retry_after_s} s",
                self.settings.retry_after_s,
            )
        if sandboxes:
            self._check_sandboxes(db, user_id, sandboxes, f"this run's {sandboxes} nodes")

    def _record(self, run_id: str, user_id: str, request: RunRequest, spec: RunSpec) -> RunRecord:
        """The run's record as it is first stored: "created", not yet taken by a worker."""
        exercise = request.exercise
        return RunRecord(
            id=run_id,
            user_id=user_id,
            exercise_id=exercise.exercise.id if exercise else None,
            robot=spec.robot,
            world=spec.world,
            clock=str(spec.clock),
            duration_s=spec.duration_s,
            seed=spec.seed,
            state=str(RunState.CREATED),
            reason="",
            created_at=time.time(),
            code=[{"name": n.name, "code": n.code} for n in spec.nodes],
            metrics={},
            nodes={},
            checks=[],
            run_dir=str(Path(self.settings.runs_dir) / run_id),
            hardware=request.hardware,
            simulation_run_id=request.simulation_run if request.hardware else None,
        )

    def _claim_robot(self, name: str, user_id: str, run_id: str, spec: RunSpec) -> None:
        """Take the user's turn on the bench robot (raises with a sentence when it is not)."""
        if self.hardware is None:
            raise RunRequestError("this server has no hardware support switched on")
        with self.store.session() as db:
            entry = inventory.by_name(db, name)
            if entry is None:
                raise RunRequestError(
                    f"no robot named '{name}' on the bench; robots: {inventory.names(db)}"
                )
            kind, in_service = entry.kind, entry.in_service
        if kind != spec.robot:
            raise RunRequestError(f"'{name}' is a {kind}; this run needs a {spec.robot}")
        if not in_service:
            raise RunRequestError(f"'{name}' is out of service; ask your instructor")
        if self.hardware.link(name) is None:
            raise RunRequestError(f"'{name}' is not connected; switch it on or ask your instructor")
        try:
            self.hardware.queue(name).start(user_id, run_id, time.monotonic())
        except QueueError as error:
            raise RunLimitError(str(error), self.settings.retry_after_s) from None

    def _release_robot(self, name: str | None, run_id: str) -> None:
        if name is not None and self.hardware is not None:  # the slot goes to the next in line
            self.hardware.queue(name).finish(run_id, time.monotonic())

    def command(self, run_id: str, command: RunCommand) -> bool:
        """Send a command (server/runs/commands.py) to a running run; False when it is not
        running (any more). Raises CommandError when the run's state refuses it now."""
        return self.executor.command(run_id, command)

    # ------------------------------------------------------------------------------ reading
    # Whatever reads a running run is here, and only here: callers get data, not the run.
    def is_running(self, run_id: str) -> bool:
        """Whether the run is still held (queued, going, or being judged and stored)."""
        return self.executor.is_running(run_id)

    def live(self, run_id: str) -> LiveRun | None:
        """A snapshot of a running run; None when it is not running (any more)."""
        status = self.executor.status(run_id)
        if status is None:
            return None
        return LiveRun(
            run_id=run_id,
            state=RunState(status.state),
            time_s=status.time_s,
            ros_version=status.ros_version,
            node_periods=status.node_periods,
            sandbox_processes=status.sandbox_processes,
        )

    def logs(self, run_id: str) -> dict[str, list[str]] | None:
        """What each node of a running run printed so far; None when it is not running."""
        status = self.executor.status(run_id)
        return dict(status.logs) if status is not None else None

    def graph(self, run_id: str) -> dict | None:
        """A running run's nodes and topics with measured rates; None when it is not running."""
        status = self.executor.status(run_id)
        return status.graph if status is not None else None

    def lights(self, run_id: str) -> tuple[LightSource, ...] | None:
        """Where a running run's lights are now; None when it is not running (or its robot is
        not made yet)."""
        status = self.executor.status(run_id)
        if status is None or status.lights is None:
            return None
        return tuple(LightSource(**light) for light in status.lights)

    def feed(self, run_id: str) -> RunTelemetry | None:
        """A run's live telemetry, for a viewer to follow; None when it has none here (never
        ran, or ended long ago)."""
        return self.executor.feed(run_id)

    def _active_ids(self, user_id: str | None = None) -> list[str]:
        with self.store.session() as db:
            records, _ = run_store.listing(
                db, RunFilter(user_id=user_id, state="active", limit=run_store.MAX_LISTED)
            )
            return [record.id for record in records]

    # ------------------------------------------------------------------------------ controls
    def stop(self, run_id: str, reason: str = "stopped by the user") -> bool:
        """Ask a run to stop; False when it is not running (any more)."""
        return self.command(run_id, Stop(reason))

    def stop_user(self, user_id: str, reason: str) -> int:
        stopped = 0
        for run_id in self._active_ids(user_id):
            with contextlib.suppress(CommandError):  # refused: it is ending already
                stopped += self.command(run_id, Stop(reason))
        return stopped

    def shutdown(self) -> None:
        """Stop every run this process executes (robots commanded to zero as each ends) and
        wait for them, up to shutdown_grace_s."""
        with self._lock:
            self._closing = True
        self.executor.shutdown(self.settings.shutdown_grace_s)

    def status(self) -> dict:
        statuses = [self.executor.status(run_id) for run_id in self._active_ids()]
        lives = [status for status in statuses if status is not None]
        feeds = [self.executor.feed(status.run_id) for status in lives]
        return {
            "active_runs": len(lives),
            "active_by_state": _count(status.state for status in lives),
            "sandbox_processes": sum(status.sandbox_processes for status in lives),
            # Warm sandboxes here and, for worker processes of this machine, there.
            "warm_pool": self.launcher.warm_count + getattr(self.executor, "warm_count", int)(),
            "max_runs_total": self.settings.max_runs_total,
            "max_runs_per_student": self.settings.max_runs_per_student,
            "live_viewers": sum(feed.viewer_count for feed in feeds if feed is not None),
            "workers": self.executor.workers(),
        }


def _case(exercise, index: int, seed: int | None):
    """The seed and start pose of an exercise's grading case `index` (cases_of, as `robodojo
    check` runs them), or RunRequestError with a sentence."""
    cases = cases_of(exercise)
    if seed is not None:
        raise RunRequestError("give a case or a seed, not both: a case chooses its own seed")
    if not 0 <= index < len(cases):
        raise RunRequestError(
            f"exercise '{exercise.id}' has {len(cases)} grading cases (0 to {len(cases) - 1}); "
            f"there is no case {index}"
        )
    return cases[index].seed, cases[index].start


def node_spec(name: str, code: str, **ros) -> NodeSpec:
    """A node sent as code (the page's editor, an exercise's files): its file is `<name>.py`;
    `ros` is params, remaps, args and namespace, as NodeSpec takes them."""
    return NodeSpec(name=name, code=code, filename=f"{name}.py", **ros)


def _replace(spec: RunSpec, **changes) -> RunSpec:
    return dataclasses.replace(spec, **changes)


def _count(values) -> dict[str, int]:
    counts: dict[str, int] = {}
    for value in values:
        counts[value] = counts.get(value, 0) + 1
    return counts
