"""ROS 2 packages RoboDojo does not provide fail with a sentence naming what to use, and a
missing module of a library package we do provide names the modules it has; the libraries
themselves import (in a real node, with sandbox/ros_compat2 on its path)."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox import ros2_imports
from tests.ros2libs.runs import run_nodes


@pytest.mark.parametrize(
    ("module", "expected"),
    [
        ("transforms3d", "tf_transformations has the functions"),
        ("tf2_sensor_msgs", "sensor_msgs_py.point_cloud2.read_points_numpy"),
        ("tf2_kdl", "tf_transformations for rotations"),
        ("rosbag2_py", "every run is recorded"),
        ("slam_toolbox", "the map comes from the run's map_server"),
        ("nav2_simple_commander.costmap_2d", "it has nav2_simple_commander.robot_navigator"),
        ("tf2_ros.buffer_client", "it has tf2_ros.buffer, tf2_ros.transform_listener"),
    ],
)
def test_the_sentence_names_the_alternative(module: str, expected: str) -> None:
    sentence = ros2_imports.sentence_for(module)
    assert sentence is not None and sentence.startswith(f"{module} is not available in RoboDojo")
    assert expected in sentence


def test_provided_libraries_have_no_sentence() -> None:
    for module in ("tf2_geometry_msgs", "tf_transformations", "sensor_msgs_py", "tf2_py"):
        assert ros2_imports.sentence_for(module) is None, module


IMPORTER = """
import rclpy
import tf2_geometry_msgs, tf2_py, tf_transformations
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult
from rclpy.action import ActionClient, ActionServer, CancelResponse, GoalResponse
from sensor_msgs_py import point_cloud2
from tf2_ros import Buffer, StaticTransformBroadcaster, TransformBroadcaster, TransformListener
from tf2_ros.static_transform_broadcaster import StaticTransformBroadcaster as Static

rclpy.init()
node = rclpy.create_node("importer")
same = tf2_py.BufferCore is Buffer.__mro__[1]
node.get_logger().info(f"imported; tf2_py.BufferCore is tf2_ros's: {same}")
try:
    import transforms3d
except ModuleNotFoundError as error:
    node.get_logger().info(f"missing: {error}")
rclpy.shutdown()
"""


def test_the_libraries_import_in_a_node_and_a_missing_one_says_why(
    launcher, tmp_path: Path
) -> None:
    outcome = run_nodes(launcher, tmp_path, {"importer": IMPORTER}, duration_s=1.0)
    log = outcome.log("importer")
    assert "imported; tf2_py.BufferCore is tf2_ros's: True" in log, outcome.describe()
    assert "missing: transforms3d is not available in RoboDojo: it is not installed" in log
