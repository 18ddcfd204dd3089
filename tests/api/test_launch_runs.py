"""A launch file of the student's workspace through POST /api/runs (`launch: {file, args}`): it
starts the nodes it names with their parameters; what is wrong in it is a 422 whose sentence
names the file and the line (never a 500), and nothing outside the caller's own workspace can
be read through it."""

from __future__ import annotations

import time

import pytest

from tests.api.conftest import wait_for_end

TALKER = """\
import rospy
from std_msgs.msg import String

rospy.init_node("talker")
rate_hz = rospy.get_param("~rate")
print("rate", rate_hz)
pub = rospy.Publisher("chatter", String, queue_size=10)
rate = rospy.Rate(rate_hz)
n = 0
while not rospy.is_shutdown():
    pub.publish(String(data=f"hello {n}"))
    n += 1
    rate.sleep()
"""
LISTENER = """\
import rospy
from std_msgs.msg import String


def heard(message):
    print("heard", message.data)


rospy.init_node("listener")
rospy.Subscriber("chatter", String, heard)
rospy.spin()
"""
TWO_NODES = """\
<launch>
  <arg name="rate" default="5"/>
  <node pkg="chat" type="talker.py" name="talker" output="screen">
    <param name="rate" value="$(arg rate)"/>
  </node>
  <node pkg="chat" type="listener.py" name="listener"/>
</launch>
"""
FREE = {"robot": "crowbot", "world": "wall_approach", "duration": 2.0}


def workspace(student, files: dict[str, str], name: str = "crowbot") -> None:
    for filename, text in files.items():
        answer = student.put(f"/api/workspaces/{name}/files/{filename}", json={"code": text})
        assert answer.status_code == 200, answer.text


def launch(student, file: str, **extra):
    return student.post("/api/runs", json={**FREE, "launch": {"file": file, **extra}})


def test_a_launch_file_starts_its_nodes_with_their_parameters(lab):
    student = lab.student("launcher")
    workspace(student, {"talker.py": TALKER, "listener.py": LISTENER, "two.launch": TWO_NODES})
    started = launch(student, "two.launch", args={"rate": "10"})
    assert started.status_code == 201, started.text
    assert started.json()["launch"]["file"] == "two.launch"
    run = wait_for_end(student, started.json()["id"])
    assert run["state"] == "finished", run["reason"]
    assert {node["name"] for node in run["code"]} == {"talker", "listener"}
    logs = student.get(f"/api/runs/{run['id']}/logs").json()["nodes"]
    assert "rate 10" in logs["talker"], logs["talker"]
    assert any(line.startswith("heard hello") for line in logs["listener"]), logs["listener"]
    graph = student.get(f"/api/runs/{run['id']}/graph").json()
    assert {"talker", "listener"} <= set(graph["nodes"])
    chatter = next(topic for topic in graph["topics"] if topic["name"].endswith("chatter"))
    assert (chatter["publishers"], chatter["subscribers"]) == (["talker"], ["listener"])


def test_an_exercise_launch_uses_the_exercise_workspace_and_its_starter_files(lab):
    student = lab.student("exerciser")
    starter = student.get("/api/exercises/crowbot_distance_pid").json()["starter"]
    node = starter[0]["name"]
    text = f'<launch>\n  <node pkg="pid" type="{node}.py" name="{node}"/>\n</launch>\n'
    workspace(student, {"pid.launch": text}, "crowbot_distance_pid")
    body = {"exercise": "crowbot_distance_pid", "duration": 1.0, "launch": {"file": "pid.launch"}}
    answer = student.post("/api/runs", json=body)
    assert answer.status_code == 201, answer.text
    run = wait_for_end(student, answer.json()["id"])
    assert [n["name"] for n in run["code"]] == [node]
    assert run["code"][0]["code"] == starter[0]["code"]  # the starter file, never saved


