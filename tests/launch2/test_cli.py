"""`robodojo run --launch FILE.launch.py name:=value` as a student types it: the launch file is
read in a sandboxed job, its mistakes end the command with a sentence (exit 2); `--ros-args`
after a node reach its command line unchanged."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path
from textwrap import dedent

import pytest

from server.cli import main
from server.cli_nodes import nodes_from_flags

BASE = ["run", "--robot", "crowbot", "--world", "wall_approach", "--duration", "3"]

TALKER = """\
import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Talker(Node):
    def __init__(self):
        super().__init__("talker")
        self.greeting = self.declare_parameter("greeting", "hi").value
        self.words = self.declare_parameter("words.first", "nobody").value
        self.pub = self.create_publisher(String, "chatter", 10)
        self.create_timer(0.2, self.tick)

    def tick(self):
        self.pub.publish(String(data=f"{self.greeting} {self.words} from {self.get_name()}"))


def main():
    rclpy.init()
    rclpy.spin(Talker())
"""
LISTENER = """\
import rclpy
from std_msgs.msg import String


def main():
    rclpy.init()
    node = rclpy.create_node("listener")
    echo = node.create_publisher(String, "echo", 10)
    node.create_subscription(String, "heard", lambda m: echo.publish(String(data=m.data)), 10)
    rclpy.spin(node)


if __name__ == "__main__":
    main()
"""
LAUNCH = """\
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    config = os.path.join(get_package_share_directory("chat"), "config", "chat.yaml")
    return LaunchDescription([
        DeclareLaunchArgument("greeting", default_value="hello"),
        Node(package="chat", executable="talker", name="speaker", output="screen",
             parameters=[config, {"greeting": LaunchConfiguration("greeting")}],
             remappings=[("chatter", "conversation")]),
        Node(package="chat", executable="listener", output="screen",
             remappings=[("heard", "conversation")]),
    ])
"""
SETUP = """\
from setuptools import setup

setup(
    name="chat",
    entry_points={
        "console_scripts": ["talker = chat.talker:main", "listener = chat.listener:main"],
    },
)
"""


def write_package(root: Path, launch: str = LAUNCH) -> Path:
    files = {
        "package.xml": "<package format='3'><name>chat</name></package>\n",
        "setup.py": SETUP,
        "chat/__init__.py": "",
        "chat/talker.py": TALKER,
        "chat/listener.py": LISTENER,
        "config/chat.yaml": "speaker:\n  ros__parameters:\n    words:\n      first: robots\n",
        "launch/chat.launch.py": launch,
    }
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(dedent(text))
    return root / "launch" / "chat.launch.py"


@pytest.mark.slow
def test_a_launch_file_mistake_ends_the_command_with_a_sentence(tmp_path, capsys) -> None:
    launch = write_package(tmp_path / "chat")
    assert main([*BASE, "--launch", str(launch), "greting:=x"]) == 2
    assert "greting are not declared" in capsys.readouterr().err
    launch.write_text(LAUNCH.replace('executable="listener"', 'executable="listenr"'))
    assert main([*BASE, "--launch", str(launch)]) == 2
    err = capsys.readouterr().err
    assert "launch/chat.launch.py, line 17: no workspace file is executable 'listenr'" in err
    xml = launch.with_name("chat.launch.xml")
    xml.write_text("<launch/>\n")
    assert main([*BASE, "--launch", str(xml)]) == 2
    assert "ROS 2 XML/YAML launch file, which RoboDojo does not read" in capsys.readouterr().err


def test_ros_args_after_a_node_reach_its_command_line(tmp_path) -> None:
    node = tmp_path / "talker.py"
    node.write_text(TALKER)
    (spec,), _ = nodes_from_flags(
        [("node", str(node)), ("args", "--ros-args -p greeting:=hey -r chatter:=Control")]
    )
    assert spec.args == ("--ros-args", "-p", "greeting:=hey", "-r", "chatter:=Control")


def robodojo(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "server.cli", *args],
        capture_output=True,
        text=True,
        timeout=180,
        check=False,
    )


def messages(out: Path, topic: str) -> list[str]:
    exported = robodojo("export", str(out))
    assert exported.returncode == 0, exported.stderr
    with open(out / "csv" / f"{topic}.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    (column,) = [name for name in rows[0] if name.endswith("data")] if rows else ["data"]
    return [row[column] for row in rows]


@pytest.mark.slow
def test_two_rclpy_nodes_run_from_a_launch_file(tmp_path) -> None:
    launch = write_package(tmp_path / "chat")
    out = tmp_path / "out"
    done = robodojo(*BASE, "--out", str(out), "--launch", str(launch), "greeting:=hey")
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    assert summary["state"] == "finished", summary
    # speaker: the launch's name (-r __node:=speaker), the YAML's words.first for /speaker, the
    # argument through the dict; its chatter remapped to conversation, which the listener
    # (its heard remapped too) echoes.
    said = messages(out, "conversation")
    assert said and set(said) == {"hey robots from speaker"}, said[:3]
    echoed = messages(out, "echo")
    assert echoed and set(echoed) == {"hey robots from speaker"}, echoed[:3]


@pytest.mark.slow
def test_ros_args_set_a_parameter_and_a_remap_of_a_node(tmp_path) -> None:
    node = tmp_path / "talker.py"
    node.write_text(TALKER + '\n\nif __name__ == "__main__":\n    main()\n')
    out = tmp_path / "out"
    ros_args = "--ros-args -p greeting:=yo -p words.first:=wheels -r chatter:=conversation"
    done = robodojo(*BASE, "--out", str(out), "--node", str(node), "--args", ros_args)
    assert done.returncode == 0, done.stderr
    said = messages(out, "conversation")
    assert said and set(said) == {"yo wheels from talker"}, said[:3]
