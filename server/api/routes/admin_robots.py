"""Instructor admin API, the robots on the bench: register one (kind, transport, address,
limits), list them with their connection state, take one out of service, remove it."""

from __future__ import annotations

import math
import time
from typing import Literal

from fastapi import APIRouter, Depends, HTTPException, Request
from pydantic import Field, field_validator

from server.api.auth import Caller, instructor
from server.api.schemas import Strict
from server.hardware.health import assess
from server.hardware.safety import DEFAULT_WATCHDOG_S, MotionLimits
from server.sim import get_robot
from server.store import robots as inventory
from server.store.models import RobotEntry

router = APIRouter(prefix="/api/admin/robots", tags=["admin"], dependencies=[Depends(instructor)])
# Which simulated robot a real one stands for, and how it is reached.
TRANSPORTS = {"crowbot": "rosserial", "turtlebot": "create_oi"}
ACCEL_FROM_SPEED_PER_S = 2.0  # [1/s] default acceleration limit: full speed in half a second


class LimitsIn(Strict):
    max_linear_m_s: float = Field(gt=0, le=5)
    max_angular_rad_s: float = Field(gt=0, le=20)
    max_linear_accel_m_s2: float = Field(gt=0, le=20)
    max_angular_accel_rad_s2: float = Field(gt=0, le=100)


class RobotIn(Strict):
    name: str = Field(pattern=r"^[a-z][a-z0-9_\-]{0,63}$", description="e.g. crowbot-1")
    kind: Literal["crowbot", "turtlebot"]
    address: str = Field(
        min_length=1, max_length=255, description="rosserial: the robot's IP; create_oi: port"
    )
    baud: int | None = Field(None, ge=300, le=4_000_000)
    limits: LimitsIn | None = None  # default: the simulated robot's, accelerations from them
    watchdog_s: float = Field(DEFAULT_WATCHDOG_S, gt=0.05, le=5.0)

    @field_validator("address")
    @classmethod
    def _no_control_characters(cls, value: str) -> str:
        if any(ord(c) < 32 for c in value):
            raise ValueError("the address holds control characters")
        return value


class RobotUpdate(Strict):
    in_service: bool


def default_limits(kind: str) -> dict:
    model = get_robot(kind).limits
    limits = MotionLimits(
        model.max_linear_m_s,
        model.max_angular_rad_s,
        model.max_linear_m_s * ACCEL_FROM_SPEED_PER_S,
        model.max_angular_rad_s * ACCEL_FROM_SPEED_PER_S,
    )
    return {name: getattr(limits, name) for name in MotionLimits.__slots__}


def robot_out(entry: RobotEntry, request: Request) -> dict:
    hub = getattr(request.app.state, "hardware", None)
    health = hub.health(entry.name) if hub else assess(None)
    return {
        "id": entry.id,
        "name": entry.name,
        "kind": entry.kind,
        "transport": entry.transport,
        "address": entry.address,
        "baud": entry.baud,
        "limits": entry.limits,
        "watchdog_s": entry.watchdog_s,
        "in_service": entry.in_service,
        "connection": health.sentence,
        "health": health.as_dict(),
    }


@router.post("", status_code=201, summary="Register a robot on the bench")
def add_robot(body: RobotIn, request: Request) -> dict:
    limits = body.limits.model_dump() if body.limits else default_limits(body.kind)
    if not all(math.isfinite(v) for v in limits.values()):
        raise HTTPException(422, "limits must be finite numbers")
    transport = TRANSPORTS[body.kind]
    if transport == "create_oi" and body.baud is None:
        raise HTTPException(422, "a Create/Roomba base needs its serial baud rate (115200)")
    with request.app.state.store.session() as db:
        if inventory.by_name(db, body.name) is not None:
            raise HTTPException(409, f"a robot named '{body.name}' is registered already")
        if inventory.by_address(db, transport, body.address) is not None:
            raise HTTPException(409, f"another robot is registered at '{body.address}'")
        entry = inventory.add(
            db, name=body.name, kind=body.kind, transport=transport, address=body.address,
            baud=body.baud, limits=limits, watchdog_s=body.watchdog_s,
        )  # fmt: skip
        return robot_out(entry, request)


@router.get("", summary="The robots on the bench, with their connection state")
def list_robots(request: Request, _: Caller = Depends(instructor)) -> dict:
    with request.app.state.store.session() as db:
        return {"robots": [robot_out(e, request) for e in inventory.listing(db)]}


def robot_or_404(db, name: str) -> RobotEntry:
    entry = inventory.by_name(db, name)
    if entry is None:
        raise HTTPException(404, f"no robot named '{name}'; robots: {inventory.names(db)}")
    return entry


@router.patch("/{name}", summary="Take a robot out of service, or back in")
def update_robot(name: str, body: RobotUpdate, request: Request) -> dict:
    with request.app.state.store.session() as db:
        entry = robot_or_404(db, name)
        entry.in_service = body.in_service
        out = robot_out(entry, request)
    # Out of service: an offered turn waits, nobody loses their place; back: the next is offered.
    request.app.state.hardware.queue(name).set_in_service(body.in_service, time.monotonic())
    out["in_service"] = body.in_service
    return out


@router.delete("/{name}", summary="Remove a robot from the inventory")
def remove_robot(name: str, request: Request) -> dict:
    with request.app.state.store.session() as db:
        inventory.remove(db, robot_or_404(db, name))
    return {"ok": True}
