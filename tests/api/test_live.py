"""The live websocket: telemetry at the rate each viewer asked for with honest drop counts,
commands answered with an ack or an error carrying the request id, the robot's controls, and
an exercise's check results before the end."""

from __future__ import annotations

import json
import time

import pytest
from websockets.sync.client import connect

from tests.api.conftest import wait_for_end

WATCHER = """\
RATE_HZ = 20
SUBSCRIBE = ["Light", "Button"]


def step(obs):
    if obs.Button is not None and obs.Button.data:
        print("button pressed")
    return {"Control": (0.0, 0.0)}
"""


def live(lab, client, run_id: str):
    url = lab.url.replace("http", "ws") + f"/api/runs/{run_id}/live?token={client.token}"
    return connect(url)


def frames_for(ws, seconds: float) -> list[dict]:
    frames, deadline = [], time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            frames.append(json.loads(ws.recv(timeout=max(0.01, deadline - time.monotonic()))))
        except TimeoutError:
            break
    return frames


def answer_to(frames: list[dict], request_id) -> dict:
    return next(f for f in frames if f["type"] in ("ack", "error") and f.get("id") == request_id)


@pytest.fixture
def light_run(lab):
    student = lab.student("watcher")
    answer = student.post(
        "/api/runs",
        json={
            "robot": "crowbot",
            "world": "light_arena",
            "nodes": [{"name": "watcher", "code": WATCHER}],
            "clock": "realtime",
            "duration": 60,
        },
    )
    assert answer.status_code == 201, answer.text
    run_id = answer.json()["id"]
    yield student, run_id
    student.post(f"/api/runs/{run_id}/stop")
    wait_for_end(student, run_id)


def test_a_viewer_gets_the_rate_it_asked_for_and_counts_what_it_missed(lab, light_run):
    student, run_id = light_run
    with live(lab, student, run_id) as ws:
        ws.send(json.dumps({"id": 1, "op": "subscribe", "topic": "Light", "max_rate_hz": 4}))
        frames_for(ws, 1.0)  # the start: snapshot, history, first value
        frames = [f for f in frames_for(ws, 3.0) if f["type"] == "telemetry"]
    # The CrowBot publishes Light at 20 Hz; at 4 Hz a viewer gets ~12 frames in 3 s, each
    # saying how many samples it skipped (~4), and every sample is either sent or counted.
    assert 9 <= len(frames) <= 14, len(frames)
    assert all(f["topic"] == "Light" and len(f["msg"]["data"]) == 2 for f in frames)
    times = [f["time_s"] for f in frames]
    assert times == sorted(times)
    missed = sum(f["dropped"] for f in frames)
    assert missed > 2 * len(frames)
    span_samples = round((times[-1] - times[0]) * 20)
    assert abs((missed - frames[0]["dropped"]) + len(frames) - 1 - span_samples) <= 2


def test_commands_are_acked_and_reach_the_robot(lab, light_run):
    student, run_id = light_run
    with live(lab, student, run_id) as ws:
        ws.send(json.dumps({"id": "b", "op": "button", "pressed": True}))
        ws.send(json.dumps({"id": "l", "op": "light", "x": 0.5, "y": -0.5}))
        ws.send(json.dumps({"id": "g", "op": "goal", "x": 0.2, "y": 0.1, "yaw": 1.0}))
        ws.send(json.dumps({"id": "t", "op": "teleop", "key": "up"}))
        ws.send(json.dumps({"id": "p", "op": "pause"}))
        ws.send(json.dumps({"id": "u", "op": "warp"}))
        ws.send(json.dumps({"id": "r", "op": "subscribe", "topic": "Light", "max_rate_hz": 0}))
        ws.send(json.dumps({"id": "x", "op": "light", "x": "far", "y": 0}))
        ws.send("not json")
        ws.send(json.dumps([1, 2]))
        frames = frames_for(ws, 3.0)
    for request_id in ("b", "l", "g"):
        assert answer_to(frames, request_id) == {"type": "ack", "id": request_id}
    expected_errors = {
        "t": "no teleop",
        "p": "only a lockstep",
        "u": "unknown op",
        "r": "max_rate_hz",
        "x": "'x' must be a finite number",
    }
    for request_id, words in expected_errors.items():
        error = answer_to(frames, request_id)
        assert error["type"] == "error" and words in error["detail"], error
    unnamed = [f for f in frames if f["type"] == "error" and f["id"] is None]
    assert len(unnamed) == 2 and all("JSON object" in f["detail"] for f in unnamed)
    assert any(f["type"] == "log" and f["line"] == "button pressed" for f in frames)