@pytest.mark.parametrize(
    ("files", "file", "words"),
    [
        ({}, "two.launch", "no launch file 'two.launch' in your workspace"),
        ({"a.launch": "<launch/>"}, "talker.py", "not a launch file"),
        ({"a.launch": "<launch/>"}, "../a.launch", "'..'"),
        (
            {"bad.launch": "<launch>\n  <node pkg='x'\n</launch>\n"},
            "bad.launch",
            "bad.launch, line 3: this is not well-formed XML",
        ),
        (
            {"n.launch": '<launch>\n\n  <node pkg="p" type="ghost.py" name="g"/>\n</launch>'},
            "n.launch",
            "n.launch, line 3",
        ),
        (
            {"e.launch": '<launch>\n  <param name="x" value="$(eval 1+1)"/>\n</launch>'},
            "e.launch",
            "e.launch, line 2",
        ),
    ],
)
def test_launch_file_mistakes_are_422_with_the_file_and_line(lab, files, file, words):
    student = lab.student("mistaken")
    workspace(student, files)
    answer = launch(student, file)
    assert answer.status_code == 422, answer.text
    assert words in answer.json()["detail"], answer.json()
    assert student.get("/api/runs").json()["total"] == 0


def test_a_launch_argument_the_file_does_not_declare_is_a_422(lab):
    student = lab.student("arguer")
    workspace(student, {"talker.py": TALKER, "listener.py": LISTENER, "two.launch": TWO_NODES})
    answer = launch(student, "two.launch", args={"speed": "3"})
    assert answer.status_code == 422 and "speed" in answer.json()["detail"]


def test_a_student_cannot_launch_another_students_workspace(lab):
    owner = lab.student("owner")
    workspace(owner, {"talker.py": TALKER, "listener.py": LISTENER, "two.launch": TWO_NODES})
    other = lab.student("other")
    answer = launch(other, "two.launch")
    assert answer.status_code == 422
    assert "no launch file 'two.launch' in your workspace" in answer.json()["detail"]
    # Naming the owner's files from the other's own launch file finds nothing either.
    workspace(other, {"mine.launch": TWO_NODES})
    answer = launch(other, "mine.launch")
    assert answer.status_code == 422 and "talker.py" in answer.json()["detail"]
    assert other.get("/api/runs").json()["total"] == 0


ATTACKS = {
    "passwd_include": ('<launch>\n  <include file="/etc/passwd"/>\n</launch>\n', "line 2"),
    "find_escape": (
        '<launch>\n  <include file="$(find chat)/../../../etc/passwd"/>\n</launch>\n',
        "line 2",
    ),
    "rosparam_outside": (
        '<launch>\n  <rosparam command="load" file="/etc/passwd"/>\n</launch>\n',
        "line 2",
    ),
    "rosparam_escape": (
        '<launch>\n  <rosparam command="load" file="$(find chat)/../../etc/hosts"/>\n</launch>\n',
        "line 2",
    ),
    "textfile_outside": (
        '<launch>\n  <param name="p" textfile="/etc/passwd"/>\n</launch>\n',
        "line 2",
    ),
    "node_outside": ('<launch>\n  <node pkg="x" type="/bin/sh" name="sh"/>\n</launch>\n', "line 2"),
    "command_param": (
        '<launch>\n  <param name="p" command="cat /etc/passwd"/>\n</launch>\n',
        "line 2",
    ),
    "entity_bomb": (
        '<?xml version="1.0"?>\n<!DOCTYPE l [<!ENTITY a "aaaaaaaaaa">'
        '<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;">'
        '<!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">]>\n<launch><arg name="x" default="&d;"/>'
        "</launch>\n",
        "line 2",
    ),
    "external_entity": (
        '<?xml version="1.0"?>\n<!DOCTYPE l [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n'
        '<launch><param name="p" value="&x;"/></launch>\n',
        "line 2",
    ),
}


@pytest.mark.parametrize("attack", sorted(ATTACKS))
def test_launch_files_cannot_reach_outside_the_workspace(lab, attack):
    text, words = ATTACKS[attack]
    student = lab.student("attacker")
    workspace(student, {"attack.launch": text, "talker.py": TALKER})
    answer = launch(student, "attack.launch")
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"]
    assert "attack.launch" in detail and words in detail, detail
    assert "root:" not in answer.text  # nothing of the server's files comes back
    assert student.get("/api/runs").json()["total"] == 0


