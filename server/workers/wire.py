"""What crosses between a web process and a worker, as JSON: a run job, a batch of a run's live
traffic (telemetry samples, events, a status snapshot), a command and its answer.

JSON and never pickle: whoever can write to the queue's Redis must not thereby run code on the
workers. Every decoder checks what it reads and raises `WireError` with a sentence.

    data = job_to_json(RunJob(...));        job = job_from_json(data)
    data = batch_to_json(LiveBatch(...));   batch = batch_from_json(data)
"""

from __future__ import annotations

import base64
import json
import math
from dataclasses import dataclass, field
from typing import Any

import msgspec

from sandbox.protocol import Api, Clock
from server.runs.commands import CommandError, RunCommand, command_dict, parse_command
from server.runs.spec import NodeSpec, RunSpec

WIRE_VERSION = 1  # bumped when a field's meaning changes: a worker refuses a job it cannot read


class WireError(ValueError):
    """A message that is not what this side of the wire expects; the text says what is wrong."""


# ------------------------------------------------------------------------------------ jobs
@dataclass(frozen=True, slots=True)
class RunJob:
    """One run to execute, made by a web process and executed by whichever worker takes it."""

    run_id: str
    user_id: str
    spec: RunSpec
    run_dir: str  # where the run writes; every process sees the data volume at the same path
    exercise_id: str | None = None  # judged at the end by the worker (server/exercises)
    hardware: str | None = None  # a bench robot's inventory name: placed on the worker holding it
    queued_wall_s: float = 0.0  # [s] time.time() when the web process queued it


def spec_to_json(spec: RunSpec) -> dict[str, Any]:
    return {
        "robot": spec.robot,
        "world": spec.world,
        "nodes": [_node_to_json(node) for node in spec.nodes],
        "clock": str(spec.clock),
        "duration_s": spec.duration_s,
        "seed": spec.seed,
        "spawn": spec.spawn,
        "initial_pose": list(spec.initial_pose) if spec.initial_pose is not None else None,
        "light_position": list(spec.light_position) if spec.light_position is not None else None,
        "goal": list(spec.goal) if spec.goal is not None else None,
        "params": _json_only(spec.params, "the run's parameters"),
        "script": [[time_s, command_dict(command)] for time_s, command in spec.script],
        "builtin_nodes": list(spec.builtin_nodes),
        "files": [[name, _b64(data)] for name, data in spec.files],
        "explicit_ros_version": spec.explicit_ros_version,
    }


def spec_from_json(data: Any) -> RunSpec:
    data = _object(data, "a run spec")
    try:
        script = tuple(
            (float(time_s), parse_command(command)) for time_s, command in data.get("script", [])
        )
        return RunSpec(
            robot=str(data["robot"]),
            world=str(data["world"]),
            nodes=tuple(_node_from_json(node) for node in data["nodes"]),
            clock=Clock(data["clock"]),
            duration_s=float(data["duration_s"]),
            seed=int(data["seed"]),
            spawn=data.get("spawn"),
            initial_pose=_floats(data.get("initial_pose"), 3),
            light_position=_floats(data.get("light_position"), 2),
            goal=_floats(data.get("goal"), 3),
            params=dict(data.get("params") or {}),
            script=script,
            builtin_nodes=tuple(str(name) for name in data.get("builtin_nodes", [])),
            files=tuple((str(name), _unb64(text)) for name, text in data.get("files", [])),
            explicit_ros_version=data.get("explicit_ros_version"),
        )
    except (KeyError, TypeError, ValueError, CommandError) as error:
        if isinstance(error, WireError):
            raise
        raise WireError(f"a run spec on the wire is malformed: {error!r}") from None


def _node_to_json(node: NodeSpec) -> dict[str, Any]:
    return {
        "name": node.name,
        "code": node.code,
        "filename": node.filename,
        "api": str(node.api),
        "params": _json_only(node.params, f"node '{node.name}''s parameters"),
        "remaps": [list(pair) for pair in node.remaps],
        "args": list(node.args),
        "namespace": node.namespace,
        "ros_version": node.ros_version,
    }


def _node_from_json(data: Any) -> NodeSpec:
    data = _object(data, "a node")
    return NodeSpec(
        name=str(data["name"]),
        code=str(data["code"]),
        filename=str(data["filename"]),
        api=Api(data.get("api", "auto")),
        params=dict(data.get("params") or {}),
        remaps=tuple((str(a), str(b)) for a, b in data.get("remaps", [])),
        args=tuple(str(arg) for arg in data.get("args", [])),
        namespace=str(data.get("namespace", "/")),
        ros_version=data.get("ros_version"),
    )


