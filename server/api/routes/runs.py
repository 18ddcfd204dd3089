"""Runs: start one, list mine, look at one, stop/pause/resume it, and download what it left:
the MCAP recording, a CSV per topic, the logs and the files the code saved.

A run that is not the caller's is answered 404, exactly as one that does not exist
(instructors see every run)."""

from __future__ import annotations

import json
import threading
from datetime import UTC, datetime
from pathlib import Path

from fastapi import APIRouter, Depends, HTTPException, Query, Request
from fastapi.responses import FileResponse, PlainTextResponse

from sandbox.protocol import Clock
from server.api.auth import Caller, current_user
from server.api.schemas import RunCommand, RunCreate
from server.runs import commands
from server.runs.export import csv_file_name, export_csv
from server.runs.launch import LaunchPlan
from server.runs.recorder import ARTIFACTS_DIR, LOGS_DIR, RECORDING_FILE
from server.runs.safe_paths import inside, safe_relative_path
from server.runs.spec import NodeSpec
from server.runs.state import RunState
from server.service import catalog, disk, exercises, workspace_files, workspace_runs
from server.service.runs import RunRequest, RunService, node_spec
from server.store import runs as run_store
from server.store.models import RunRecord

router = APIRouter(prefix="/api/runs", tags=["runs"])
NOT_FOUND = "no such run (or it is not yours)"
_csv_lock = threading.Lock()  # one export per run at a time


def iso(epoch: float | None) -> str | None:
    return datetime.fromtimestamp(epoch, UTC).isoformat() if epoch is not None else None


def _live_state(state: RunState) -> str:
    """An ended run still in the service is being judged and stored: its end (with the score)
    shows once the store has it, so a client never sees 'finished' without its checks."""
    return str(RunState.STOPPING) if state.is_end else str(state)


def run_out(record: RunRecord, service: RunService, with_code: bool = False) -> dict:
    """The run as the API shows it: the stored record, with what a running run is doing now
    (its state, time and loop periods, read through the service) while it runs."""
    live = service.live(record.id)
    out = {
        "id": record.id,
        "user_id": record.user_id,
        "exercise": record.exercise_id,
        "robot": record.robot,
        "world": record.world,
        "clock": record.clock,
        "ros_version": live.ros_version if live else (record.metrics or {}).get("ros_version", 1),
        "duration_s": record.duration_s,
        "seed": record.seed,
        "hardware": record.hardware,
        "simulation_run": record.simulation_run_id,  # a hardware run: the gate's simulation run
        "state": _live_state(live.state) if live else record.state,
        "reason": record.reason,
        "created_at": iso(record.created_at),
        "started_at": iso(record.started_at),
        "ended_at": iso(record.ended_at),
        "time_s": live.time_s if live else record.sim_time_s,
        "wall_s": record.wall_s,
        "metrics": record.metrics,
        "nodes": record.nodes,
        "checks": record.checks,
        "score": record.score,
        "disk_bytes": record.disk_bytes,  # [B] measured when the run ended
        "files_removed": record.files_removed_at is not None,  # by the lab's retention
        "links": {
            "self": f"/api/runs/{record.id}",
            "live": f"/api/runs/{record.id}/live",
            "recording": f"/api/runs/{record.id}/recording.mcap",
            "logs": f"/api/runs/{record.id}/logs",
            "artifacts": f"/api/runs/{record.id}/artifacts",
            "csv": f"/api/runs/{record.id}/csv",
            "graph": f"/api/runs/{record.id}/graph",
            "viz": f"/api/runs/{record.id}/viz/",
        },
    }
    if record.simulation_run_id is not None:  # sim-vs-real: this robot run against its gate run
        out["links"]["comparison"] = f"/api/runs/{record.id}/comparison"
        out["links"]["simulation_run"] = f"/api/runs/{record.simulation_run_id}"
    if with_code:
        out["code"] = record.code
    if live is not None:
        out["nodes_live"] = {name: {"period": period} for name, period in live.node_periods.items()}
    return out


def visible_run(request: Request, caller: Caller, run_id: str) -> RunRecord:
    with request.app.state.store.session() as db:
        record = run_store.get(db, run_id)
    if record is None or not caller.can_see(record.user_id):
        raise HTTPException(404, NOT_FOUND)
    return record


