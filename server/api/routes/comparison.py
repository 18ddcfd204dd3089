"""Sim-vs-real: GET /api/runs/{id}/comparison puts a hardware run beside the simulation run of
the same code that passed its gate (server/service/comparison.py does the comparing).

Who may see it is the hardware run's rule: its owner or an instructor; anyone else is answered
404, as for a run that does not exist."""

from __future__ import annotations

from pathlib import Path

from fastapi import APIRouter, Depends, HTTPException, Request

from server.api.auth import Caller, current_user
from server.api.routes.runs import files_of, service_of
from server.runs.recorder import RECORDING_FILE
from server.service import comparison
from server.store import runs as run_store

router = APIRouter(prefix="/api/runs", tags=["runs"])


@router.get(
    "/{run_id}/comparison",
    summary="Sim-vs-real: a hardware run against the simulation run that passed its gate",
)
def compare(run_id: str, request: Request, caller: Caller = Depends(current_user)) -> dict:
    real = files_of(request, caller, run_id)
    if real.hardware is None:
        raise HTTPException(
            409,
            f"run {run_id} ran in simulation; open the comparison from a run on a real robot "
            "(it links to the simulation run that passed its gate)",
        )
    if real.simulation_run_id is None:
        raise HTTPException(
            409,
            f"run {run_id} on '{real.hardware}' has no simulation run linked: it started "
            "without passing the simulation gate (the gate was waived, or the run is older "
            "than the link); run the same code in simulation, then on the robot again",
        )
    with request.app.state.store.session() as db:
        simulated = run_store.get(db, real.simulation_run_id)
    if simulated is None:
        raise HTTPException(
            404,
            f"the simulation run {real.simulation_run_id} this run passed its gate with was "
            "deleted; run the same code in simulation, then on the robot again",
        )
    service = service_of(request)
    for record in (real, simulated):
        if service.is_running(record.id):
            raise HTTPException(
                409, f"run {record.id} is still going; the comparison is made once it has ended"
            )
    if simulated.files_removed_at is not None:
        files_of(request, caller, simulated.id)  # answers 410 with the retention sentence
    sim_rec = comparison.read_recording(Path(simulated.run_dir) / RECORDING_FILE)
    real_rec = comparison.read_recording(Path(real.run_dir) / RECORDING_FILE, true_pose=False)
    return {
        "hardware_run": real.id,
        "simulation_run": simulated.id,
        "robot": real.hardware,
        "kind": real.robot,
        "exercise": real.exercise_id,
        "states": {comparison.SIMULATION: simulated.state, comparison.HARDWARE: real.state},
        "scores": {comparison.SIMULATION: simulated.score, comparison.HARDWARE: real.score},
        "durations_s": {
            comparison.SIMULATION: simulated.sim_time_s,
            comparison.HARDWARE: real.sim_time_s,
        },
        "checks": comparison.compare_checks(simulated.checks or [], real.checks or []),
        **comparison.overlay(sim_rec, real_rec),
        "links": {
            "hardware_run": f"/api/runs/{real.id}",
            "simulation_run": f"/api/runs/{simulated.id}",
        },
    }
