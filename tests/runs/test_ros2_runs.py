"""ROS 2 runs with real rclpy nodes in the sandbox: the robot's edge as a node meets it (ROS 2
types and CDR in, Twist or TwistStamped out), a recording every independent reader decodes, and
an exercise's checks passing, unchanged, on an rclpy port of its reference."""

from __future__ import annotations

from pathlib import Path

import pytest
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader

from sandbox.protocol import Clock
from server.exercises.grading import grade
from server.exercises.registry import get_exercise
from server.runs.export import export_csv
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState

pytestmark = pytest.mark.slow  # whole ROS 2 runs on the TurtleBot3 and an exercise: seconds each

STAMPED_DRIVER = """\
import rclpy
from rclpy.node import Node
from geometry_msgs.msg import TwistStamped
from sensor_msgs.msg import LaserScan


class Driver(Node):
    def __init__(self):
        super().__init__("driver")
        self.pub = self.create_publisher(TwistStamped, "cmd_vel", 10)
        self.create_subscription(LaserScan, "scan", self.on_scan, 10)
        self.create_timer(0.1, self.tick)
        self.scans = 0

    def on_scan(self, scan):
        if self.scans == 0:
            self.get_logger().info(
                f"first scan: {type(scan).__module__} frame={scan.header.frame_id} "
                f"stamp={scan.header.stamp.sec}.{scan.header.stamp.nanosec:09d} "
                f"beams={len(scan.ranges)}"
            )
        self.scans += 1

    def tick(self):
        cmd = TwistStamped()
        cmd.header.stamp = self.get_clock().now().to_msg()
        cmd.header.frame_id = "base_link"
        cmd.twist.linear.x = 0.1
        cmd.twist.angular.z = 0.3
        self.pub.publish(cmd)


rclpy.init()
rclpy.spin(Driver())
"""

# server/exercises/reference/crowbot_distance_pid.py, written as an rclpy node: the same PID,
# gains and rate; a timer in place of the Rate loop.
PID_RCLPY = """\
import rclpy
from rclpy.node import Node
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

KP, KI, KD = 0.4, 0.4, 0.4
SETPOINT_M = 0.2
PERIOD_S = 0.1
MAX_SPEED_M_S = 0.128
INTEGRATE_WITHIN_M = 0.05


class PidDistance(Node):
    def __init__(self):
        super().__init__("pid_distance")
        self.distance_m = None
        self.integral, self.previous_error = 0.0, None
        self.create_subscription(Int32, "Distance", self.on_distance, 10)
        self.control = self.create_publisher(Twist, "Control", 10)
        self.create_timer(PERIOD_S, self.tick)

    def on_distance(self, msg):
        if msg.data > 0:
            self.distance_m = msg.data / 100.0

    def tick(self):
        if self.distance_m is None:
            return
        error = self.distance_m - SETPOINT_M
        previous = self.previous_error
        derivative = 0.0 if previous is None else (error - previous) / PERIOD_S
        command = KP * error + KI * self.integral + KD * derivative
        if abs(command) < MAX_SPEED_M_S and abs(error) < INTEGRATE_WITHIN_M:
            self.integral += error * PERIOD_S
        self.previous_error = error
        move = Twist()
        move.linear.x = max(-MAX_SPEED_M_S, min(MAX_SPEED_M_S, command))
        self.control.publish(move)


def main():
    rclpy.init()
    node = PidDistance()
    try:
        rclpy.spin(node)
    finally:
        node.destroy_node()


main()
"""


@pytest.mark.parametrize("clock", [Clock.LOCKSTEP, Clock.REALTIME])
def test_a_jazzy_style_node_drives_a_turtlebot3_with_twist_stamped(launcher, tmp_path, clock):
    spec = RunSpec(
        robot="turtlebot3",
        world="office",
        nodes=(NodeSpec("driver", STAMPED_DRIVER, "driver.py"),),
        duration_s=3.0,
        clock=clock,
    )
    run = Run(spec, launcher, tmp_path)
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    assert result.ros_version == 2 and result.summary()["ros_version"] == 2
    assert result.metrics["distance_travelled_m"] > 0.1
    assert result.nodes["driver"]["rejected_commands"] == 0
    log = (tmp_path / "logs" / "driver.log").read_text()
    assert "first scan: sensor_msgs.msg._laser_scan frame=base_scan stamp=0." in log, log
    assert "beams=360" in log, log
    with AnyReader([tmp_path]) as reader:  # through metadata.yaml, as ros2 bag play DIR
        types = {c.topic: c.msgtype for c in reader.connections}
        decoded = sum(1 for c, _, raw in reader.messages() if reader.deserialize(raw, c.msgtype))
        assert decoded == reader.message_count > 50
    assert types["/cmd_vel"] == "geometry_msgs/msg/TwistStamped"
    assert types["/scan"] == "sensor_msgs/msg/LaserScan"
    files = {path.name for path in export_csv(Path(result.paths["recording"]), tmp_path / "csv")}
    assert {"cmd_vel.csv", "scan.csv", "odom.csv", "tf.csv"} <= files


def test_an_exercise_passes_its_checks_on_an_rclpy_reference(launcher, tmp_path):
    exercise = get_exercise("crowbot_distance_pid")
    nodes = (NodeSpec("pid_distance", PID_RCLPY, "pid_distance.py"),)
    graded = grade(exercise, nodes, launcher, tmp_path, clock=Clock.LOCKSTEP)
    failed = [(c.name, c.per_seed, c.threshold) for c in graded.checks if not c.passed]
    assert graded.passed, (failed, [r["reason"] for r in graded.runs])
    assert all(r["state"] == "finished" for r in graded.runs)
    with open(Path(graded.runs[0]["run_dir"]) / "recording.mcap", "rb") as handle:
        assert make_reader(handle).get_header().profile == "ros2"  # it was a ROS 2 run
