"""`robodojo run` with ROS 2 nodes: no flag, the run is ROS 2 because its node uses rclpy; a run
mixing rclpy and rospy nodes ends with the contract's sentence before anything starts."""

from __future__ import annotations

import json

import pytest

from tests.test_cli import robodojo

RCLPY_DRIVER = """\
import rclpy
from rclpy.node import Node
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32


class Approach(Node):
    def __init__(self):
        super().__init__("approach")
        self.pub = self.create_publisher(Twist, "Control", 10)
        self.create_subscription(Int32, "Distance", self.on_distance, 10)

    def on_distance(self, msg):
        cmd = Twist()
        cmd.linear.x = 0.15 if msg.data > 30 else 0.0
        self.pub.publish(cmd)


rclpy.init()
rclpy.spin(Approach())
"""

ROSPY_TALKER = """\
import rospy
rospy.init_node("talker")
rospy.spin()
"""


@pytest.mark.slow
def test_a_rclpy_node_makes_a_ros2_run_with_no_flag(tmp_path):
    node = tmp_path / "approach.py"
    node.write_text(RCLPY_DRIVER)
    out = tmp_path / "run"
    done = robodojo(
        "run", "--robot", "crowbot", "--world", "wall_approach", "--node", str(node),
        "--duration", "3", "--out", str(out),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    assert summary["ros_version"] == 2
    assert summary["metrics"]["distance_travelled_m"] > 0.1  # the Twist drove the robot
    assert (out / "metadata.yaml").is_file()  # ros2 bag play RUN_DIR
    exported = robodojo("export", str(out))
    assert exported.returncode == 0, exported.stderr
    header = (out / "csv" / "Distance.csv").read_text().splitlines()[0]
    assert header == "time_s,data"


def test_mixing_rclpy_and_rospy_nodes_is_an_error_with_the_sentence(tmp_path):
    (tmp_path / "approach.py").write_text(RCLPY_DRIVER)
    (tmp_path / "talker.py").write_text(ROSPY_TALKER)
    done = robodojo(
        "run", "--robot", "crowbot", "--world", "wall_approach",
        "--node", str(tmp_path / "approach.py"), "--node", str(tmp_path / "talker.py"),
        "--duration", "1", "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert done.returncode == 2
    assert done.stderr.strip() == (
        "robodojo: node `approach` uses rclpy (ROS 2) and node `talker` uses rospy (ROS 1); "
        "a run is one or the other"
    )
    assert not (tmp_path / "run" / "recording.mcap").exists()
