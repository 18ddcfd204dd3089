"""ROS 2 nodes in the node host for the rclpy tests: the real host, runtime and rclpy layer,
driven by the test parent of tests/sandbox/test_host_harness.py (frames as msgpack through
queues), with a CrowBot whose topics carry ROS 2 types."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import msgspec

from sandbox.msgs import get_message_class
from sandbox.protocol import Clock, Envelope, Exited, NodeInfo, RobotTopic, Yield
from tests.sandbox.test_host_harness import Parent

CROWBOT_TOPICS_ROS2 = [
    RobotTopic("Distance", "std_msgs/msg/Int32", "publish", 20.0),
    RobotTopic("Button", "std_msgs/msg/Bool", "publish", 20.0),
    RobotTopic("Control", "geometry_msgs/msg/Twist", "subscribe"),
    RobotTopic("Buzzer", "std_msgs/msg/Bool", "subscribe"),
]


def ros2_info(name: str = "node", **overrides: Any) -> NodeInfo:
    """What a ROS 2 CrowBot node called `name` is told about its run."""
    fields: dict[str, Any] = {
        "node_name": name,
        "robot": "crowbot",
        "robot_topics": CROWBOT_TOPICS_ROS2,
        "velocity_topic": "Control",
        "clock": Clock.LOCKSTEP,
        "ros_version": 2,
    }
    fields.update(overrides)
    return NodeInfo(**fields)


def message(type_name: str, **fields: Any) -> Any:
    return get_message_class(type_name)(**fields)


def envelope(topic: str, msg: Any) -> Envelope:
    return Envelope(topic, msg._type, msg.serialize())


def decode(env: Envelope) -> Any:
    return get_message_class(env.type).deserialize(env.data)


def start(code: str, workdir: Path, name: str = "node", **info: Any) -> Parent:
    return Parent(code, workdir, info=ros2_info(name, **info), filename=f"{name}.py")


def run(
    code: str,
    workdir: Path,
    sensors: Callable[[float], list[Envelope]] = lambda t: [],
    *,
    name: str = "node",
    spin_period_s: float = 0.05,
    max_wakes: int = 1000,
    **info: Any,
) -> tuple[list[Yield], Exited, Parent]:
    """Run a ROS 2 node to its end in lockstep; the Exited carries everything it published
    after its last sleep."""
    parent = start(code, workdir, name, **info)
    yields, exited = parent.run_lockstep(sensors, spin_period_s=spin_period_s, max_wakes=max_wakes)
    exited = msgspec.structs.replace(exited, published=parent.last_published(exited))
    return yields, exited, parent


def published(yields: list[Yield], exited: Exited, topic: str) -> list[Any]:
    """Every message the node published on `topic`, decoded, in order."""
    found = [e for y in yields for e in y.published if e.topic == topic]
    found += [e for e in exited.published if e.topic == topic]
    return [decode(e) for e in found]