def job_to_json(job: RunJob) -> dict[str, Any]:
    return {
        "wire": WIRE_VERSION,
        "run_id": job.run_id,
        "user_id": job.user_id,
        "spec": spec_to_json(job.spec),
        "run_dir": job.run_dir,
        "exercise_id": job.exercise_id,
        "hardware": job.hardware,
        "queued_wall_s": job.queued_wall_s,
    }


def job_from_json(data: Any) -> RunJob:
    data = _object(data, "a run job")
    if data.get("wire") != WIRE_VERSION:
        raise WireError(
            f"a run job of wire version {data.get('wire')!r} reached a worker that reads version "
            f"{WIRE_VERSION}; run the same RoboDojo version on web processes and workers"
        )
    try:
        return RunJob(
            run_id=str(data["run_id"]),
            user_id=str(data["user_id"]),
            spec=spec_from_json(data["spec"]),
            run_dir=str(data["run_dir"]),
            exercise_id=data.get("exercise_id"),
            hardware=data.get("hardware"),
            queued_wall_s=float(data.get("queued_wall_s", 0.0)),
        )
    except KeyError as error:
        raise WireError(f"a run job on the wire lacks {error}") from None


# ------------------------------------------------------------------------------------ live
@dataclass(frozen=True, slots=True)
class Sample:
    """The newest message on a topic when the batch was made (latest wins, as in
    server/service/telemetry.py): `skipped` messages on that topic were overwritten since the
    previous batch, so a viewer's `dropped` count stays true across the wire."""

    topic: str
    type_name: str
    time_ns: int  # [ns] run clock
    data: bytes  # the message, serialized as recorded (ROS 1 or CDR)
    wall_s: float  # [s] time.time() when the run produced it: delivery latency end to end
    skipped: int = 0


@dataclass(frozen=True, slots=True)
class RunStatus:
    """A running run read at one moment, for the routes, the 3D view and the hub: what
    `RunService.live/logs/graph/lights` answer. Published a few times a second and at every
    state change; a web process answers from the newest one it has."""

    run_id: str
    state: str  # RunState value
    reason: str
    time_s: float  # [s] run clock
    ros_version: int
    node_periods: dict[str, dict]  # node -> metrics.recent_summary()
    sandbox_processes: int
    logs: dict[str, list[str]]  # node -> lines kept so far (the slot's bounded log)
    graph: dict  # bus.graph()
    lights: list[dict] | None  # [{name, x, y, z, intensity, movable}]; None before the robot
    worker: str  # the worker's id (host:pid), for the admin page and "worker lost"
    wall_s: float  # [s] time.time() when it was read


@dataclass(frozen=True, slots=True)
class LiveBatch:
    """What one run produced since its previous batch: samples (one per topic, the newest),
    events in order (the viewers' frames: {"type": "log"|"state"|"checks"|..., ...}) and, when
    due, a fresh status. `final` is set on the run's last batch (after its end state and check
    results), so a web process knows nothing more will come."""

    run_id: str
    samples: tuple[Sample, ...] = ()
    events: tuple[dict[str, Any], ...] = ()
    status: RunStatus | None = None
    final: bool = False


def batch_to_json(batch: LiveBatch) -> dict[str, Any]:
    return {
        "run_id": batch.run_id,
        "samples": [
            [s.topic, s.type_name, s.time_ns, _b64(s.data), s.wall_s, s.skipped]
            for s in batch.samples
        ],
        "events": list(batch.events),
        "status": _status_to_json(batch.status) if batch.status is not None else None,
        "final": batch.final,
    }


def batch_from_json(data: Any) -> LiveBatch:
    data = _object(data, "a live batch")
    try:
        samples = tuple(
            Sample(str(topic), str(type_name), int(time_ns), _unb64(text), float(wall), int(skip))
            for topic, type_name, time_ns, text, wall, skip in data.get("samples", [])
        )
        events = tuple(_object(event, "a live event") for event in data.get("events", []))
        status = data.get("status")
        return LiveBatch(
            run_id=str(data["run_id"]),
            samples=samples,
            events=events,
            status=_status_from_json(status) if status is not None else None,
            final=bool(data.get("final", False)),
        )
    except (KeyError, TypeError, ValueError) as error:
        if isinstance(error, WireError):
            raise
        raise WireError(f"a live batch on the wire is malformed: {error!r}") from None


