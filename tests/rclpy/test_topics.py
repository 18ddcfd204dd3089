"""Publishers and subscriptions: names as rcl resolves them, QoS depth, reliability and
durability between the nodes of one file and across the run's bus."""

from __future__ import annotations

from pathlib import Path

import msgspec
import pytest

from sandbox.protocol import Envelope, Exited, GraphTopic, Outcome, Yield
from tests.rclpy.harness import envelope, message, published, run, start


def test_names_resolve_against_the_namespace_and_remaps_as_rcl_does(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import String

rclpy.init()
node = Node('driver', namespace='robot1')
topics = [
    node.create_publisher(String, name, 1).topic_name
    for name in ('chatter', '/abs', '~/private', '{node}/sub', 'from_cli')
]
report = node.create_publisher(String, '/report', 1)
report.publish(String(data=' '.join(topics)))
report.publish(String(data=node.get_fully_qualified_name()))
"""
    _, exited, _ = run(code, tmp_path, argv=["--ros-args", "-r", "from_cli:=/remapped"])
    assert exited.outcome is Outcome.FINISHED, exited.error
    lines = [m.data for m in published([], exited, "report")]
    assert lines == [
        "/robot1/chatter /abs /robot1/driver/private /robot1/driver/sub /remapped",
        "/robot1/driver",
    ]


def test_the_run_renames_and_places_the_node_as_a_launch_file_does(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import String
rclpy.init()
node = Node('talker')
node.create_publisher(String, 'chatter', 1).publish(String(data=node.get_fully_qualified_name()))
"""
    _, exited, _ = run(
        code, tmp_path, namespace="/team2", remaps={"__node": "speaker", "chatter": "news"}
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [
        (e.topic, m.data)
        for e, m in zip(exited.published, published([], exited, "team2/news"), strict=True)
    ] == [("team2/news", "/team2/speaker")]


@pytest.mark.parametrize(
    ("name", "reason", "caret"),
    [
        (
            "cmd vel",
            "topic name must not contain characters other than alphanumerics, '_', '~', "
            "'{', or '}'",
            3,
        ),
        ("2fast", "topic name token must not start with a number", 0),
        ("scan/", "topic name must not end with a forward slash", 4),
        ("a~b", "topic name must not have tilde '~' unless it is the first character", 1),
    ],
)
def test_an_invalid_topic_name_raises_rclpys_sentence(
    tmp_path: Path, name: str, reason: str, caret: int
) -> None:
    code = f"""
import rclpy
from rclpy.node import Node
from std_msgs.msg import String
rclpy.init()
Node('n').create_publisher(String, {name!r}, 10)
"""
    _, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "InvalidTopicNameException"
    assert exited.error.message == f"Invalid topic name: {reason}:\n  '{name}'\n   {' ' * caret}^"
    assert exited.error.line == 6


def test_qos_or_depth_is_checked_as_rclpy_checks_it(tmp_path: Path) -> None:
    code = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import String
rclpy.init()
Node('n').create_publisher(String, 'chatter')
"""
    _, exited, _ = run(code, tmp_path)
    assert exited.error.type == "TypeError"
    assert "qos_profile" in exited.error.message  # the missing positional argument
    bad_depth = code.replace("'chatter')", "'chatter', -1)")
    _, exited, _ = run(bad_depth, tmp_path)
    assert (exited.error.type, exited.error.message) == (
        "ValueError",
        "history depth must be greater than or equal to zero",
    )
    instance = code.replace(
        "create_publisher(String, 'chatter')", "create_publisher(String(), 'chatter', 10)"
    )
    _, exited, _ = run(instance, tmp_path)
    assert exited.error.type == "TypeError" and "pass the class itself" in exited.error.message


def test_depth_bounds_what_a_subscription_keeps_from_a_burst(tmp_path: Path) -> None:
    code = """
import time
import rclpy
from rclpy.node import Node
from std_msgs.msg import Int32
rclpy.init()
node = Node('sampler')
seen = []
node.create_subscription(Int32, 'Distance', lambda m: seen.append(m.data), 3)
time.sleep(1.0)          # not spinning: readings wait in the subscription's queue
while rclpy.ok() and len(seen) < 3:
    rclpy.spin_once(node, timeout_sec=0)
node.create_publisher(Int32, 'seen', 10).publish(Int32(data=int(''.join(map(str, seen)))))
"""

    def sensors(time_s: float) -> list[Envelope]:
        return [envelope("Distance", message("std_msgs/msg/Int32", data=d)) for d in range(1, 9)]

    yields, exited, _ = run(code, tmp_path, sensors)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published(yields, exited, "seen")] == [678]  # the newest 3 of 8


QOS_TWO_NODES = """
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from std_msgs.msg import String

rclpy.init()
talker, listener = Node('talker'), Node('listener')
best_effort = talker.create_publisher(String, 'fast', qos_profile_sensor_data)
latched = talker.create_publisher(
    String, 'mission', QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
latched.publish(String(data='go north'))
got = []
listener.create_subscription(String, 'fast', lambda m: got.append('reliable ' + m.data), 10)
listener.create_subscription(
    String, 'fast', lambda m: got.append('best effort ' + m.data), qos_profile_sensor_data)
listener.create_subscription(
    String, 'mission', lambda m: got.append('volatile ' + m.data), 10)
listener.create_subscription(
    String, 'mission', lambda m: got.append('transient ' + m.data),
    QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
best_effort.publish(String(data='ping'))
executor = SingleThreadedExecutor()
executor.add_node(talker)
executor.add_node(listener)
for _ in range(3):
    executor.spin_once(timeout_sec=0.1)
out = listener.create_publisher(String, 'got', 10)
for line in got:
    out.publish(String(data=line))
"""


def test_qos_decides_what_reaches_a_subscription_in_one_process(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    yields, exited, _ = run(QOS_TWO_NODES, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert sorted(m.data for m in published(yields, exited, "got")) == [
        "best effort ping",
        "transient go north",
    ]
    out = capsys.readouterr().out
    assert (
        "[WARN] [0.000000000] [talker]: New subscription discovered on topic '/fast', "
        "requesting incompatible QoS. No messages will be sent to it. Last incompatible "
        "policy: RELIABILITY"
    ) in out
    assert (
        "[WARN] [0.000000000] [listener]: New publisher discovered on topic '/fast', offering "
        "incompatible QoS. No messages will be received from it. Last incompatible policy: "
        "RELIABILITY"
    ) in out


def test_qos_marks_from_the_bus_keep_a_publishers_messages_from_incompatible_subscriptions(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = """
import rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, qos_profile_sensor_data
from std_msgs.msg import String
rclpy.init()
node = Node('listener')
got = []
node.create_subscription(String, 'fast', lambda m: got.append('reliable ' + m.data), 10)
node.create_subscription(String, 'fast', lambda m: got.append('best effort ' + m.data),
                         qos_profile_sensor_data)
node.create_subscription(String, 'mission', lambda m: got.append('volatile ' + m.data), 10)
node.create_subscription(String, 'mission', lambda m: got.append('transient ' + m.data),
                         QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
for _ in range(4):
    rclpy.spin_once(node, timeout_sec=0.1)
out = node.create_publisher(String, 'got', 10)
for line in got:
    out.publish(String(data=line))
"""
    parent = start(code, tmp_path, "listener")
    first = parent.next()
    assert isinstance(first, Yield)
    declared = {(d.name, d.best_effort, d.latch, d.volatile) for d in first.subscribed}
    # one declaration per topic, as permissive as the node's subscriptions need
    assert ("fast", False, False, True) in declared
    graph = [
        GraphTopic("fast", "std_msgs/msg/String", ["sensor"], ["listener"], ["sensor"], []),
        GraphTopic("mission", "std_msgs/msg/String", ["planner"], ["listener"], [], ["planner"]),
    ]
    text = message("std_msgs/msg/String", data="ping")
    mission = message("std_msgs/msg/String", data="go north")
    deliveries = [
        Envelope("fast", text._type, text.serialize(), publisher="sensor"),
        Envelope("mission", mission._type, mission.serialize(), publisher="planner", replayed=True),
    ]
    frame = parent.wake(0.05, deliveries, graph)
    while isinstance(frame, Yield):
        frame = parent.wake(frame.wake_at_s or 0.1)
    assert isinstance(frame, Exited)
    exited = msgspec.structs.replace(frame, published=parent.last_published(frame))
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert sorted(m.data for m in published([], exited, "got")) == [
        "best effort ping",
        "transient go north",
    ]
    assert "offering incompatible QoS" in capsys.readouterr().out


def test_an_incompatible_qos_callback_replaces_the_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = """
import rclpy
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from std_msgs.msg import String

rclpy.init()
node = Node('careful')
events = []
callbacks = SubscriptionEventCallbacks(
    incompatible_qos=lambda event: events.append((event.total_count, event.last_policy_kind)))
node.create_subscription(String, 'fast', lambda m: None, 10, event_callbacks=callbacks)
node.create_publisher(String, 'fast', qos_profile_sensor_data)
node.create_publisher(String, 'report', 10).publish(String(data=repr(events)))
"""
    _, exited, _ = run(code, tmp_path)
    assert exited.outcome is Outcome.FINISHED, exited.error
    assert [m.data for m in published([], exited, "report")] == ["[(1, 16)]"]  # RELIABILITY
    out = capsys.readouterr().out
    assert "offering incompatible QoS" not in out
    assert "requesting incompatible QoS" in out  # the publisher keeps rclpy's default
