"""The student page with a ROS 2 launch file: "+ File" gives a .launch.py a Python skeleton,
the run selector takes it when its tab opens (it is never a node), and the run starts the
rclpy node it names with its launch name and a parameter from a launch argument's default."""

from __future__ import annotations

import re

import pytest
from playwright.sync_api import expect

from tests.e2e.test_student_launch import add_data_file, add_node
from tests.e2e.test_student_page import make_student, shot

pytestmark = pytest.mark.slow  # Chromium drives the pages: seconds per test

TALKER = """\
import rclpy
from rclpy.node import Node
from std_msgs.msg import String


def main():
    rclpy.init()
    node = Node("talker")
    speed = node.declare_parameter("speed", 0.0).value
    node.get_logger().info(f"I am {node.get_name()}, speed {speed}")
    pub = node.create_publisher(String, "chatter", 10)
    node.create_timer(0.2, lambda: pub.publish(String(data="hi")))
    rclpy.spin(node)


if __name__ == "__main__":
    main()
"""
LAUNCH = """\
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("speed", default_value="0.25"),
        Node(package="chat", executable="talker", name="speaker", output="screen",
             parameters=[{"speed": LaunchConfiguration("speed")}]),
    ])
"""


def test_a_ros2_launch_file_in_the_workspace_runs_its_node(web_lab, new_page, screenshots):
    invite = make_student(web_lab, new_page, screenshots, "ros2lin")
    page = new_page()
    page.goto(invite)
    expect(page).to_have_url(re.compile(r"/(#.*)?$"))
    page.goto(f"{web_lab.url}/#free/crowbot/wall_approach")
    expect(page.get_by_test_id("editor").locator(".cm-content")).to_contain_text("def ")

    add_node(page, "talker", TALKER)
    page.get_by_test_id("file-new-data").click()
    page.get_by_test_id("file-new-name").fill("launch/chat.launch.py")
    page.get_by_test_id("file-new-create").click()
    editor = page.get_by_test_id("editor").locator(".cm-content")
    expect(editor).to_contain_text("def generate_launch_description():")  # the skeleton
    add_data_file(page, "launch/chat2.launch.py", LAUNCH)
    expect(page.get_by_test_id("run-what")).to_have_value("launch/chat2.launch.py")
    expect(page.get_by_test_id("save-status")).to_contain_text(re.compile("[Ss]aved"),
                                                               timeout=10_000)  # fmt: skip
    page.get_by_test_id("run-duration").fill("2")
    page.get_by_test_id("run-button").click()
    expect(page.get_by_test_id("run-state")).to_contain_text("finished", timeout=30_000)
    expect(page.get_by_test_id("console")).to_contain_text("I am speaker, speed 0.25")
    page.locator("#tab-graph").click()
    graph = page.get_by_test_id("graph")
    expect(graph.locator('[data-testid="graph-node"][data-name="speaker"]')).to_be_visible()
    shot(page, screenshots, "student-launch2-run")
    assert page.console_watch.errors == [], page.console_watch.errors
