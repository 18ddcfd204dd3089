"""The run service: starts runs for users, enforces the lab's limits, keeps the store up to date
as runs change state, judges exercise runs when they end, and stops everything cleanly at
shutdown. It knows nothing of HTTP: the API calls it, the CLI could too.

Runs execute in-process, each `Run.execute()` on a worker thread of one pool (the executor seam:
a distributed worker would replace `_submit`). A run's crash ends that run only: `execute()`
never raises for what a node does, and anything else is caught here and stored as the reason.

This is the one door to a running run: routes, the websocket, the 3D view and the hardware hub
tell it things with typed commands (`command(run_id, Stop(...))`, server/runs/commands.py) and
read it through plain snapshots (`live`, `logs`, `graph`, `lights`, `feed`); none of them holds
the `Run`. What crosses this door is data, so a run on another process could stand behind it.
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
import uuid
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from sandbox.launcher import Launcher
from sandbox.protocol import Clock
from server.exercises.grading import judge_run, run_spec
from server.hardware.backend import HardwareRobot
from server.hardware.queue import QueueError
from server.hardware.safety import MotionLimits
from server.runs.commands import RunCommand, Stop
from server.runs.recorder import json_safe
from server.runs.result import RunResult
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState
from server.service import disk
from server.service.catalog import ExerciseEntry
from server.service.telemetry import RunTelemetry, TelemetryRegistry
from server.sim.world import LightSource
from server.store import robots as inventory
from server.store import runs as run_store
from server.store.db import Store
from server.store.models import RunRecord

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


@dataclass
class ActiveRun:
    run: Run
    user_id: str
    telemetry: RunTelemetry
    exercise: ExerciseEntry | None
    hardware: str | None = None  # the bench robot's name, for a hardware run
    started_wall: float = field(default_factory=time.monotonic)


@dataclass(frozen=True, slots=True)
class LiveRun:
    """What a running run looks like now, read once: routes show this, never the run itself."""

    run_id: str
    state: RunState
    time_s: float  # [s] the run's clock (simulated time for a lockstep run)
    ros_version: int  # 1 or 2: the dialect the nodes speak
    node_periods: dict[str, dict]  # node -> its recent loop periods (metrics.recent_summary)
    sandbox_processes: int  # nodes with a live sandbox process


class _Watch:
    """The run's observer: live viewers get everything, the store gets state changes."""

    def __init__(self, service: RunService, run_id: str, telemetry: RunTelemetry) -> None:
        self.service = service
        self.run_id = run_id
        self.telemetry = telemetry
        self._end: tuple[RunState, str, float] | None = None

    def on_message(self, topic: str, type_name: str, time_ns: int, data: bytes) -> None:
        self.telemetry.on_message(topic, type_name, time_ns, data)

    def on_logs(self, node: str, lines: list[str]) -> None:
        self.telemetry.on_logs(node, lines)

    def on_state(self, state: RunState, reason: str, time_s: float) -> None:
        if state.is_end:
            # Viewers hear of the end after the results are stored and the checks judged, so
            # the check results reach them before the socket closes.
            self._end = (state, reason, time_s)
            return
        try:
            with self.service.store.session() as db:
                run_store.set_state(db, self.run_id, str(state))
        except Exception:
            log.exception("run %s: could not store state %s", self.run_id, state)
        self.telemetry.on_state(state, reason, time_s)

    def release_end(self) -> None:
        state, reason, time_s = self._end or (RunState.FAILED, "failed: the run did not end", 0.0)
        self.telemetry.on_state(state, reason, time_s)