def files_of(request: Request, caller: Caller, run_id: str) -> RunRecord:
    """A run whose files are asked for: 410 Gone when retention removed them."""
    record = visible_run(request, caller, run_id)
    if record.files_removed_at is not None:
        with request.app.state.store.session() as db:
            days = disk.retention_days(db, request.app.state.settings)
        raise HTTPException(410, disk.files_removed_sentence(record, days))
    return record


def service_of(request: Request) -> RunService:
    return request.app.state.runs


def file_answer(*media_types: str) -> dict:
    """A route's OpenAPI `responses` for a file: its real content type(s), not FastAPI's
    default JSON (which clients and schemathesis' content-type check would believe)."""
    binary = {"schema": {"type": "string", "format": "binary"}}
    return {200: {"description": "the file", "content": {m: binary for m in media_types}}}


# OpenAPI links from a started run to what can be read or done with it (OpenAPI 3.1 section
# 4.8.20): clients and schemathesis' stateful tests follow `id` instead of guessing `run_id`.
RUN_LINKS = {
    f"{method}{path.replace('/', '_').replace('.', '_')}": {
        "operationRef": "#/paths/~1api~1runs~1{run_id}" + path.replace("/", "~1") + f"/{method}",
        "parameters": {"run_id": "$response.body#/id"},
    }
    for method, path in [
        ("get", ""),
        ("get", "/logs"),
        ("get", "/csv"),
        ("get", "/metrics.json"),
        ("get", "/graph"),
        ("get", "/artifacts"),
        ("get", "/recording.mcap"),
        ("post", "/stop"),
    ]
}


@router.post(
    "",
    status_code=201,
    summary="Start a run (an exercise, or a robot in a world)",
    openapi_extra={"responses": {"201": {"links": RUN_LINKS}}},
)
def create(body: RunCreate, request: Request, caller: Caller = Depends(current_user)) -> dict:
    service = service_of(request)
    entry = None
    if body.exercise is not None:
        with request.app.state.store.session() as db:
            entry = exercises.find(db, body.exercise)
        if body.robot not in (None, entry.exercise.robot) or body.world not in (
            None,
            entry.exercise.world,
        ):
            raise HTTPException(
                422,
                f"exercise '{entry.exercise.id}' uses robot '{entry.exercise.robot}' in world "
                f"'{entry.exercise.world}'; leave robot and world out",
            )
    else:
        if body.robot is None or body.world is None:
            raise HTTPException(
                422, "give an exercise, or a robot and a world: {robot, world, nodes}"
            )
        catalog.check_robot(body.robot)
        catalog.check_world(body.world)
    nodes, plan, files = _nodes_and_files(request, caller, body, entry)
    gated = request.app.state.settings.hardware_gate and (
        entry is None or entry.exercise.hardware_gate
    )
    simulation_run = None  # the simulation run of this code, kept for the sim-vs-real report
    if body.hardware is not None:
        from server.api.routes.hardware import gate_refusal, simulation_gate

        robot = entry.exercise.robot if entry else body.robot
        verdict = simulation_gate(
            request, caller.id, entry.exercise.id if entry else None, robot,
            [{"name": n.name, "code": n.code} for n in nodes],
        )  # fmt: skip
        if gated and not verdict["passed"]:
            return gate_refusal(verdict)
        simulation_run = verdict["simulation_run"]  # None where a waived gate found none
    request_ = RunRequest(
        robot=body.robot,
        world=body.world,
        exercise=entry,
        nodes=nodes,
        teleop=body.teleop,
        hardware=body.hardware,
        simulation_run=simulation_run,
        clock=Clock(body.clock) if body.clock else None,
        duration_s=body.duration,
        seed=body.seed,
        case=body.case,
        params=dict(plan.params) if plan else {},
        files=files,
    )
    record = service.start(caller.id, request_)
    out = run_out(record, service)
    if plan is not None:
        out["launch"] = {"file": body.launch.file, "notes": list(plan.notes)}
    return out