def test_an_include_loop_is_a_422_quickly(lab):
    student = lab.student("looper")
    workspace(
        student,
        {
            "a.launch": '<launch>\n  <include file="$(find chat)/b.launch"/>\n</launch>\n',
            "b.launch": '<launch>\n  <include file="$(find chat)/a.launch"/>\n</launch>\n',
            "self.launch": '<launch>\n  <include file="$(dirname)/self.launch"/>\n</launch>\n',
        },
    )
    for file in ("a.launch", "self.launch"):
        began = time.monotonic()
        answer = launch(student, file)
        assert answer.status_code == 422, answer.text
        assert "line 2" in answer.json()["detail"], answer.json()
        assert time.monotonic() - began < 5.0


# ---------------------------------------------------------------- ROS 2 Python launch files
ROS2_NODE = """\
import rclpy


def main():
    rclpy.init()
    node = rclpy.create_node("chatter")
    node.get_logger().info(f"rate {node.declare_parameter('rate', 1.0).value}")
    rclpy.spin(node)


if __name__ == "__main__":
    main()
"""
ROS2_LAUNCH = """\
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("rate", default_value="5.0"),
        Node(package="chat", executable="chatter", name="talker", namespace="robot1",
             parameters=["config/chat.yaml", {"rate": LaunchConfiguration("rate")}],
             remappings=[("out", "chatter")]),
    ])
"""
ROS2_PARAMS = "/**:\n  ros__parameters:\n    rate: 2.0\n    frame: base_link\n"


def test_a_ros2_launch_file_is_read_in_the_sandbox_into_the_runs_nodes(lab):
    student = lab.student("ros2")
    files = {"chatter.py": ROS2_NODE, "launch/chat.launch.py": ROS2_LAUNCH}
    workspace(student, {**files, "config/chat.yaml": ROS2_PARAMS})
    started = launch(student, "launch/chat.launch.py", args={"rate": "10.0"})
    assert started.status_code == 201, started.text
    run = wait_for_end(student, started.json()["id"])
    assert run["state"] == "finished", run["reason"]
    assert [node["name"] for node in run["code"]] == ["talker"]
    assert run["code"][0]["code"] == ROS2_NODE
    # The launch's name (over the code's "chatter") in its namespace; the argument's rate over
    # the YAML's (the dict comes after the file).
    logs = student.get(f"/api/runs/{run['id']}/logs").json()["nodes"]["talker"]
    assert any("[robot1.talker]: rate 10.0" in line for line in logs), logs


ROS2_MISTAKES = {
    "syntax": ("def generate_launch_description(:\n", "bad.launch.py, line 1: invalid Python"),
    "no_function": ("x = 1\n", "defines no generate_launch_description()"),
    "outside_include": (
        "from launch import LaunchDescription\n"
        "from launch.actions import IncludeLaunchDescription\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([IncludeLaunchDescription('/etc/passwd')])\n",
        "bad.launch.py, line 4: the included launch file '/etc/passwd' is outside your workspace",
    ),
    "outside_params": (
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import Node\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([Node(package='chat', executable='chatter',\n"
        "        parameters=['../../../etc/passwd'])])\n",
        "bad.launch.py, line 4: the parameter file '../../../etc/passwd' is outside",
    ),
    "read_server_file": (
        "from launch import LaunchDescription\n"
        "def generate_launch_description():\n"
        "    print(open('/etc/shadow').read())\n",
        "bad.launch.py, line 3:",
    ),
}


@pytest.mark.slow
@pytest.mark.parametrize("mistake", sorted(ROS2_MISTAKES))
def test_ros2_launch_file_mistakes_are_422_with_the_file_and_line(lab, mistake):
    text, words = ROS2_MISTAKES[mistake]
    student = lab.student("ros2_mistaken")
    workspace(student, {"chatter.py": ROS2_NODE, "bad.launch.py": text})
    answer = launch(student, "bad.launch.py")
    assert answer.status_code == 422, answer.text
    assert words in answer.json()["detail"], answer.json()
    assert "root:" not in answer.text
    assert student.get("/api/runs").json()["total"] == 0
