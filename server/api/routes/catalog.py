"""Robots, worlds and exercises: what there is to run. Every logged-in user may read these."""

from __future__ import annotations

from fastapi import APIRouter, Depends, Request

from server.api.auth import Caller, current_user
from server.service import catalog, exercises

router = APIRouter(prefix="/api", tags=["catalog"])


@router.get("/health", summary="Liveness: the server answers and its store opens")
def health(request: Request) -> dict:
    with request.app.state.store.session() as db:
        db.connection()
    return {"ok": True}


@router.get("/robots", summary="The robots, with their topics")
def robots(_: Caller = Depends(current_user)) -> list[dict]:
    return catalog.robots()


@router.get("/worlds", summary="The worlds, with the robots each is meant for")
def worlds(_: Caller = Depends(current_user)) -> list[dict]:
    return catalog.worlds()


@router.get("/exercises", summary="Exercises with their text, starter code and checks")
def exercise_list(request: Request, _: Caller = Depends(current_user)) -> list[dict]:
    with request.app.state.store.session() as db:
        return [catalog.describe(entry) for entry in exercises.all_entries(db)]


@router.get("/exercises/{exercise_id}", summary="One exercise")
def exercise_one(exercise_id: str, request: Request, _: Caller = Depends(current_user)) -> dict:
    with request.app.state.store.session() as db:
        return catalog.describe(exercises.find(db, exercise_id))
