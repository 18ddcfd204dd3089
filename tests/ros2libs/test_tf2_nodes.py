"""ROS 2 tf2_ros in real nodes: a TransformListener fed by the run's "/tf" looks the robot up
(exactly the pose the recording carries at that stamp), unknown frames raise tf2's
LookupException naming the known ones; and between two nodes, a TransformBroadcaster's and a
StaticTransformBroadcaster's frames reach another node's buffer, where tf2_geometry_msgs moves
a point through them."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from tests.ros2libs.runs import run_nodes

NS = 1_000_000_000

LOOKER = """
import math
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.time import Time
from tf2_ros import LookupException, TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener


class Looker(Node):
    def __init__(self):
        super().__init__("looker")
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.cmd = self.create_publisher(Twist, "cmd_vel", 10)
        self.create_timer(0.25, self.tick)
        self.ticks = 0

    def tick(self):
        self.ticks += 1
        twist = Twist()
        twist.angular.z = 0.6
        self.cmd.publish(twist)
        try:
            t = self.tf_buffer.lookup_transform("map", "base_link", Time())
        except TransformException as error:
            self.get_logger().info(f"not yet: {type(error).__name__}")
            return
        q, p = t.transform.rotation, t.transform.translation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        stamp = t.header.stamp.sec * 1_000_000_000 + t.header.stamp.nanosec
        self.get_logger().info(f"tf {stamp} {p.x:.6f} {p.y:.6f} {yaw:.6f}")
        if self.ticks == 8:
            try:
                self.tf_buffer.lookup_transform("map", "nowhere", Time())
            except LookupException as error:
                self.get_logger().info(f"lookup error: {error}")


rclpy.init()
rclpy.spin(Looker())
"""


def recorded_body_poses(outcome) -> dict[int, tuple[float, float, float]]:
    """header.stamp [ns] -> (x, y, yaw) of map -> base_link in the recording's /tf."""
    poses = {}
    for _, message in outcome.messages("tf"):
        for transform in message.transforms:
            if (transform.header.frame_id, transform.child_frame_id) == ("map", "base_link"):
                q, p = transform.transform.rotation, transform.transform.translation
                yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
                stamp = transform.header.stamp
                poses[stamp.sec * NS + stamp.nanosec] = (p.x, p.y, yaw)
    return poses


@pytest.mark.slow
def test_a_listener_sees_the_runs_tree(launcher, tmp_path: Path) -> None:
    outcome = run_nodes(
        launcher,
        tmp_path,
        {"looker": LOOKER},
        robot="turtlebot3",
        world="office",
        spawn="start",
        duration_s=3.0,
    )
    log = outcome.log("looker")
    lines = re.findall(r"tf (\d+) (\S+) (\S+) (\S+)", log)
    assert len(lines) >= 8, outcome.describe()
    recorded = recorded_body_poses(outcome)
    for stamp, x, y, yaw in lines:
        assert int(stamp) in recorded, (stamp, sorted(recorded)[:5])
        rx, ry, ryaw = recorded[int(stamp)]
        assert (float(x), float(y)) == pytest.approx((rx, ry), abs=2e-6)
        assert math.cos(float(yaw) - ryaw) > math.cos(1e-5)
    yaws = [float(line[3]) for line in lines]
    assert abs(yaws[-1] - yaws[0]) > 0.3  # the robot turned, and the lookups followed it
    assert re.search(r'lookup error: "nowhere" passed to lookupTransform .* does not exist\. '
                     r"Known frames: .*base_link.*map", log)  # fmt: skip


BROADCASTER = """
import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros import StaticTransformBroadcaster, TransformBroadcaster


def transform(node, parent, child, x):
    t = TransformStamped()
    t.header.stamp = node.get_clock().now().to_msg()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x = x
    t.transform.rotation.w = 1.0
    return t


class Frames(Node):
    def __init__(self):
        super().__init__("frames")
        self.static = StaticTransformBroadcaster(self)
        self.static.sendTransform(transform(self, "carrier", "camera", 0.25))
        self.moving = TransformBroadcaster(self)
        self.create_timer(0.1, self.tick)

    def tick(self):
        seconds = self.get_clock().now().nanoseconds / 1e9
        self.moving.sendTransform(transform(self, "world", "carrier", seconds))


rclpy.init()
rclpy.spin(Frames())
"""

