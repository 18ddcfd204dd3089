"""The node host's ROS 2 switch, in the real sandbox: a ROS 2 node gets rclpy and ROS 2
messages, a ROS 1 node rospy, and each gets a sentence for the other dialect's modules."""

from __future__ import annotations

import ast

from sandbox.host import choose_api
from sandbox.protocol import Api, Exited, Outcome, Yield
from sandbox.ros2_imports import sentence_for as ros2_sentence
from sandbox.ros_imports import sentence_for as ros1_sentence
from tests.rclpy.harness import ros2_info
from tests.sandbox.conftest import crowbot_info


def run_sandboxed(launcher, code: str, info) -> Exited:
    node = launcher.start(info.node_name)
    try:
        reply = node.load(code, f"{info.node_name}.py", Api.AUTO, info)
        if isinstance(reply, Yield):
            reply = node.shutdown("test over")
        else:
            reply = node.shutdown("script ended") if not isinstance(reply, Exited) else reply
        assert isinstance(reply, Exited), reply
        return reply
    finally:
        node.close()


def test_a_ros2_node_runs_rclpy_with_ros2_messages_in_the_sandbox(launcher) -> None:
    code = (
        "import rclpy\n"
        "from rclpy.node import Node\n"
        "from std_msgs.msg import Int32\n"
        "rclpy.init()\n"
        "node = Node('sandboxed')\n"
        "assert Int32._type == 'std_msgs/msg/Int32', Int32._type\n"
        "node.create_publisher(Int32, 'count', 10).publish(Int32(data=7))\n"
    )
    exited = run_sandboxed(launcher, code, ros2_info("sandboxed"))
    assert exited.outcome is Outcome.FINISHED, exited.error


def test_rospy_in_a_ros2_run_fails_with_a_sentence(launcher) -> None:
    exited = run_sandboxed(launcher, "import os\nimport rospy\n", ros2_info("mixed"))
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "ModuleNotFoundError"
    assert exited.error.message == ros2_sentence("rospy")
    assert exited.error.message.startswith(
        "rospy is not available in RoboDojo: is part of ROS 1 and this run is ROS 2"
    )
    assert exited.error.line == 2


def test_rclpy_in_a_ros1_run_fails_with_a_sentence(launcher) -> None:
    exited = run_sandboxed(launcher, "import rclpy\n", crowbot_info("mixed"))
    assert exited.outcome is Outcome.ERROR
    assert exited.error.message == ros1_sentence("rclpy")
    assert "this run is ROS 1" in exited.error.message


def test_a_ros2_interface_package_we_lack_says_which_we_have(launcher) -> None:
    exited = run_sandboxed(launcher, "from turtlesim.msg import Pose\n", ros2_info("turtle"))
    assert exited.outcome is Outcome.ERROR
    assert exited.error.message.startswith("turtlesim is not available in RoboDojo")


def test_a_file_importing_rclpy_is_a_script_even_with_a_step_function() -> None:
    tree = ast.parse("from rclpy.node import Node\n\ndef step(obs):\n    return {}\n")
    assert choose_api(tree, Api.AUTO) is Api.ROSPY
    plain = ast.parse("def step(obs):\n    return {}\n")
    assert choose_api(plain, Api.AUTO) is Api.STEP


def test_rclpy_modules_we_leave_out_say_so(launcher) -> None:
    exited = run_sandboxed(launcher, "import rclpy\nimport rclpy.lifecycle\n", ros2_info("lc"))
    assert exited.outcome is Outcome.ERROR
    assert exited.error.message == (
        "rclpy.lifecycle is not available in RoboDojo: lifecycle (managed) nodes are not "
        "provided; use a plain rclpy.node.Node"
    )