def _nodes_and_files(
    request: Request, caller: Caller, body: RunCreate, entry
) -> tuple[tuple[NodeSpec, ...], LaunchPlan | None, tuple[tuple[str, bytes], ...]]:
    """The nodes (sent, or named by a launch file of the caller's workspace), the launch plan
    (global parameters, notes) and the workspace's data files for every node."""
    workspace = body.workspace
    if workspace is None and body.launch is not None:
        workspace = entry.exercise.id if entry else body.robot
    files: dict[str, str] = {}
    if workspace is not None:
        with request.app.state.store.session() as db:
            files = workspace_runs.contents(db, caller.id, workspace)
    plan = None
    if body.launch is not None:
        service = service_of(request)
        plan = workspace_runs.launch_plan(
            files,
            body.launch.file,
            body.launch.args,
            service.launcher,
            lambda: service.launch_file_job(caller.id),  # one of the student's sandbox jobs
        )
        nodes = plan.nodes
    else:
        nodes = tuple(
            node_spec(
                n.name,
                n.code,
                params=dict(n.params),
                remaps=tuple(n.remaps.items()),
                args=tuple(n.args),
                namespace=n.namespace,
            )
            for n in body.nodes or ()
        )
    return nodes, plan, workspace_files.data_files(files.items())


@router.get("", summary="My runs, newest first")
def listing(
    request: Request,
    caller: Caller = Depends(current_user),
    exercise: str | None = Query(None, max_length=64),
    robot: str | None = Query(None, max_length=32, description="only runs of this robot"),
    limit: int = Query(50, ge=1, le=500),
    offset: int = Query(0, ge=0, le=10**9),
) -> dict:
    where = run_store.RunFilter(
        user_id=caller.id, exercise_id=exercise, robot=robot, limit=limit, offset=offset
    )
    with request.app.state.store.session() as db:
        rows, total = run_store.listing(db, where)
    service = service_of(request)
    return {"total": total, "runs": [run_out(r, service) for r in rows]}