USER = """
import rclpy
import tf2_geometry_msgs
from geometry_msgs.msg import PointStamped
from rclpy.node import Node
from rclpy.time import Time
from tf2_ros import TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener


class User(Node):
    def __init__(self):
        super().__init__("user")
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.create_timer(0.5, self.tick)

    def tick(self):
        try:
            t = self.tf_buffer.lookup_transform("world", "camera", Time())
        except TransformException as error:
            self.get_logger().info(f"waiting: {type(error).__name__}")
            return
        point = PointStamped()
        point.header.frame_id = "camera"
        point.point.x = 1.0
        moved = tf2_geometry_msgs.do_transform_point(point, t)
        through_buffer = self.tf_buffer.transform(point, "world")
        stamp = t.header.stamp.sec + t.header.stamp.nanosec / 1e9
        self.get_logger().info(
            f"camera at {stamp:.3f}: x={t.transform.translation.x:.3f} "
            f"point={moved.point.x:.3f} buffer={through_buffer.point.x:.3f} "
            f"in {moved.header.frame_id}")


rclpy.init()
rclpy.spin(User())
"""


def test_frames_broadcast_by_one_node_reach_another(launcher, tmp_path: Path) -> None:
    outcome = run_nodes(launcher, tmp_path, {"frames": BROADCASTER, "user": USER}, duration_s=3.0)
    lines = re.findall(
        r"camera at (\S+): x=(\S+) point=(\S+) buffer=(\S+) in world", outcome.log("user")
    )
    assert len(lines) >= 3, outcome.describe()
    for stamp, x, point, through_buffer in lines:
        # world -> carrier is x = t, carrier -> camera 0.25 more, the point 1 m beyond
        assert float(x) == pytest.approx(float(stamp) + 0.25, abs=1e-3)
        assert float(point) == pytest.approx(float(x) + 1.0, abs=1e-3)
        # the point has no stamp (time 0): buffer.transform uses the latest transform
        assert float(through_buffer) >= float(point) - 1e-3


WAITER = """
import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.time import Time
from tf2_ros import LookupException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener

rclpy.init()
node = Node("waiter")
buffer = Buffer()
listener = TransformListener(buffer, node)
start = node.get_clock().now()
try:
    buffer.lookup_transform("map", "base_link", Time(), timeout=Duration(seconds=0.5))
except LookupException:
    waited = (node.get_clock().now() - start).nanoseconds / 1e9
    node.get_logger().info(f"not spun: LookupException after {waited:.2f} s")
for _ in range(5):
    rclpy.spin_once(node, timeout_sec=0.1)
found = buffer.lookup_transform("map", "base_link", Time(), timeout=Duration(seconds=0.5))
node.get_logger().info(f"spun: found {found.child_frame_id} in {found.header.frame_id}")
try:
    buffer.lookup_transform("map", "base_link", Time(), timeout=1.0)
except TypeError as error:
    node.get_logger().info(f"float timeout: {error}")
rclpy.shutdown()
"""


def test_a_wait_for_a_transform_fills_nothing_until_the_node_spins(
    launcher, tmp_path: Path
) -> None:
    outcome = run_nodes(launcher, tmp_path, {"waiter": WAITER}, duration_s=3.0)
    log = outcome.log("waiter")
    match = re.search(r"not spun: LookupException after (\S+) s", log)
    assert match and float(match.group(1)) == pytest.approx(0.5, abs=0.03), outcome.describe()
    assert "spun: found base_link in map" in log
    assert "float timeout: lookup_transform() takes its timeout as an rclpy.duration" in log