def test_an_emergency_stop_is_named_after_the_login_not_the_frame(lab, light_run):
    student, run_id = light_run
    with live(lab, student, run_id) as ws:
        ws.send(json.dumps({"id": "w", "op": "estop", "who": "the instructor"}))
        ws.send(json.dumps({"id": "r", "op": "stop", "reason": "stopped by an instructor"}))
        frames = frames_for(ws, 1.0)
        assert "it does not know who" in answer_to(frames, "w")["detail"]
        assert "it does not know reason" in answer_to(frames, "r")["detail"]
        assert student.get(f"/api/runs/{run_id}").json()["state"] == "running"  # not obeyed
        ws.send(json.dumps({"id": "e", "op": "estop"}))
        frames = []
        while not frames or frames[-1]["type"] != "end":
            frames.append(json.loads(ws.recv(timeout=20)))
    assert answer_to(frames, "e") == {"type": "ack", "id": "e"}
    run = wait_for_end(student, run_id)
    assert run["reason"] == "interrupted: emergency stop by the user"


def test_a_command_flood_is_refused_not_obeyed(lab, light_run):
    student, run_id = light_run
    with live(lab, student, run_id) as ws:
        for number in range(120):
            ws.send(json.dumps({"id": number, "op": "button", "pressed": False}))
        frames = frames_for(ws, 2.0)
    answers = [f for f in frames if f["type"] in ("ack", "error")]
    assert len(answers) == 120
    refused = [f for f in answers if f["type"] == "error"]
    assert refused and all("slow down" in f["detail"] for f in refused)


def test_an_exercise_run_sends_its_checks_before_the_end(lab):
    student = lab.student("graded")
    exercise = student.get("/api/exercises/crowbot_distance_pid").json()
    assert "reference" not in exercise  # students never get the solution
    nodes = [{"name": s["name"], "code": s["code"]} for s in exercise["starter"]]
    started = student.post(
        "/api/runs",
        json={"exercise": "crowbot_distance_pid", "nodes": nodes, "clock": "realtime",
              "duration": 2},
    )  # fmt: skip
    assert started.status_code == 201, started.text
    run_id = started.json()["id"]
    with live(lab, student, run_id) as ws:
        frames = []
        while not frames or frames[-1]["type"] != "end":
            frames.append(json.loads(ws.recv(timeout=20)))
    kinds = [f["type"] for f in frames]
    assert "checks" in kinds and kinds.index("checks") < len(kinds) - 1
    checks = frames[kinds.index("checks")]
    names = {c["name"] for c in exercise["checks"]}
    assert {c["name"] for c in checks["checks"]} == names
    assert 0.0 <= checks["score"] <= 1.0
    stored = wait_for_end(student, run_id)
    assert stored["checks"] == checks["checks"] and stored["score"] == checks["score"]


def test_a_free_run_with_teleop_is_driven_by_arrow_keys(lab):
    student = lab.student("driver")
    code = "RATE_HZ = 10\n\n\ndef step(obs):\n    return None\n"
    answer = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "clock": "realtime", "duration": 20,
              "teleop": True, "nodes": [{"name": "idle", "code": code}]},
    )  # fmt: skip
    assert answer.status_code == 201, answer.text
    run_id = answer.json()["id"]
    with live(lab, student, run_id) as ws:
        ws.send(json.dumps({"id": "k", "op": "teleop", "key": "up", "pressed": True}))
        frames = frames_for(ws, 2.0)
        ws.send(json.dumps({"id": "w", "op": "teleop", "key": "warp"}))
        frames += frames_for(ws, 0.5)
    assert answer_to(frames, "k") == {"type": "ack", "id": "k"}
    assert "teleop knows the keys" in answer_to(frames, "w")["detail"]
    student.post(f"/api/runs/{run_id}/stop")
    run = wait_for_end(student, run_id)
    assert run["metrics"]["distance_travelled_m"] > 0.05  # the up arrow drove it forward