@router.get("/{run_id}", summary="One run: state, reason, metrics, periods, checks")
def one(run_id: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    return run_out(visible_run(request, caller, run_id), service_of(request), with_code=True)


def _command(request: Request, caller: Caller, run_id: str, command: commands.RunCommand) -> dict:
    record = visible_run(request, caller, run_id)
    try:
        running = service_of(request).command(record.id, command)
    except commands.CommandError as error:
        raise HTTPException(409, str(error)) from None
    if not running:
        what = "stop" if isinstance(command, commands.EmergencyStop) else command.op
        raise HTTPException(409, f"run {run_id} has ended ({record.state}); nothing to {what}")
    return {"ok": True, "id": run_id, "action": command.op}


def stop_by(caller: Caller, note: str | None = None) -> commands.Stop:
    """The stop a caller sends: who stopped the run is the login's to say, never the client's
    (a note the client adds comes after it)."""
    return commands.Stop(f"stopped by {caller.who}" + (f": {note}" if note else ""))


def emergency_stop_by(caller: Caller) -> commands.EmergencyStop:
    """The emergency stop a caller sends, named after the login, not after what a client says."""
    return commands.EmergencyStop(caller.who)


@router.post("/{run_id}/stop", summary="Stop a run (the robot is commanded to stop)")
def stop(
    run_id: str,
    request: Request,
    body: RunCommand | None = None,
    caller: Caller = Depends(current_user),
) -> dict:
    return _command(request, caller, run_id, stop_by(caller, body.reason if body else None))


@router.post("/{run_id}/estop", summary="Emergency stop: the robot stops now")
def emergency_stop(run_id: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    return _command(request, caller, run_id, emergency_stop_by(caller))


@router.post("/{run_id}/pause", summary="Pause a lockstep run")
def pause(run_id: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    return _command(request, caller, run_id, commands.Pause())


@router.post("/{run_id}/resume", summary="Resume a paused run")
def resume(run_id: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    return _command(request, caller, run_id, commands.Resume())


def _run_file(record: RunRecord, relative: str) -> Path:
    root = Path(record.run_dir)
    try:
        path = inside(root, safe_relative_path(relative))
    except ValueError:
        raise HTTPException(404, f"no file '{relative}' in this run") from None
    if not path.is_file():
        raise HTTPException(404, f"no file '{relative}' in this run")
    return path


@router.get(
    "/{run_id}/recording.mcap",
    summary="The run's recording (MCAP, as rosbag2 for ROS 2)",
    response_class=FileResponse,
    responses=file_answer("application/octet-stream"),
)
def recording(run_id: str, request: Request, caller: Caller = Depends(current_user)):
    record = files_of(request, caller, run_id)
    path = Path(record.run_dir) / RECORDING_FILE
    if not path.is_file():
        raise HTTPException(404, "this run has no recording (it failed before it started)")
    return FileResponse(
        path, media_type="application/octet-stream", filename=f"robodojo-{run_id}.mcap"
    )


@router.get("/{run_id}/csv", summary="The topics with a CSV file each (after the run ended)")
def csv_list(run_id: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    record = files_of(request, caller, run_id)
    folder = _export(request, record)
    return {
        "files": [
            {"name": p.name, "url": f"/api/runs/{run_id}/csv/{p.name}"}
            for p in sorted(folder.glob("*.csv"))
        ]
    }


@router.get(
    "/{run_id}/csv/{name}",
    summary="One topic as CSV",
    response_class=FileResponse,
    responses=file_answer("text/csv"),
)
def csv_file(run_id: str, name: str, request: Request, caller: Caller = Depends(current_user)):
    record = files_of(request, caller, run_id)
    folder = _export(request, record)
    wanted = name if name.endswith(".csv") else csv_file_name(name)
    path = folder / wanted
    if "/" in wanted or not path.is_file():
        names = ", ".join(sorted(p.name for p in folder.glob("*.csv")))
        raise HTTPException(404, f"no CSV '{name}' in this run; its files: {names}")
    return FileResponse(path, media_type="text/csv", filename=f"{run_id}-{wanted}")


def _export(request: Request, record: RunRecord) -> Path:
    if service_of(request).is_running(record.id):
        raise HTTPException(409, "the run is still going; CSV files are made when it has ended")
    recording_path = Path(record.run_dir) / RECORDING_FILE
    if not recording_path.is_file():
        raise HTTPException(404, "this run has no recording (it failed before it started)")
    folder = Path(record.run_dir) / "csv"
    with _csv_lock:
        if not (folder / ".done").is_file():
            export_csv(recording_path, folder)
            (folder / ".done").write_text("")
    return folder


@router.get("/{run_id}/logs", summary="What each node printed")
def logs(run_id: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    record = files_of(request, caller, run_id)
    running = service_of(request).logs(record.id)
    if running is not None:
        return {"nodes": running}
    folder = Path(record.run_dir) / LOGS_DIR
    nodes = {}
    if folder.is_dir():
        for path in sorted(folder.glob("*.log")):
            nodes[path.stem] = path.read_text("utf-8", errors="replace").splitlines()
    return {"nodes": nodes}


@router.get(
    "/{run_id}/logs/{node}.log",
    summary="One node's log as text",
    response_class=PlainTextResponse,
    responses=file_answer("text/plain"),
)
def log_file(run_id: str, node: str, request: Request, caller: Caller = Depends(current_user)):
    record = files_of(request, caller, run_id)
    path = _run_file(record, f"{LOGS_DIR}/{node}.log")
    return PlainTextResponse(path.read_text("utf-8", errors="replace"))


@router.get("/{run_id}/metrics.json", summary="Full metrics with histograms")
def metrics_file(run_id: str, request: Request, caller: Caller = Depends(current_user)):
    record = files_of(request, caller, run_id)
    path = _run_file(record, "metrics.json")
    return json.loads(path.read_text("utf-8"))


@router.get("/{run_id}/graph", summary="Nodes and topics with measured rates (rqt_graph)")
def graph(run_id: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    record = files_of(request, caller, run_id)
    running = service_of(request).graph(record.id)
    if running is not None:
        return running
    return json.loads(_run_file(record, "graph.json").read_text("utf-8"))


@router.get("/{run_id}/artifacts", summary="Files the nodes saved")
def artifact_list(run_id: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    record = files_of(request, caller, run_id)
    folder = Path(record.run_dir) / ARTIFACTS_DIR
    files = []
    if folder.is_dir():
        for path in sorted(p for p in folder.rglob("*") if p.is_file()):
            name = path.relative_to(folder).as_posix()
            files.append(
                {
                    "name": name,
                    "bytes": path.stat().st_size,
                    "url": f"/api/runs/{run_id}/artifacts/{name}",
                }
            )
    return {"files": files}


@router.get(
    "/{run_id}/artifacts/{name:path}",
    summary="One saved file",
    response_class=FileResponse,
    responses=file_answer("*/*"),
)
def artifact(run_id: str, name: str, request: Request, caller: Caller = Depends(current_user)):
    record = files_of(request, caller, run_id)
    path = _run_file(record, f"{ARTIFACTS_DIR}/{name}")
    return FileResponse(path, filename=path.name)
