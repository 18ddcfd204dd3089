"""POST /api/runs with ROS 2 nodes: no new field, the run is ROS 2 because a node uses rclpy
and says so ("ros_version": 2); mixing rclpy and rospy nodes is a 422 with the contract's
sentence; the recording, CSV and live telemetry of a ROS 2 run are served as a ROS 1 run's
are, in ROS 2 types."""

from __future__ import annotations

import json
import time

import pytest

from tests.api.conftest import wait_for_end
from tests.api.test_live import frames_for, live
from tests.test_cli_ros2 import RCLPY_DRIVER, ROSPY_TALKER


def run_body(*nodes: tuple[str, str]) -> dict:
    return {
        "robot": "crowbot",
        "world": "wall_approach",
        "duration": 2.0,
        "nodes": [{"name": name, "code": code} for name, code in nodes],
    }


def test_mixing_ros1_and_ros2_nodes_is_a_422_with_the_sentence(lab):
    student = lab.student("mixer")
    answer = student.post(
        "/api/runs", json=run_body(("talker", ROSPY_TALKER), ("drive", RCLPY_DRIVER))
    )
    assert answer.status_code == 422, answer.text
    assert answer.json()["detail"] == (
        "node `drive` uses rclpy (ROS 2) and node `talker` uses rospy (ROS 1); "
        "a run is one or the other"
    )
    assert student.get("/api/runs").json()["total"] == 0


def test_a_rclpy_node_runs_as_ros2_and_says_so(lab):
    student = lab.student("ros2student")
    started = student.post("/api/runs", json=run_body(("drive", RCLPY_DRIVER)))
    assert started.status_code == 201, started.text
    assert started.json()["ros_version"] == 2
    run = wait_for_end(student, started.json()["id"])
    assert run["state"] == "finished", run["reason"]
    assert run["ros_version"] == 2 and run["metrics"]["ros_version"] == 2
    assert run["metrics"]["distance_travelled_m"] > 0.05
    recording = student.get(f"/api/runs/{run['id']}/recording.mcap")
    assert recording.status_code == 200 and recording.content[:8] == b"\x89MCAP0\r\n"
    assert b"ros2msg" in recording.content
    csv = student.get(f"/api/runs/{run['id']}/csv/Control.csv")
    assert csv.status_code == 200, csv.text
    assert csv.text.splitlines()[0].startswith("time_s,linear.x,linear.y")


@pytest.mark.slow
def test_a_ros2_run_streams_live_telemetry_in_ros2_types(lab):
    student = lab.student("ros2viewer")
    body = {**run_body(("drive", RCLPY_DRIVER)), "clock": "realtime", "duration": 30.0}
    started = student.post("/api/runs", json=body)
    assert started.status_code == 201, started.text
    run_id = started.json()["id"]
    try:
        with live(lab, student, run_id) as ws:
            for request_id, topic in enumerate(("Distance", "Control"), start=1):
                ws.send(json.dumps({"id": request_id, "op": "subscribe", "topic": topic}))
            by_topic: dict[str, dict] = {}
            deadline = time.monotonic() + 20.0  # the node's start-up on a loaded machine
            while len(by_topic) < 2 and time.monotonic() < deadline:
                for frame in frames_for(ws, 0.5):
                    if frame["type"] == "telemetry":
                        by_topic[frame["topic"]] = frame
    finally:
        student.post(f"/api/runs/{run_id}/stop")
        wait_for_end(student, run_id)
    assert by_topic["Distance"]["msg_type"] == "std_msgs/msg/Int32"
    assert isinstance(by_topic["Distance"]["msg"]["data"], int)
    assert by_topic["Control"]["msg_type"] == "geometry_msgs/msg/Twist"
    assert by_topic["Control"]["msg"]["linear"]["x"] in (0.0, 0.15)