def _status_to_json(status: RunStatus) -> dict[str, Any]:
    return {name: getattr(status, name) for name in RunStatus.__slots__}


def _status_from_json(data: Any) -> RunStatus:
    data = _object(data, "a run status")
    missing = [name for name in RunStatus.__slots__ if name not in data]
    if missing:
        raise WireError(f"a run status on the wire lacks {', '.join(missing)}")
    return RunStatus(**{name: data[name] for name in RunStatus.__slots__})


# ------------------------------------------------------------------------------------ commands
@dataclass(frozen=True, slots=True)
class CommandRequest:
    """A typed command (server/runs/commands.py) for a run, with an id its answer carries."""

    request_id: str
    run_id: str
    command: RunCommand


@dataclass(frozen=True, slots=True)
class CommandAnswer:
    """`taken`: the run is held here and took it; `refusal`: its state refused it now (the
    sentence a 409 shows); neither: the run is not running here (any more)."""

    request_id: str
    taken: bool
    refusal: str | None = None
    extra: dict[str, Any] = field(default_factory=dict)


def request_to_json(request: CommandRequest) -> dict[str, Any]:
    return {
        "request_id": request.request_id,
        "run_id": request.run_id,
        "command": command_dict(request.command),
    }


def request_from_json(data: Any) -> CommandRequest:
    data = _object(data, "a command request")
    try:
        return CommandRequest(
            str(data["request_id"]), str(data["run_id"]), parse_command(data["command"])
        )
    except KeyError as error:
        raise WireError(f"a command request on the wire lacks {error}") from None
    except CommandError as error:
        raise WireError(f"a command request on the wire is not a command: {error}") from None


def answer_to_json(answer: CommandAnswer) -> dict[str, Any]:
    return {
        "request_id": answer.request_id,
        "taken": answer.taken,
        "refusal": answer.refusal,
        "extra": answer.extra,
    }


def answer_from_json(data: Any) -> CommandAnswer:
    data = _object(data, "a command answer")
    try:
        return CommandAnswer(
            str(data["request_id"]),
            bool(data["taken"]),
            data.get("refusal"),
            dict(data.get("extra") or {}),
        )
    except KeyError as error:
        raise WireError(f"a command answer on the wire lacks {error}") from None


# ------------------------------------------------------------------------------------ helpers
def dumps(data: dict[str, Any]) -> bytes:
    """Compact JSON bytes; NaN and infinities are refused (JSON has none)."""
    return json.dumps(data, separators=(",", ":"), allow_nan=False).encode()


def loads(raw: bytes | str) -> Any:
    """The value of JSON bytes or text. msgspec reads it: 1.6 us for a 1.7 KB live batch where
    `json` took 5.5 (every batch of every viewed run is read on the web side); like `dumps` it
    refuses NaN and infinities."""
    try:
        return msgspec.json.decode(raw)
    except (ValueError, UnicodeDecodeError) as error:
        raise WireError(f"a message on the wire is not JSON: {error}") from None


def _object(data: Any, what: str) -> dict[str, Any]:
    if not isinstance(data, dict):
        raise WireError(f"{what} on the wire must be a JSON object, got {type(data).__name__}")
    return data


def _floats(values: Any, count: int) -> tuple[float, ...] | None:
    if values is None:
        return None
    if not isinstance(values, list) or len(values) != count:
        raise WireError(f"expected a list of {count} numbers, got {values!r}")
    numbers = tuple(float(value) for value in values)
    if not all(math.isfinite(number) for number in numbers):
        raise WireError(f"expected finite numbers, got {values!r}")
    return numbers


def _json_only(values: dict[str, object], what: str) -> dict[str, object]:
    try:
        json.dumps(values, allow_nan=False)
    except (TypeError, ValueError) as error:
        raise WireError(f"{what} cannot cross to a worker as JSON: {error}") from None
    return values


def _b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


def _unb64(text: Any) -> bytes:
    if not isinstance(text, str):
        raise WireError(f"expected base64 text, got {type(text).__name__}")
    try:
        return base64.b64decode(text, validate=True)
    except ValueError as error:
        raise WireError(f"bad base64 on the wire: {error}") from None
