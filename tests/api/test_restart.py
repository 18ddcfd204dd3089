"""Nothing is lost across a stop: a graceful shutdown stops runs cleanly (the robot's last
command is zero velocity), a crash (SIGKILL) leaves a readable recording up to the last chunk,
and at the next start runs cut off are marked interrupted, with their code and data still there.
"""

from __future__ import annotations

import io
import signal
import time

import psutil
import pytest
from mcap.exceptions import EndOfFile
from mcap.records import Channel, Message
from mcap.stream_reader import StreamReader

from sandbox.msgs.geometry_msgs import Twist
from tests.api.conftest import start_server, stop_server, wait_for_end

pytestmark = pytest.mark.slow  # a server started, crashed or stopped per test

SPIN = 'RATE_HZ = 20\n\n\ndef step(obs):\n    print("spin")\n    return {"Control": (0.05, 0.4)}\n'


def messages(data: bytes) -> dict[str, list[bytes]]:
    """Every message of a recording, read as a stream: works without the summary section a
    crashed writer never wrote."""
    channels: dict[int, str] = {}
    found: dict[str, list[bytes]] = {}
    try:
        for record in StreamReader(io.BytesIO(data), skip_magic=False).records:
            if isinstance(record, Channel):
                channels[record.id] = record.topic
            elif isinstance(record, Message):
                found.setdefault(channels[record.channel_id], []).append(record.data)
    except EndOfFile:  # a crashed writer's file ends without its footer: read up to there
        pass
    return found


def start_spinning(server, seconds: float = 2.0):
    student = server.student("ada")
    answer = student.post(
        "/api/runs",
        json={
            "robot": "crowbot",
            "world": "wall_approach",
            "nodes": [{"name": "spin", "code": SPIN}],
            "clock": "realtime",
            "duration": 120,
        },
    )
    assert answer.status_code == 201, answer.text
    run_id = answer.json()["id"]
    deadline = time.monotonic() + 30
    while student.get(f"/api/runs/{run_id}").json()["time_s"] < seconds:
        assert time.monotonic() < deadline, "the run did not get going"
        time.sleep(0.1)
    return student.token, run_id


def test_graceful_shutdown_stops_runs_with_the_robot_at_zero(tmp_path):
    server = start_server(tmp_path)
    token, run_id = start_spinning(server)
    assert stop_server(server) in (0, -signal.SIGTERM)
    assert any("Application shutdown complete" in line for line in server.output)

    again = start_server(tmp_path)
    try:
        student = again.client(token)
        run = wait_for_end(student, run_id, timeout_s=5)
        assert run["state"] == "interrupted"
        assert run["reason"] == "interrupted: the server is shutting down"
        assert run["nodes"]["spin"]["wakes"] > 20  # the metrics were stored at the end
        recorded = messages(student.get(f"/api/runs/{run_id}/recording.mcap").content)
        commands = [Twist.deserialize(data) for data in recorded["/Control"]]
        assert commands[0].angular.z > 0 and commands[-1] == Twist()
        assert student.get(f"/api/runs/{run_id}/logs").json()["nodes"]["spin"][0] == "spin"
    finally:
        stop_server(again)


def test_a_crash_leaves_a_readable_recording_and_an_interrupted_run(tmp_path):
    server = start_server(tmp_path)
    token, run_id = start_spinning(server, seconds=3.0)
    sandboxes = psutil.Process(server.process.pid).children(recursive=True)
    assert sandboxes, "the run's node should be a sandbox process below the server"
    server.process.send_signal(signal.SIGKILL)
    server.process.wait(10)
    stop_server(server)
    # bubblewrap's --die-with-parent: no student process outlives the server.
    _, alive = psutil.wait_procs(sandboxes, timeout=10)
    assert alive == []

    again = start_server(tmp_path)
    try:
        assert any("marked interrupted" in line for line in again.output)
        student = again.client(token)
        run = student.get(f"/api/runs/{run_id}").json()
        assert run["state"] == "interrupted"
        assert run["reason"] == "interrupted: the server stopped while the run was active"
        assert run["code"][0]["code"] == SPIN
        recorded = messages(student.get(f"/api/runs/{run_id}/recording.mcap").content)
        # Chunks close every second: at least the first 1-2 s of a 3 s run survived.
        assert len(recorded["/Distance"]) >= 20
        # The student can start again at once: the killed run does not count against them.
        answer = student.post(
            "/api/runs",
            json={
                "robot": "crowbot",
                "world": "wall_approach",
                "nodes": [{"name": "spin", "code": SPIN}],
                "duration": 1,
            },
        )
        assert answer.status_code == 201
        assert wait_for_end(student, answer.json()["id"])["state"] == "finished"
    finally:
        stop_server(again)


def test_login_url_gives_the_instructor_a_new_link_and_retires_the_old(tmp_path):
    import subprocess
    import sys

    server = start_server(tmp_path)
    old_token = server.admin_token
    stop_server(server)
    printed = subprocess.run(
        [sys.executable, "-m", "server.cli", "login-url", "--data", str(tmp_path)],
        capture_output=True, text=True, check=True, timeout=60,
    ).stdout.strip()  # fmt: skip
    assert printed.startswith("http://127.0.0.1:8000/login?token=")
    new_token = printed.split("token=", 1)[1]
    again = start_server(tmp_path)
    try:
        assert not any("log in as the instructor" in line for line in again.output)
        assert again.client(old_token).get("/api/me").status_code == 401
        me = again.client(new_token).get("/api/me").json()
        assert me["role"] == "instructor"
    finally:
        stop_server(again)
