"""Routes read a running run only through RunService (server/service/runs.py): the listing, one
run, its logs and its graph show what the run is doing while it runs; and a run the service
refuses leaves nothing behind in the student's history."""

from __future__ import annotations

import time

from tests.api.conftest import STEP_CONTROLLER, wait_for_end

IDLE = "RATE_HZ = 20\n\n\ndef step(obs):\n    print('tick')\n    return None\n"


def poll(fetch, predicate, timeout_s: float = 30.0):
    """The first value of fetch() that satisfies predicate, or an AssertionError with the last."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = fetch()
        if predicate(value):
            return value
        assert time.monotonic() < deadline, value
        time.sleep(0.1)


def test_a_running_run_shows_its_state_time_periods_logs_and_graph(lab):
    student = lab.student("door-live")
    started = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "clock": "realtime", "duration": 60,
              "nodes": [{"name": "driver", "code": STEP_CONTROLLER}]},
    )  # fmt: skip
    assert started.status_code == 201, started.text
    run_id = started.json()["id"]
    try:

        def listed() -> dict:
            runs = student.get("/api/runs").json()["runs"]
            return next(r for r in runs if r["id"] == run_id)

        run = poll(
            listed,
            lambda r: (
                r["state"] == "running"
                and r["time_s"] > 0.5
                and r.get("nodes_live", {}).get("driver", {}).get("period", {}).get("count", 0) > 5
            ),
        )
        assert run["ros_version"] == 1
        period = run["nodes_live"]["driver"]["period"]
        assert 0.02 <= period["p50_s"] <= 0.2, period  # [s] a 20 Hz node's loop, give or take
        one = student.get(f"/api/runs/{run_id}").json()
        assert one["state"] == "running" and one["time_s"] >= run["time_s"]
        assert "driver" in one["nodes_live"]
        logs = poll(
            lambda: student.get(f"/api/runs/{run_id}/logs").json()["nodes"],
            lambda nodes: any(line.startswith("distance") for line in nodes.get("driver", [])),
        )
        assert set(logs) == {"driver"}
        graph = student.get(f"/api/runs/{run_id}/graph").json()
        assert "driver" in graph["nodes"]
        assert any(t["name"].strip("/") == "Distance" for t in graph["topics"])
        csv = student.get(f"/api/runs/{run_id}/csv")
        assert csv.status_code == 409 and "still going" in csv.json()["detail"]
    finally:
        student.post(f"/api/runs/{run_id}/stop")
    ended = wait_for_end(student, run_id)
    assert ended["state"] == "interrupted" and "nodes_live" not in ended


def test_a_refused_hardware_run_leaves_no_record(lab):
    student = lab.student("door-refused")
    nodes = [{"name": "idle", "code": IDLE}]
    # The simulation gate first: this exact code finishes a simulation run.
    simulated = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "duration": 0.5, "nodes": nodes},
    )
    assert simulated.status_code == 201, simulated.text
    assert wait_for_end(student, simulated.json()["id"])["state"] == "finished"

    refused = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "duration": 5, "nodes": nodes,
              "hardware": "crowbot-nowhere"},
    )  # fmt: skip
    assert refused.status_code == 422, refused.text
    assert "no robot named 'crowbot-nowhere'" in refused.json()["detail"]
    history = student.get("/api/runs").json()
    assert history["total"] == 1
    assert [r["id"] for r in history["runs"]] == [simulated.json()["id"]]
    assert all(r["hardware"] is None and r["state"] != "created" for r in history["runs"])
