"""The robots on the bench for students: which there are, whether connected, the queue for
each (join, leave, my position and estimated start); the simulation gate before a hardware run;
the emergency stop. Instructors reorder and skip in the queue and take robots out of service
(`/api/admin/robots`)."""

from __future__ import annotations

import time

from fastapi import APIRouter, Depends, HTTPException, Request
from fastapi.responses import JSONResponse
from pydantic import Field

from server.api.auth import Caller, current_user, instructor
from server.api.routes.admin_robots import robot_or_404
from server.api.schemas import Strict
from server.hardware.queue import QueueError
from server.store import robots as inventory
from server.store import runs as run_store
from server.store.models import RobotEntry

router = APIRouter(tags=["hardware"])


def _hub(request: Request):
    return request.app.state.hardware


def _entry(request: Request, name: str) -> RobotEntry:
    with request.app.state.store.session() as db:
        return robot_or_404(db, name)


@router.get("/api/hardware", summary="The robots on the bench, their state and queues")
def robots(request: Request, caller: Caller = Depends(current_user)) -> dict:
    hub, now = _hub(request), time.monotonic()
    with request.app.state.store.session() as db:
        entries = inventory.listing(db)
    out = []
    for entry in entries:
        queue = hub.queue(entry.name)
        described = queue.describe(now)
        mine = queue.position(caller.id)
        health = hub.health(entry.name)
        if not caller.is_instructor:  # students see positions, not who holds them
            for place in described["places"]:
                place.pop("user_id")
                place.pop("run_id")
        out.append(
            {
                "name": entry.name,
                "kind": entry.kind,
                "in_service": entry.in_service,
                "connection": health.sentence,
                "health": health.as_dict(),
                "queue": described,
                "my_position": mine,
                "my_estimated_wait_s": (
                    round(queue.estimated_wait_s(caller.id, now), 1) if mine else None
                ),
            }
        )
    return {"robots": out}


@router.post("/api/hardware/{name}/queue", summary="Join the queue for a robot (one place each)")
def join(name: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    entry = _entry(request, name)
    if not entry.in_service:
        raise HTTPException(409, f"'{name}' is out of service; ask your instructor")
    queue, now = _hub(request).queue(name), time.monotonic()
    place = queue.join(caller.id, now)
    return {
        "robot": name,
        "position": queue.position(caller.id),
        "state": str(place.state),
        "estimated_wait_s": round(queue.estimated_wait_s(caller.id, now), 1),
        "start_within_s": queue.start_within_s if place.offered_until_s else None,
    }


@router.delete("/api/hardware/{name}/queue", summary="Leave the queue for a robot")
def leave(name: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    _entry(request, name)
    _hub(request).queue(name).leave(caller.id, time.monotonic())
    return {"ok": True}


class QueueMove(Strict):
    user_id: str = Field(max_length=64)
    position: int = Field(1, ge=1, le=10_000)


@router.post("/api/admin/hardware/{name}/queue/move", summary="Move a waiting student")
def move(name: str, body: QueueMove, request: Request, _: Caller = Depends(instructor)) -> dict:
    _entry(request, name)
    queue = _hub(request).queue(name)
    try:
        queue.move(body.user_id, body.position, time.monotonic())
    except QueueError as error:
        raise HTTPException(409, str(error)) from None
    return queue.describe(time.monotonic())


@router.post("/api/admin/hardware/{name}/queue/skip", summary="Take a student out of a queue")
def skip(name: str, body: QueueMove, request: Request, _: Caller = Depends(instructor)) -> dict:
    _entry(request, name)
    queue = _hub(request).queue(name)
    try:
        queue.skip(body.user_id, time.monotonic())
    except QueueError as error:
        raise HTTPException(409, str(error)) from None
    return queue.describe(time.monotonic())


def simulation_gate(request: Request, user_id: str, exercise_id: str | None, robot: str,
                    nodes: list[dict]) -> dict:  # fmt: skip
    """The verdict: has this code finished a simulation run of the same exercise (or robot)?"""
    with request.app.state.store.session() as db:
        passed = run_store.finished_simulation_run(db, user_id, exercise_id, robot, nodes)
    if passed is not None:
        return {
            "passed": True,
            "simulation_run": passed,
            "reason": "this code finished a simulation run of the same exercise",
        }
    what = f"exercise '{exercise_id}'" if exercise_id else f"the {robot} in free play"
    return {
        "passed": False,
        "simulation_run": None,
        "reason": f"run this exact code in simulation ({what}) until it finishes without an "
        "error, then try the real robot",
    }


def gate_refusal(verdict: dict) -> JSONResponse:
    return JSONResponse(status_code=409, content={"detail": verdict["reason"], "gate": verdict})
