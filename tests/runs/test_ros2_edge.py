"""The robot's edge in a ROS 2 run (server/runs/dialect.py), driven through the Run engine with
hand-built CDR envelopes: what the robot, /tf, the goal, faults and the built-in nodes put on the
bus is ROS 2 CDR; what a node commands reaches the simulator as ROS 1 objects, Twist or
TwistStamped on the velocity topic. No sandboxed node is needed here (tests/runs/test_ros2_runs.py
runs real rclpy nodes)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from sandbox.msgs import get_message_class
from sandbox.protocol import Envelope, TopicDecl
from server.runs.builtin import BUILTIN_NODES, BuiltinNode
from server.runs.commands import Goal, InjectFault, Teleop
from server.runs.faults import FaultKind
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec, RunSpecError

NS = 1_000_000_000


def decoded_messages(path: str) -> list:
    """Every message of an MCAP file as mcap-ros2-support decodes it (an independent reader)."""
    with open(path, "rb") as handle:
        reader = make_reader(handle, decoder_factories=[DecoderFactory()])
        return [
            SimpleNamespace(channel=channel, schema=schema, ros_msg=decoded)
            for schema, channel, _, decoded in reader.iter_decoded_messages()
        ]


Twist2 = get_message_class("geometry_msgs/msg/Twist")
TwistStamped2 = get_message_class("geometry_msgs/msg/TwistStamped")


def prepared(tmp_path, robot="crowbot", world="wall_approach", **kw) -> Run:
    """A ROS 2 run with its robot, bus and recorder ready, and one node slot `driver` that is
    never started: the test speaks for it."""
    spec = RunSpec(
        robot=robot,
        world=world,
        nodes=(NodeSpec("driver", "print('never started')\n", "driver.py"),),
        explicit_ros_version=2,
        **kw,
    )
    run = Run(spec, launcher=None, out_dir=tmp_path)
    run.core.prepare()
    run.bus.add_node("driver")
    return run


def listen(run: Run, topic: str, type_name: str, node: str = "listener") -> None:
    run.bus.add_node(node)
    run.bus.declare(node, [], [TopicDecl(topic, type_name)])


def received(run: Run, node: str = "listener") -> list:
    envelopes, _ = run.bus.take(node)
    return [(e.topic, e.type, get_message_class(e.type).deserialize(e.data)) for e in envelopes]


def twist(x: float, z: float, stamped: bool = False, sec: int = 0) -> Envelope:
    message = Twist2()
    message.linear.x, message.angular.z = x, z
    if stamped:
        message = TwistStamped2(twist=message)
        message.header.stamp.sec = sec
        return Envelope("Control", "geometry_msgs/msg/TwistStamped", message.serialize())
    return Envelope("Control", "geometry_msgs/msg/Twist", message.serialize())


def test_the_robot_is_declared_and_described_in_ros2_names(tmp_path):
    run = prepared(tmp_path)
    types = {name: topic.type for name, topic in run.bus.topics.items()}
    assert types["Distance"] == "std_msgs/msg/Int32"
    assert types["Control"] == "geometry_msgs/msg/Twist"
    assert types["goal"] == "geometry_msgs/msg/PoseStamped"
    assert types["tf"] == "tf2_msgs/msg/TFMessage"
    info = run.core.node_info(run.spec.nodes[0])
    assert info.ros_version == 2
    assert {t.name: t.type for t in info.robot_topics}["Light"] == "std_msgs/msg/Int32MultiArray"
    assert {t.name: t.type for t in info.robot_topics}["goal"] == "geometry_msgs/msg/PoseStamped"
    run.recorder.close()


def test_sensor_messages_and_tf_reach_nodes_as_ros2_cdr(tmp_path):
    run = prepared(tmp_path)
    listen(run, "Distance", "std_msgs/msg/Int32")
    run.bus.declare("listener", [], [TopicDecl("tf", "tf2_msgs/msg/TFMessage")])
    run.core.advance_to(NS // 2)
    messages = received(run)
    distances = [m for topic, _, m in messages if topic == "Distance"]
    assert distances, "the ultrasonic sensor published nothing in half a second"
    assert type(distances[-1]).__module__ == "std_msgs.msg._int32"  # rosidl's module
    assert distances[-1].data == run.sim.read("Distance").data
    tf = [m for topic, _, m in messages if topic == "tf"][-1]
    base = next(t for t in tf.transforms if t.child_frame_id == "base_link")
    assert base.header.frame_id == "map"
    assert base.transform.translation.x == pytest.approx(run.sim.state.pose.x)
    assert (base.header.stamp.sec, base.header.stamp.nanosec) == (0, NS // 2)  # sent at 0.5 s
    run.recorder.close()


def test_twist_and_twist_stamped_both_drive_the_robot(tmp_path):
    run = prepared(tmp_path)
    slot = run.slots["driver"]
    run.core.from_node(slot, [twist(0.2, 0.5)])
    assert run.sim.read("Control")._type == "geometry_msgs/Twist"  # the simulator's ROS 1 class
    assert (run.sim.read("Control").linear.x, run.sim.read("Control").angular.z) == (0.2, 0.5)
    run.core.from_node(slot, [twist(-0.1, 0.0, stamped=True, sec=3)])
    assert run.sim.read("Control").linear.x == pytest.approx(-0.1)
    assert slot.metrics.rejected_commands == 0
    run.recorder.close()


def test_other_command_topics_take_their_ros2_type(tmp_path):
    run = prepared(tmp_path)
    leds = get_message_class("std_msgs/msg/Int32MultiArray")(data=[255, 0, 64])
    run.core.from_node(run.slots["driver"], [Envelope("Leds", leds._type, leds.serialize())])
    assert run.sim.read("Leds")._type == "std_msgs/Int32MultiArray"
    assert list(run.sim.read("Leds").data) == [255, 0, 64]
    run.recorder.close()


def test_another_type_on_the_velocity_topic_is_said_once_and_ignored(tmp_path):
    run = prepared(tmp_path)
    slot = run.slots["driver"]
    run.core.from_node(slot, [twist(0.2, 0.0)])
    wrong = get_message_class("std_msgs/msg/Float32")(data=1.0)
    envelope = Envelope("Control", "std_msgs/msg/Float32", wrong.serialize())
    run.core.from_node(slot, [envelope, envelope, envelope])
    said = [line for line in slot.logs if "Control" in line]
    assert said == [
        "[robot] 'Control' takes geometry_msgs/msg/Twist or geometry_msgs/msg/TwistStamped, not "
        "std_msgs/msg/Float32; the robot ignores these messages (publish one of those types)"
    ]
    assert slot.metrics.rejected_commands == 3
    assert run.sim.read("Control").linear.x == pytest.approx(0.2)  # the last good command holds
    run.recorder.close()


def test_a_subscriber_gets_only_the_type_it_subscribed_with_on_the_velocity_topic(tmp_path):
    run = prepared(tmp_path)
    listen(run, "Control", "geometry_msgs/msg/TwistStamped")
    slot = run.slots["driver"]
    run.core.from_node(slot, [twist(0.1, 0.0), twist(0.3, 0.0, stamped=True)])
    assert [(topic, kind) for topic, kind, _ in received(run)] == [
        ("Control", "geometry_msgs/msg/TwistStamped")
    ]
    run.recorder.close()


def test_the_zero_command_at_the_end_uses_the_type_the_node_used(tmp_path):
    run = prepared(tmp_path)
    run.core.from_node(run.slots["driver"], [twist(0.3, 0.0, stamped=True)])
    run.core.advance_to(NS)
    run.core.edge.command_zero(run.time_ns)
    assert run.sim.read("Control").linear.x == 0.0
    paths = run.recorder.close()

    commands = [m for m in decoded_messages(paths["recording"]) if m.channel.topic == "/Control"]
    assert [m.schema.name for m in commands] == ["geometry_msgs/msg/TwistStamped"] * 2
    assert commands[-1].ros_msg.twist.linear.x == 0.0
    assert commands[-1].ros_msg.header.stamp.sec == 1  # the run's end time


def test_the_goal_is_a_ros2_pose_stamped(tmp_path):
    run = prepared(tmp_path)
    listen(run, "goal", "geometry_msgs/msg/PoseStamped")
    run.command(Goal(1.0, -0.5, math.pi / 2))
    run.core.apply_commands()
    [(_, kind, goal)] = received(run)
    assert kind == "geometry_msgs/msg/PoseStamped"
    assert (goal.pose.position.x, goal.pose.position.y) == (1.0, -0.5)
    assert goal.pose.orientation.z == pytest.approx(math.sin(math.pi / 4))
    assert goal.header.frame_id == "map"
    run.recorder.close()


def test_faults_act_on_the_converted_messages(tmp_path):
    run = prepared(tmp_path)
    listen(run, "Distance", "std_msgs/msg/Int32")
    run.command(InjectFault(FaultKind.DROP_TOPIC, "Distance", 1.0))
    run.core.apply_commands()
    run.core.advance_to(NS // 2)
    assert received(run) == []
    run.core.advance_to(2 * NS)  # the fault cleared at 1 s
    assert [kind for _, kind, _ in received(run)][-1] == "std_msgs/msg/Int32"
    run.recorder.close()


def test_ros1_builtins_publish_ros2_and_take_a_nodes_ros2_goal(tmp_path):
    run = prepared(
        tmp_path,
        robot="turtlebot3",
        world="office",
        builtin_nodes=("map_server", "localization", "planner", "teleop"),
    )
    listen(run, "pose", "geometry_msgs/msg/PoseStamped")
    run.bus.declare("listener", [], [TopicDecl("plan", "nav_msgs/msg/Path")])
    run.builtins.start(run.core)
    info = run.core.node_info(run.spec.nodes[0])
    assert {t.name: t.type for t in info.robot_topics}["map"] == "nav_msgs/msg/OccupancyGrid"
    assert run.bus.topics["map"].type == "nav_msgs/msg/OccupancyGrid"
    goal = get_message_class("geometry_msgs/msg/PoseStamped")()
    goal.header.frame_id = "map"
    goal.pose.position.x, goal.pose.position.y = run.sim.state.pose.x + 0.5, run.sim.state.pose.y
    envelope = Envelope("goal_pose", goal._type, goal.serialize())
    run.core.from_node(run.slots["driver"], [envelope])
    messages = received(run)
    pose = [m for topic, _, m in messages if topic == "pose"][-1]
    assert pose.pose.position.x == pytest.approx(run.sim.state.pose.x)
    plan = [m for topic, _, m in messages if topic == "plan"][-1]
    assert plan._type == "nav_msgs/msg/Path" and len(plan.poses) >= 2
    # teleop's ROS 1 Twist drives the robot and is recorded as a ROS 2 Twist.
    run.command(Teleop("up", True))
    run.core.apply_commands()
    run.core.advance_to(NS)
    assert run.sim.read("cmd_vel").linear.x > 0
    paths = run.recorder.close()

    kinds = {m.channel.topic: m.schema.name for m in decoded_messages(paths["recording"])}
    assert kinds["/cmd_vel"] == "geometry_msgs/msg/Twist"
    assert kinds["/map"] == "nav_msgs/msg/OccupancyGrid"


class EchoService(BuiltinNode):
    """A ROS 2-native built-in serving `__srv__/echo` (what the Nav2 helper's action server does
    with `<action>/_action/send_goal`): ROS 2 objects in, ROS 2 objects out. The request type is
    a String here to keep the test about the host (services carry robodojo_msgs ServiceCall)."""

    name = "echo_service"
    ros2_native = True
    publishes = (("echoed", "std_msgs/msg/String"),)

    def graph_subscriptions(self):
        return (("__srv__/echo", "std_msgs/msg/String"),)

    def on_message(self, run, topic, message):
        self.seen = message
        drive = TwistStamped2()
        drive.twist.linear.x = 0.05
        return [
            ("echoed", get_message_class("std_msgs/msg/String")(data=message.data + "!")),
            ("Control", drive),  # as Nav2's controller would on a Jazzy TurtleBot3
        ]


def test_a_ros2_native_builtin_is_a_graph_subscriber_and_speaks_ros2(tmp_path, monkeypatch):
    monkeypatch.setitem(BUILTIN_NODES, "echo_service", EchoService)
    run = prepared(tmp_path, builtin_nodes=("echo_service",))
    run.builtins.start(run.core)
    topics = {t.name: t for t in run.bus.graph_topics()}
    assert topics["__srv__/echo"].subscribers == ["echo_service"]  # wait_for_service sees it
    listen(run, "echoed", "std_msgs/msg/String")
    call = get_message_class("std_msgs/msg/String")(data="hello")
    request = Envelope("__srv__/echo", call._type, call.serialize())
    run.core.from_node(run.slots["driver"], [request])
    assert run.builtins.get("echo_service").seen == call  # the ROS 2 object, not a ROS 1 one
    assert [(t, m.data) for t, _, m in received(run)] == [("echoed", "hello!")]
    assert run.sim.read("Control").linear.x == pytest.approx(0.05)  # the twist of it
    assert not run.bus.has_pending("echo_service")  # delivered directly, nothing queued
    paths = run.recorder.close()
    with open(paths["recording"], "rb") as handle:
        recorded = {c.topic for c in make_reader(handle).get_summary().channels.values()}
    assert {"/echoed", "/__srv__/echo"} <= recorded


def test_a_ros2_native_builtin_in_a_ros1_run_is_refused(tmp_path, monkeypatch):
    monkeypatch.setitem(BUILTIN_NODES, "echo_service", EchoService)
    spec = RunSpec(
        robot="crowbot",
        world="wall_approach",
        nodes=(NodeSpec("driver", "import rospy\n", "driver.py"),),
        builtin_nodes=("echo_service",),
    )
    with pytest.raises(RunSpecError, match="'echo_service' serves ROS 2 nodes"):
        Run(spec, launcher=None, out_dir=tmp_path)


class ForgetfulNative(BuiltinNode):
    """Publishes a ROS 2 message without saying it speaks ROS 2."""

    name = "forgetful"

    def start(self, run):
        return [("said", get_message_class("std_msgs/msg/String")(data="hi"))]


def test_a_builtin_publishing_ros2_without_saying_so_gets_a_sentence(tmp_path, monkeypatch):
    monkeypatch.setitem(BUILTIN_NODES, "forgetful", ForgetfulNative)
    run = prepared(tmp_path, builtin_nodes=("forgetful",))
    with pytest.raises(TypeError, match="says ros2_native = True"):
        run.builtins.start(run.core)
    run.recorder.close()
