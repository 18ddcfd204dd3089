"""The graph as a node sees it, destroying entities, wait_for_message and remove_ros_args."""

from __future__ import annotations

from pathlib import Path

from sandbox.protocol import GraphTopic, Outcome, Yield
from tests.rclpy.harness import envelope, message, published, start

CODE = """
import sys
import rclpy
from rclpy.node import Node
from rclpy.utilities import remove_ros_args
from rclpy.wait_for_message import wait_for_message
from std_msgs.msg import Int32, String

rclpy.init(args=sys.argv)
node = Node('observer')
other = Node('helper')
out = node.create_publisher(String, 'report', 10)
sub = other.create_subscription(String, 'report', lambda m: None, 10)
ok, reading = wait_for_message(Int32, node, 'Distance', time_to_wait=1.0)
out.publish(String(data=f'{ok} {reading.data}'))
out.publish(String(data=str(node.count_publishers('Distance'))))
out.publish(String(data=str(node.count_subscribers('report'))))
names = [name for name, _ in node.get_topic_names_and_types()]
out.publish(String(data=' '.join(names)))
out.publish(String(data=' '.join(node.get_node_names())))
first, second = other.destroy_subscription(sub), other.destroy_subscription(sub)
out.publish(String(data=f'{first}{second}'))
out.publish(String(data=str(node.count_subscribers('report'))))
out.publish(String(data=' '.join(remove_ros_args(sys.argv)[1:])))
ok, reading = wait_for_message(Int32, node, 'Button_count', time_to_wait=0.5)
out.publish(String(data=f'{ok} {reading}'))
"""


def test_graph_queries_destroy_and_wait_for_message(tmp_path: Path) -> None:
    argv = ["--verbose", "--ros-args", "-p", "x:=1", "--", "input.csv"]
    parent = start(CODE, tmp_path, "observer", argv=argv)
    frame = parent.next()
    assert isinstance(frame, Yield) and frame.wake_on and "Distance" in frame.wake_on
    graph = [
        GraphTopic("Distance", "std_msgs/msg/Int32", ["robot"], ["observer"]),
        GraphTopic("report", "std_msgs/msg/String", ["observer"], ["logger_node"]),
    ]
    reading = envelope("Distance", message("std_msgs/msg/Int32", data=42))
    yields = [frame]
    frame = parent.wake(0.05, [reading], graph)
    while isinstance(frame, Yield):
        yields.append(frame)
        frame = parent.wake(frame.wake_at_s if frame.wake_at_s is not None else 2.0)
    assert frame.outcome is Outcome.FINISHED, frame.error
    lines = [m.data for m in published(yields, _with_last(parent, frame), "report")]
    assert lines == [
        "True 42",
        "1",  # the robot
        "2",  # logger_node in another process, and helper in this one
        "/Distance /report",
        "helper logger_node observer",
        "TrueFalse",
        "1",
        "--verbose input.csv",
        "False None",
    ]


def _with_last(parent, exited):
    import msgspec

    return msgspec.structs.replace(exited, published=parent.last_published(exited))
