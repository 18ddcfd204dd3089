"""What rosrun or a launch file gives a node, through POST /api/runs: per-node `params`,
`remaps`, `args` and `namespace`, checked at the edge (422 with the field's path and a
sentence) and seen by the node as rospy sees them."""

from __future__ import annotations

import pytest

from tests.api.conftest import wait_for_end

PARAM_NODE = """\
import rospy

rospy.init_node("tuned")
print("speed", rospy.get_param("~speed"))
print("limit", rospy.get_param("/max_speed"))
print("gains", rospy.get_param("~gains"))
print("missing", rospy.get_param("~nothing", "default"))
"""


def free_run(**node) -> dict:
    return {
        "robot": "crowbot",
        "world": "wall_approach",
        "duration": 1.0,
        "nodes": [{"name": "tuned", "code": PARAM_NODE, **node}],
    }


@pytest.mark.parametrize(
    ("body", "field", "words"),
    [
        (free_run(params={"a//b": 1}), "body.nodes.0.params.a//b.[key]", "not a ROS name"),
        (free_run(params={"1x": 1}), "body.nodes.0.params.1x.[key]", "not a ROS name"),
        (free_run(params={"~x": None}), "body.nodes.0.params", "cannot be null"),
        (free_run(params={"~x": {"deep": [1, None]}}), "body.nodes.0.params", "cannot be null"),
        (free_run(params={"~x": "y" * 70_000}), "body.nodes.0.params", "workspace file"),
        (free_run(remaps={"cmd_vel": "../etc"}), "body.nodes.0.remaps.cmd_vel", "not a ROS name"),
        (free_run(remaps=[["a", "b"]]), "body.nodes.0.remaps", "dictionary"),
        (free_run(args=["ok", "bad\nline"]), "body.nodes.0.args.1", "one line"),
        (free_run(args=["a"] * 33), "body.nodes.0.args", "at most 32"),
        (free_run(namespace="~private"), "body.nodes.0.namespace", "not a ROS namespace"),
        (free_run(namespace="a//b"), "body.nodes.0.namespace", "not a ROS namespace"),
        (free_run(env={"X": "1"}), "body.nodes.0.env", "not permitted"),
        (
            {**free_run(), "launch": {"file": "two.launch"}},
            "body.nodes",
            "not both",
        ),
        (
            {**free_run(), "nodes": None, "launch": {"file": "a.launch", "args": {"a b": "1"}}},
            "body.launch.args.a b.[key]",
            "not a launch argument name",
        ),
        ({"robot": "crowbot", "world": "wall_approach"}, "body.nodes", "or a launch file"),
    ],
)
def test_bad_ros_arguments_are_422_with_the_field_and_a_sentence(lab, body, field, words):
    student = lab.student("typo")
    answer = student.post("/api/runs", json=body)
    assert answer.status_code == 422, answer.text
    problems = answer.json()["errors"]
    assert field in [p["field"] for p in problems], problems
    assert any(words in p["message"] for p in problems if p["field"] == field), problems
    assert student.get("/api/runs").json()["total"] == 0


def test_a_node_reads_its_private_and_global_parameters(lab):
    student = lab.student("tuner")
    body = free_run(params={"~speed": 0.25, "/max_speed": 1, "~gains": {"kp": 2.0, "ki": [0, 1]}})
    started = student.post("/api/runs", json=body)
    assert started.status_code == 201, started.text
    run = wait_for_end(student, started.json()["id"])
    logs = student.get(f"/api/runs/{run['id']}/logs").json()["nodes"]["tuned"]
    assert "speed 0.25" in logs and "limit 1" in logs, logs
    assert "missing default" in logs, logs
    gains = next(line for line in logs if line.startswith("gains"))
    assert "'kp': 2.0" in gains and "'ki': [0, 1]" in gains, gains


SPEAKER = """\
import rospy
from std_msgs.msg import String

rospy.init_node("speaker")
print("rate", rospy.get_param("~rate"))
pub = rospy.Publisher("chatter", String, queue_size=1)
rate = rospy.Rate(5)
while not rospy.is_shutdown():
    pub.publish(String(data="hi"))
    rate.sleep()
"""


def test_remaps_args_and_namespace_reach_the_node_as_rosrun_gives_them(lab):
    student = lab.student("rosrunner")
    body = {
        "robot": "crowbot",
        "world": "wall_approach",
        "duration": 1.0,
        "nodes": [
            {
                "name": "speaker",
                "code": SPEAKER,
                "remaps": {"chatter": "speech"},
                "args": ["_rate:=4"],
                "namespace": "robot1",
            }
        ],
    }
    started = student.post("/api/runs", json=body)
    assert started.status_code == 201, started.text
    run = wait_for_end(student, started.json()["id"])
    assert run["state"] == "finished", run["reason"]
    logs = student.get(f"/api/runs/{run['id']}/logs").json()["nodes"]["speaker"]
    assert "rate 4" in logs, logs
    topics = {t["name"] for t in student.get(f"/api/runs/{run['id']}/graph").json()["topics"]}
    assert "robot1/speech" in topics and not any(t.endswith("chatter") for t in topics), topics
