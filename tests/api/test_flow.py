"""The lab's story over the real server: an instructor makes a student; the student logs in
with the invite link, saves code, starts a run, watches telemetry and logs over the websocket,
stops it there, downloads the recording; another student sees none of it."""

from __future__ import annotations

import io
import json
import time

from mcap.reader import make_reader
from websockets.sync.client import connect

from tests.api.conftest import STEP_CONTROLLER, wait_for_end


def ws_url(lab, run_id: str) -> str:
    return lab.url.replace("http://", "ws://") + f"/api/runs/{run_id}/live"


def cookie_header(client) -> dict:
    return {"Cookie": "; ".join(f"{k}={v}" for k, v in client.cookies.items())}


def receive_until(ws, predicate, timeout_s: float = 20.0) -> list[dict]:
    frames = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        frame = json.loads(ws.recv(timeout=max(0.1, deadline - time.monotonic())))
        frames.append(frame)
        if predicate(frame):
            return frames
    raise AssertionError(f"no matching frame within {timeout_s} s; got {frames[-5:]}")


def test_student_story(lab):
    student = lab.student("ada")
    other = lab.student("bob")

    # The invite link gave a session cookie: HttpOnly and SameSite=Strict.
    fresh = lab.client()
    login = fresh.get(f"/login?token={student.token}", follow_redirects=False)
    cookie = login.headers["set-cookie"].lower()
    assert "httponly" in cookie and "samesite=strict" in cookie
    assert student.get("/api/me").json()["name"] == "ada"

    saved = student.put("/api/workspaces/crowbot/files/driver.py", json={"code": STEP_CONTROLLER})
    assert saved.status_code == 200, saved.text
    assert saved.json()["version"] == 1
    files = student.get("/api/workspaces/crowbot").json()["files"]
    assert [(f["filename"], f["code"]) for f in files] == [("driver.py", STEP_CONTROLLER)]

    started = student.post(
        "/api/runs",
        json={
            "robot": "crowbot",
            "world": "wall_approach",
            "nodes": [{"name": "driver", "code": STEP_CONTROLLER}],
            "clock": "realtime",
            "duration": 30,
        },
    )
    assert started.status_code == 201, started.text
    run_id = started.json()["id"]

    with connect(ws_url(lab, run_id), additional_headers=cookie_header(student)) as ws:
        snapshot = json.loads(ws.recv(timeout=10))
        assert snapshot["type"] == "snapshot"
        ws.send(json.dumps({"id": 1, "op": "subscribe", "topic": "Distance", "max_rate_hz": 20}))
        frames = receive_until(
            ws, lambda f: f["type"] == "telemetry" and f["topic"] == "Distance" and f["time_s"] > 1
        )
        assert {"type": "ack", "id": 1} in frames
        telemetry = [f for f in frames if f["type"] == "telemetry"]
        assert all(f["msg_type"] == "std_msgs/Int32" for f in telemetry)
        assert all(isinstance(f["msg"]["data"], int) for f in telemetry)
        logs = receive_until(ws, lambda f: f["type"] == "log")
        assert logs[-1]["node"] == "driver" and logs[-1]["line"].startswith("distance")
        ws.send(json.dumps({"id": "s", "op": "stop"}))
        ending = receive_until(ws, lambda f: f["type"] == "end")
        assert {"type": "ack", "id": "s"} in ending
        assert ending[-1]["state"] == "interrupted"

    run = wait_for_end(student, run_id)
    assert run["state"] == "interrupted" and "stopped by the user" in run["reason"]
    assert run["time_s"] < 30
    assert run["nodes"]["driver"]["wakes"] > 10

    recording = student.get(f"/api/runs/{run_id}/recording.mcap")
    assert recording.status_code == 200
    topics = {
        channel.topic
        for channel in make_reader(io.BytesIO(recording.content)).get_summary().channels.values()
    }
    assert {"/Distance", "/Control"} <= topics
    assert student.get(f"/api/runs/{run_id}/logs").json()["nodes"]["driver"]
    assert run_id in [r["id"] for r in student.get("/api/runs").json()["runs"]]

    # Another student: the run does not exist for them, over HTTP and the websocket.
    assert other.get(f"/api/runs/{run_id}").status_code == 404
    assert other.get(f"/api/runs/{run_id}/recording.mcap").status_code == 404
    assert run_id not in [r["id"] for r in other.get("/api/runs").json()["runs"]]
    assert other.get("/api/workspaces/crowbot").json()["files"] == []
    with connect(ws_url(lab, run_id), additional_headers=cookie_header(other)) as ws:
        try:
            ws.recv(timeout=5)
            raise AssertionError("another student's websocket got a frame")
        except Exception as closed:  # ConnectionClosed with our code
            assert getattr(closed, "rcvd", None) is not None and closed.rcvd.code == 4404

    # The instructor sees it among everyone's runs.
    with lab.admin() as admin:
        listed = admin.get("/api/admin/runs", params={"user": student.user["id"]}).json()
        assert [r["id"] for r in listed["runs"]] == [run_id]
        assert admin.get(f"/api/runs/{run_id}").status_code == 200


def test_lockstep_run_finishes_with_metrics_and_csv(lab):
    student = lab.student("carla")
    started = student.post(
        "/api/runs",
        json={
            "robot": "crowbot",
            "world": "wall_approach",
            "nodes": [{"name": "driver", "code": STEP_CONTROLLER}],
            "duration": 10,
            "seed": 3,
        },
    )
    assert started.status_code == 201, started.text
    run = wait_for_end(student, started.json()["id"])
    assert run["state"] == "finished", run["reason"]
    assert run["time_s"] == 10.0 and run["seed"] == 3
    assert run["nodes"]["driver"]["period"]["p50_s"] == 0.05
    assert run["metrics"]["distance_travelled_m"] > 0.1
    csvs = student.get(f"/api/runs/{run['id']}/csv").json()["files"]
    assert "Distance.csv" in [f["name"] for f in csvs]
    text = student.get(f"/api/runs/{run['id']}/csv/Distance.csv").text
    assert text.splitlines()[0] == "time_s,data" and len(text.splitlines()) > 150


def test_worlds_carry_their_geometry_for_a_map(lab):
    worlds = {w["id"]: w for w in lab.student("mapper").get("/api/worlds").json()}
    arena = worlds["light_arena"]
    assert arena["lights"] == [{"name": "lamp", "x": 1.0, "y": 1.6, "movable": True}]
    assert len(arena["segments"]) == 4 and all(len(s) == 4 for s in arena["segments"])
    assert worlds["crop_rows"]["circles"][0][-1] == "plant"
    assert len(worlds["line_track"]["tape"]) > 10
    assert worlds["office"]["spawns"][0]["name"] == "start"


def test_my_runs_filter_by_robot(lab):
    student = lab.student("filter")
    code = "RATE_HZ = 10\n\n\ndef step(obs):\n    return None\n"
    started = student.post(
        "/api/runs",
        json={"robot": "ir_scout", "world": "obstacle_maze", "duration": 0.5,
              "nodes": [{"name": "idle", "code": code}]},
    )  # fmt: skip
    wait_for_end(student, started.json()["id"])
    assert student.get("/api/runs", params={"robot": "ir_scout"}).json()["total"] == 1
    assert student.get("/api/runs", params={"robot": "crowbot"}).json()["total"] == 0