class RunService:
    def __init__(self, store: Store, settings, launcher: Launcher, hardware=None) -> None:
        self.hardware = hardware  # server/service/hardware.py HardwareHub, or None
        self.store = store
        self.settings = settings
        self.launcher = launcher
        self.telemetry = TelemetryRegistry()
        self._active: dict[str, ActiveRun] = {}
        self._lock = threading.Lock()
        self._closing = False
        self._pool = ThreadPoolExecutor(
            max_workers=settings.max_runs_total, thread_name_prefix="run"
        )
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
        if request.exercise is not None:
            exercise = request.exercise.exercise
            seed = request.seed if request.seed is not None else exercise.seeds[0]
            start = exercise.starts[0] if exercise.starts else None
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
            mine = sum(1 for a in self._active.values() if a.user_id == user_id)
            if mine >= self.settings.max_runs_per_student:
                raise RunLimitError(
                    f"you already have {mine} runs going (the limit is "
                    f"{self.settings.max_runs_per_student}); stop one or wait for it to end",
                    self.settings.retry_after_s,
                )
            if len(self._active) >= self.settings.max_runs_total:
                raise RunLimitError(
                    f"the lab is running its maximum of {self.settings.max_runs_total} runs; "
                    f"try again in {self.settings.retry_after_s} s",
                    self.settings.retry_after_s,
                )
            with self.store.session() as db:  # measured sizes, summed: no directory is walked
                disk.check_budgets(db, user_id, self.settings)
            run_id = uuid.uuid4().hex
            run_dir = Path(self.settings.runs_dir) / run_id
            exercise = request.exercise
            record = RunRecord(
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
                run_dir=str(run_dir),
                hardware=request.hardware,
                simulation_run_id=request.simulation_run if request.hardware else None,
            )
            # The robot is claimed before the run is stored: a refused run (not your turn, not
            # connected) leaves no record, like any other refused request, instead of a run
            # "created" forever in the student's history.
            backend = None
            if request.hardware is not None:
                backend = self._claim_robot(request.hardware, user_id, run_id, spec)
            try:
                run = Run(spec, self.launcher, run_dir, run_id=run_id, backend=backend)
                with self.store.session() as db:
                    run_store.add(db, record)
            except BaseException:
                if request.hardware is not None:  # the robot's slot goes to the next in line
                    self.hardware.queue(request.hardware).finish(run_id, time.monotonic())
                raise
            telemetry = self.telemetry.create(run_id)
            run.observer = _Watch(self, run_id, telemetry)
            self._active[run_id] = ActiveRun(run, user_id, telemetry, exercise, request.hardware)
        self._pool.submit(self._execute, run_id)
        return record

    def _claim_robot(self, name: str, user_id: str, run_id: str, spec: RunSpec):
        """The bench robot for this run, if it is the user's turn (raises with a sentence)."""
        if self.hardware is None:
            raise RunRequestError("this server has no hardware support switched on")
        with self.store.session() as db:
            entry = inventory.by_name(db, name)
            if entry is None:
                raise RunRequestError(
                    f"no robot named '{name}' on the bench; robots: {inventory.names(db)}"
                )
            kind, in_service = entry.kind, entry.in_service
            limits, watchdog_s = dict(entry.limits), entry.watchdog_s
        if kind != spec.robot:
            raise RunRequestError(f"'{name}' is a {kind}; this run needs a {spec.robot}")
        if not in_service:
            raise RunRequestError(f"'{name}' is out of service; ask your instructor")
        link = self.hardware.link(name)
        if link is None:
            raise RunRequestError(f"'{name}' is not connected; switch it on or ask your instructor")
        try:
            self.hardware.queue(name).start(user_id, run_id, time.monotonic())
        except QueueError as error:
            raise RunLimitError(str(error), self.settings.retry_after_s) from None
        try:
            link.drain()
            return HardwareRobot(kind, link, MotionLimits(**limits), watchdog_s)
        except BaseException:
            self.hardware.queue(name).finish(run_id, time.monotonic())
            raise

    def command(self, run_id: str, command: RunCommand) -> bool:
        """Send a command (server/runs/commands.py) to a running run; False when it is not
        running (any more). Raises CommandError when the run's state refuses it now."""
        active = self._active.get(run_id)
        if active is None:
            return False
        active.run.command(command)
        return True

    # ------------------------------------------------------------------------------ running
    def _execute(self, run_id: str) -> None:
        active = self._active[run_id]
        run = active.run
        result: RunResult | None = None
        try:
            result = run.execute()
        except Exception as error:  # execute() should not raise; if it does, this run ends
            log.exception("run %s raised out of execute()", run_id)
            reason = f"failed: internal error ({error!r})"
            self._store_end(run_id, RunState.FAILED, reason, None, active)
        else:
            self._store_end(run_id, result.state, result.reason, result, active)
        finally:
            with self._lock:
                self._active.pop(run_id, None)
            if active.hardware is not None and self.hardware is not None:
                self.hardware.queue(active.hardware).finish(run_id, time.monotonic())
            watch = run.observer
            if isinstance(watch, _Watch):
                watch.release_end()

    def _store_end(
        self,
        run_id: str,
        state: RunState,
        reason: str,
        result: RunResult | None,
        active: ActiveRun,
    ) -> None:
        checks: list[dict] = []
        score = None
        if result is not None and active.exercise is not None:
            try:
                checks, score = judge_run(active.exercise.exercise, result, active.run.out_dir)
            except Exception as error:
                log.exception("run %s: judging failed", run_id)
                checks = [{"name": "judging", "passed": False, "error": repr(error)}]
                score = 0.0
        with self.store.session() as db:
            record = run_store.get(db, run_id)
            if record is None:
                return
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
            record.disk_bytes = disk.dir_bytes(active.run.out_dir)  # once, for the budgets
        if checks:
            active.telemetry.on_event(
                {"type": "checks", "checks": json_safe(checks), "score": score}
            )

    # ------------------------------------------------------------------------------ reading
    # Whatever reads a running Run is here, and only here: callers get data, not the run.
    def is_running(self, run_id: str) -> bool:
        """Whether the run is still in the service (going, or being judged and stored)."""
        return run_id in self._active

    def live(self, run_id: str) -> LiveRun | None:
        """A snapshot of a running run; None when it is not running (any more)."""
        active = self._active.get(run_id)
        if active is None:
            return None
        run = active.run
        slots = dict(run.slots)
        return LiveRun(
            run_id=run_id,
            state=run.state,
            time_s=run.time_s,
            ros_version=run.dialect.ros_version,
            node_periods={
                name: slot.metrics.period.recent_summary() for name, slot in slots.items()
            },
            sandbox_processes=sum(1 for slot in slots.values() if slot.process is not None),
        )

    def logs(self, run_id: str) -> dict[str, list[str]] | None:
        """What each node of a running run printed so far; None when it is not running."""
        active = self._active.get(run_id)
        if active is None:
            return None
        return {name: list(slot.logs) for name, slot in dict(active.run.slots).items()}

    def graph(self, run_id: str) -> dict | None:
        """A running run's nodes and topics with measured rates; None when it is not running."""
        active = self._active.get(run_id)
        return active.run.bus.graph() if active is not None else None

    def lights(self, run_id: str) -> tuple[LightSource, ...] | None:
        """Where a running run's lights are now (the simulation replaces the tuple whole when
        one moves, so it is read safely from here); None when it is not running (or its robot
        is not made yet)."""
        active = self._active.get(run_id)
        robot = active.run.sim if active is not None else None
        return tuple(robot.lights) if robot is not None else None

    def feed(self, run_id: str) -> RunTelemetry | None:
        """A running run's telemetry, for a viewer to follow; None when it is not running."""
        active = self._active.get(run_id)
        return active.telemetry if active is not None else None

    def _actives(self) -> list[ActiveRun]:
        with self._lock:
            return list(self._active.values())

    # ------------------------------------------------------------------------------ controls
    def stop(self, run_id: str, reason: str = "stopped by the user") -> bool:
        """Ask a run to stop; False when it is not running (any more)."""
        return self.command(run_id, Stop(reason))

    def stop_user(self, user_id: str, reason: str) -> int:
        stopped = 0
        for active in self._actives():
            if active.user_id == user_id:
                active.run.command(Stop(reason))
                stopped += 1
        return stopped

    def shutdown(self) -> None:
        """Stop every run (robots commanded to zero as each ends) and wait for them."""
        with self._lock:
            self._closing = True
            actives = list(self._active.values())
        for active in actives:
            active.run.command(Stop("the server is shutting down"))
        deadline = time.monotonic() + self.settings.shutdown_grace_s
        while self._active and time.monotonic() < deadline:
            time.sleep(0.05)
        self._pool.shutdown(wait=False, cancel_futures=True)

    def status(self) -> dict:
        with self._lock:
            run_ids = list(self._active)
        lives = [live for live in map(self.live, run_ids) if live is not None]
        return {
            "active_runs": len(lives),
            "active_by_state": _count(str(live.state) for live in lives),
            "sandbox_processes": sum(live.sandbox_processes for live in lives),
            "warm_pool": self.launcher.warm_count,
            "max_runs_total": self.settings.max_runs_total,
            "max_runs_per_student": self.settings.max_runs_per_student,
            "live_viewers": self.telemetry.viewer_count(),
        }


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
