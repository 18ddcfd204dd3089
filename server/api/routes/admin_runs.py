"""Instructor admin API, runs: everyone's runs with filters, stop any run, the server's status
(with the disk used by runs), the retention of old runs' files."""

from __future__ import annotations

import os
import time
from datetime import datetime
from typing import Literal

import psutil
from fastapi import APIRouter, Depends, HTTPException, Query, Request
from pydantic import BaseModel, Field
from sqlalchemy import select

from server.api.auth import Caller, instructor
from server.api.routes.runs import run_out
from server.runs.state import RunState
from server.service import disk
from server.store import runs as run_store
from server.store.models import User

router = APIRouter(prefix="/api/admin", tags=["admin"])
STARTED = time.time()


def _epoch(value: datetime | None, name: str) -> float | None:
    if value is None:
        return None
    return value.timestamp() if value.tzinfo else value.replace(tzinfo=None).timestamp()


@router.get("/runs", summary="Every run, newest first, filtered by user, exercise, state, date")
def all_runs(
    request: Request,
    _: Caller = Depends(instructor),
    user: str | None = Query(None, max_length=64),
    exercise: str | None = Query(None, max_length=64),
    state: RunState | Literal["active"] | None = Query(
        None, description="a run state, or 'active' for every state before the end"
    ),
    since: datetime | None = Query(None, description="created at or after (ISO 8601)"),
    until: datetime | None = Query(None, description="created before (ISO 8601)"),
    limit: int = Query(100, ge=1, le=500),
    offset: int = Query(0, ge=0, le=10**9),
) -> dict:
    where = run_store.RunFilter(
        user_id=user,
        exercise_id=exercise,
        state=str(state) if state else None,
        since=_epoch(since, "since"),
        until=_epoch(until, "until"),
        limit=limit,
        offset=offset,
    )
    with request.app.state.store.session() as db:
        rows, total = run_store.listing(db, where)
        names = {
            user.id: user.name
            for user in db.scalars(select(User).where(User.id.in_({r.user_id for r in rows})))
        }
    service = request.app.state.runs
    runs = []
    for record in rows:
        out = run_out(record, service)
        out["user_name"] = names.get(record.user_id)
        runs.append(out)
    return {"total": total, "runs": runs}


@router.post("/runs/{run_id}/stop", summary="Stop anyone's run")
def stop_any(run_id: str, request: Request, _: Caller = Depends(instructor)) -> dict:
    with request.app.state.store.session() as db:
        record = run_store.get(db, run_id)
    if record is None:
        raise HTTPException(404, f"no run '{run_id}'")
    if not request.app.state.runs.stop(run_id, "stopped by an instructor"):
        raise HTTPException(409, f"run {run_id} has ended ({record.state}); nothing to stop")
    return {"ok": True, "id": run_id, "action": "stop"}


def _sandbox_processes() -> dict:
    """Processes below the server: the sandboxes (bwrap and the runners inside)."""
    me = psutil.Process(os.getpid())
    children = me.children(recursive=True)
    rss = 0
    for child in children:
        try:
            rss += child.memory_info().rss
        except psutil.Error:
            continue
    return {"count": len(children), "rss_mib": round(rss / 2**20, 1)}


@router.get("/status", summary="Active runs, sandbox processes, CPU, memory, queues")
def status(request: Request, _: Caller = Depends(instructor)) -> dict:
    me = psutil.Process(os.getpid())
    memory = psutil.virtual_memory()
    service = request.app.state.runs
    with request.app.state.store.session() as db:
        stored_active = run_store.active_count(db)
        disk_use = disk.disk_status(db, request.app.state.settings)
    return {
        "uptime_s": round(time.time() - STARTED, 1),
        "runs": service.status(),
        "stored_active_runs": stored_active,
        "sandbox": _sandbox_processes(),
        "server": {
            "rss_mib": round(me.memory_info().rss / 2**20, 1),
            "threads": me.num_threads(),
            "cpu_percent": me.cpu_percent(interval=None),
        },
        "machine": {
            "cpus": psutil.cpu_count(),
            "load_average": [round(x, 2) for x in os.getloadavg()],
            "memory_used_percent": memory.percent,
            "memory_available_mib": round(memory.available / 2**20),
        },
        "queues": {"waiting_runs": 0, "note": "runs start at once or are refused with 429"},
        "database": request.app.state.store.dialect,
        "disk": disk_use,
        "hardware": {
            "rosserial_port": request.app.state.hardware.port,
            "listening": request.app.state.hardware.listen_error or "yes",
            "problems": request.app.state.hardware.problems(),
        },
    }


class RetentionIn(BaseModel):
    retention_days: float = Field(
        ge=0, le=3650, description="days ended runs keep their files; 0 = forever"
    )


@router.get("/retention", summary="How long ended runs keep their files (0 = forever)")
def get_retention(request: Request, _: Caller = Depends(instructor)) -> dict:
    with request.app.state.store.session() as db:
        return {"retention_days": disk.retention_days(db, request.app.state.settings)}


@router.put("/retention", summary="Set the retention; old runs' files are removed at once")
def set_retention(body: RetentionIn, request: Request, _: Caller = Depends(instructor)) -> dict:
    store, settings = request.app.state.store, request.app.state.settings
    with store.session() as db:
        disk.set_retention_days(db, body.retention_days)
    swept = disk.sweep(store, settings)  # the instructor sees the effect now, not in an hour
    return {
        "retention_days": body.retention_days,
        "runs_with_files_removed_now": swept.removed,
        "freed_bytes": swept.freed_bytes,
    }
