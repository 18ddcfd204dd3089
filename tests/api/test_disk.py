"""Disk budgets and retention (issue 14, finding 4), through the real server: a student over
their budget, or a lab over its own, gets a sentence and no run; the instructor's retention
removes old runs' files and keeps their metrics; the status shows the bytes runs use.

The tests run in file order on one server: budgets first, then the status, then retention."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.api.conftest import STEP_CONTROLLER, LabServer, start_server, stop_server, wait_for_end

# Its own server, and one graded run the later tests build on: the module is one slow story.
pytestmark = pytest.mark.slow

STUDENT_BUDGET = 1  # [B] any ended run fills it
LAB_BUDGET = 2  # [B] likewise, for everyone


@pytest.fixture(scope="module")
def disk_lab(tmp_path_factory) -> Iterator[LabServer]:
    server = start_server(
        tmp_path_factory.mktemp("disk-lab"),
        {
            "ROBODOJO_STUDENT_DISK_BUDGET_BYTES": str(STUDENT_BUDGET),
            "ROBODOJO_LAB_DISK_BUDGET_BYTES": str(LAB_BUDGET),
            "ROBODOJO_SANDBOX_POOL": "1",
        },
    )
    yield server
    stop_server(server)


@pytest.fixture(autouse=True)
def _close_clients(disk_lab) -> Iterator[None]:
    yield
    disk_lab.close_clients()


def short_run() -> dict:
    return {
        "robot": "crowbot",
        "world": "wall_approach",
        "nodes": [{"name": "drive", "code": STEP_CONTROLLER}],
        "clock": "lockstep",
        "duration": 2,
    }


def _runs_of(lab: LabServer, user_id: str) -> list[dict]:
    return lab.admin().get("/api/admin/runs", params={"user": user_id}).json()["runs"]


def test_a_student_over_budget_and_a_lab_over_budget_get_a_sentence_and_no_run(disk_lab):
    ada = disk_lab.student("ada")
    graded = {"exercise": "crowbot_distance_pid", "duration": 2,
              "nodes": [{"name": "pid", "code": STEP_CONTROLLER}]}  # fmt: skip
    # A judged run: retention must keep its checks and score (the last test).
    first = ada.post("/api/runs", json=graded)
    assert first.status_code == 201, first.text
    ended = wait_for_end(ada, first.json()["id"])
    run_dir = disk_lab.data / "runs" / ended["id"]
    assert ended["disk_bytes"] > 0
    assert ended["disk_bytes"] == sum(p.stat().st_size for p in run_dir.rglob("*") if p.is_file())

    refused = ada.post("/api/runs", json=short_run())
    assert refused.status_code == 507, refused.text
    detail = refused.json()["detail"]
    assert "your runs use" in detail and "your budget is" in detail
    assert "ask your instructor" in detail
    assert len(_runs_of(disk_lab, ada.user["id"])) == 1  # no second run was made

    bob = disk_lab.student("bob")  # nothing of his own on disk: the lab's budget stops him
    refused = bob.post("/api/runs", json=short_run())
    assert refused.status_code == 507, refused.text
    detail = refused.json()["detail"]
    assert "the lab's runs and saved code use" in detail and "ask your instructor" in detail
    assert _runs_of(disk_lab, bob.user["id"]) == []


def test_the_status_shows_the_bytes_runs_use_and_the_top_students(disk_lab):
    status = disk_lab.admin().get("/api/admin/status")
    assert status.status_code == 200, status.text
    use = status.json()["disk"]
    on_disk = sum(p.stat().st_size for p in (disk_lab.data / "runs").rglob("*") if p.is_file())
    assert use["runs_bytes"] == on_disk > 0
    assert use["lab_budget_bytes"] == LAB_BUDGET
    assert use["student_budget_bytes"] == STUDENT_BUDGET
    top = use["top_students"][0]
    assert top["name"] == "ada" and top["bytes"] == on_disk


def test_saved_codes_history_counts_in_the_students_budget(disk_lab):
    """Issue 33, finding 9: versions are disk too; a student with no run but saved code is over
    a one-byte budget on their own account, and the status adds the history up."""
    dora = disk_lab.student("dora")
    url = "/api/workspaces/crowbot/files/notes.txt"
    saved = dora.put(url, json={"code": "x" * 100})
    assert saved.status_code == 200, saved.text
    refused = dora.post("/api/runs", json=short_run())
    assert refused.status_code == 507, refused.text
    assert "your runs use 0.0 MiB of disk and your saved code's history" in refused.json()["detail"]
    assert disk_lab.admin().get("/api/admin/status").json()["disk"]["history_bytes"] == 100
    assert dora.delete(url).status_code == 200  # her history goes with the file
    assert disk_lab.admin().get("/api/admin/status").json()["disk"]["history_bytes"] == 0


def test_retention_removes_old_runs_files_and_keeps_their_metrics(disk_lab):
    admin = disk_lab.admin()
    assert admin.get("/api/admin/retention").json() == {"retention_days": 0}
    (ada_run,) = admin.get("/api/admin/runs").json()["runs"]
    run_id = ada_run["id"]
    before = admin.get(f"/api/runs/{run_id}").json()
    assert before["metrics"] and before["checks"] and before["score"] is not None
    assert not before["files_removed"]
    assert admin.get(f"/api/runs/{run_id}/recording.mcap").status_code == 200

    # Not a wait for an event: the run must age past ~0.1 s so that a retention of ~0.09 s
    # takes it (retention is by age).
    time.sleep(0.2)
    answer = admin.put("/api/admin/retention", json={"retention_days": 1e-6})
    assert answer.status_code == 200, answer.text
    assert answer.json()["runs_with_files_removed_now"] == 1
    assert admin.get("/api/admin/retention").json() == {"retention_days": 1e-6}

    assert not Path(disk_lab.data / "runs" / run_id).exists()
    after = admin.get(f"/api/runs/{run_id}").json()
    assert after["files_removed"] and after["metrics"] == before["metrics"]
    assert after["score"] == before["score"] and after["checks"] == before["checks"]
    for path in ("recording.mcap", "logs", "artifacts", "metrics.json", "viz/"):
        gone = admin.get(f"/api/runs/{run_id}/{path}")
        assert gone.status_code == 410, (path, gone.text)
        assert "removed by the lab's retention" in gone.json()["detail"]
    use = admin.get("/api/admin/status").json()["disk"]
    assert use["runs_bytes"] == 0 and use["runs_with_files_removed"] == 1

    cleo = disk_lab.student("cleo")  # the lab's budget is free again: runs start
    again = cleo.post("/api/runs", json=short_run())
    assert again.status_code == 201, again.text
    wait_for_end(cleo, again.json()["id"])
