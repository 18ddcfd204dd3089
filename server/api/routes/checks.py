"""A check from the student page: GET /api/exercises/{id}/check?runs=a,b,c sums up the runs the
page started for an exercise's grading cases (POST /api/runs with `case` 0, 1, ...), judged as
`robodojo check` judges them (server/service/check_summary.py). The page polls it for the
progress bar and shows each case's checks as soon as that run's are stored.

Every run must be the caller's (an instructor may read anyone's) and of that exercise; a run
that is not is answered 404, exactly as one that does not exist.
"""

from __future__ import annotations

from fastapi import APIRouter, Depends, HTTPException, Query, Request

from server.api.auth import Caller, current_user
from server.api.routes.runs import NOT_FOUND, service_of
from server.exercises.grading import cases_of
from server.service import exercises
from server.service.check_summary import summarize
from server.store import runs as run_store

router = APIRouter(prefix="/api/exercises", tags=["runs"])
RUN_ID_CHARS = 64  # a run id is 32 hex digits; anything longer is not one


@router.get("/{exercise_id}/check", summary="A check's runs (one per grading case), summed up")
def check(
    exercise_id: str,
    request: Request,
    runs: str = Query(..., description="the check's run ids in case order, comma-separated"),
    caller: Caller = Depends(current_user),
) -> dict:
    with request.app.state.store.session() as db:
        exercise = exercises.find(db, exercise_id).exercise
        run_ids = [part.strip() for part in runs.split(",") if part.strip()]
        case_count = len(cases_of(exercise))
        if not run_ids or len(run_ids) > case_count:
            raise HTTPException(
                422,
                f"give 1 to {case_count} run ids, one per grading case of '{exercise_id}' "
                "in case order: ?runs=id0,id1",
            )
        if len(set(run_ids)) != len(run_ids):
            raise HTTPException(422, "a run id appears twice; each case has its own run")
        records = []
        for run_id in run_ids:
            record = run_store.get(db, run_id[:RUN_ID_CHARS])
            if record is None or not caller.can_see(record.user_id):
                raise HTTPException(404, NOT_FOUND)
            if record.exercise_id != exercise.id:
                raise HTTPException(
                    422, f"run {run_id} is not a run of '{exercise_id}'; leave it out"
                )
            records.append(record)
    service = service_of(request)
    times = {}
    for record in records:
        live = service.live(record.id)
        if live is not None:
            times[record.id] = live.time_s
    return summarize(exercise, records, times)
