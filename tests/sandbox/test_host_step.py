"""The step API in the node host: return forms, SUBSCRIBE, setup, RATE_HZ, obs; the examples."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox.msgs import get_message_class
from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.std_msgs import Bool, Int32, Int32MultiArray
from sandbox.protocol import Api, Clock, NodeInfo, Outcome, RobotTopic, TopicDecl, Yield
from server.sim.registry import get_robot
from tests.sandbox.test_host_harness import Parent, crowbot_info, envelope, run

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "step_api"
VELOCITY_TOPIC = {"crowbot": "Control"}  # the others use cmd_vel


def twist(v: float, w: float) -> Twist:
    command = Twist()
    command.linear.x, command.angular.z = v, w
    return command


def steps(parent: Parent, n: int, deliveries=lambda k: []) -> list[Yield]:
    frames = [parent.next()]
    for k in range(n):
        frame = frames[-1]
        assert isinstance(frame, Yield), frame
        frames.append(parent.wake(frame.wake_at_s, deliveries(k)))
    return frames


def test_each_return_form_publishes_what_it_says(tmp_path: Path) -> None:
    parent = Parent(
        """
        from geometry_msgs.msg import Twist
        from std_msgs.msg import Int32MultiArray
        RATE_HZ = 4
        calls = 0
        def step(obs):
            global calls
            calls += 1
            if calls == 1:
                return None
            if calls == 2:
                return {"Leds": Int32MultiArray(data=[1, 2, 3]), "Buzzer": True, "Control": None}
            if calls == 3:
                t = Twist()
                t.angular.z = 0.5
                return t
            return (0.1, -0.2)
        """,
        tmp_path,
    )
    frames = steps(parent, 4)
    assert [f.wake_at_s for f in frames] == pytest.approx([0.0, 0.25, 0.5, 0.75, 1.0])
    assert frames[0].subscribed == [
        TopicDecl(t.name, t.type) for t in crowbot_info().robot_topics if t.direction == "publish"
    ]
    published = [
        [(e.topic, get_message_class(e.type).deserialize(e.data)) for e in f.published]
        for f in frames[1:]
    ]
    assert published == [
        [],
        [("Leds", Int32MultiArray(data=[1, 2, 3])), ("Buzzer", Bool(True))],
        [("Control", twist(0.0, 0.5))],
        [("Control", twist(0.1, -0.2))],
    ]
    assert frames[2].advertised == [
        TopicDecl("Leds", "std_msgs/Int32MultiArray"),
        TopicDecl("Buzzer", "std_msgs/Bool"),
    ]
    assert parent.shutdown().outcome is Outcome.SHUTDOWN


def test_obs_holds_latest_messages_time_and_none_for_silent_topics(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parent = Parent(
        """
        SUBSCRIBE = ["Distance", "/Button"]
        def setup(info):
            print("setup", info.robot, info.params["mode"])
        def step(obs):
            d = obs.Distance.data if obs.Distance is not None else None
            print(f"t={obs.time:.2f} d={d} button={obs['Button']} get={obs.get('Button', 'none')}")
        """,
        tmp_path,
        info=crowbot_info(params={"mode": "test"}, default_rate_hz=5.0),
    )
    frames = steps(parent, 3, lambda k: [envelope("Distance", Int32(30 - k))] if k < 2 else [])
    assert frames[0].subscribed == [
        TopicDecl("Distance", "std_msgs/Int32"),
        TopicDecl("Button", "std_msgs/Bool"),
    ]
    assert frames[-1].wake_at_s == pytest.approx(0.6)  # default_rate_hz = 5
    parent.shutdown()
    assert capsys.readouterr().out.splitlines() == [
        "setup crowbot test",
        "t=0.00 d=30 button=None get=none",
        "t=0.20 d=29 button=None get=none",
        "t=0.40 d=29 button=None get=none",  # nothing new: the latest value stays
    ]


@pytest.mark.parametrize(
    ("expression", "expected"),
    [
        ("obs.Distnce", "obs has no 'Distnce'; did you mean 'Distance'? valid names: Distance"),
        ("obs['Light']", "'Light': it is not in SUBSCRIBE; add it there"),
    ],
)
def test_obs_explains_unknown_names(tmp_path: Path, expression: str, expected: str) -> None:
    _, exited = run(
        f"SUBSCRIBE = ['Distance']\ndef step(obs):\n    return {expression}\n", tmp_path
    )
    assert exited.outcome is Outcome.ERROR
    assert expected in exited.error.message
    assert exited.error.line == 3


@pytest.mark.parametrize(
    ("code", "message", "line"),
    [
        ("RATE_HZ = 0\ndef step(obs): pass\n", "0 < RATE_HZ <= 1000", 1),
        ("\nRATE_HZ = 5000\ndef step(obs): pass\n", "got 5000", 2),
        ("SUBSCRIBE = ['Distanse']\ndef step(obs): pass\n", "did you mean 'Distance'?", 1),
        ("\n\ndef step(obs):\n    return 'fast'\n", "step() returned a str ('fast')", 3),
        (
            "from std_msgs.msg import Bool\ndef step(obs):\n    return Bool(True)\n",
            "returned a std_msgs/Bool message; return it in a dict",
            2,
        ),
        ("def step(obs):\n    return {'Distance': 5}\n", "'Distance' is published by the robot", 1),
        ("def step(obs):\n    return {'Leds': 'red'}\n", "std_msgs/Int32MultiArray.data", 1),
    ],
)
def test_step_contract_errors_name_what_was_wrong(
    tmp_path: Path, code: str, message: str, line: int
) -> None:
    _, exited = run(code, tmp_path, api=Api.STEP)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "StepError"
    assert message in exited.error.message
    assert exited.error.line == line


def test_auto_picks_rospy_when_the_file_calls_init_node(tmp_path: Path) -> None:
    yields, exited = run(
        "import rospy\ndef step(obs):\n    pass\nrospy.init_node('x')\nprint(__name__)\n",
        tmp_path,
    )
    assert yields == [] and exited.outcome is Outcome.FINISHED


def test_signal_shutdown_in_step_finishes(tmp_path: Path) -> None:
    yields, exited = run(
        "import rospy\nRATE_HZ = 10\ndef step(obs):\n"
        "    if obs.time >= 0.3:\n        rospy.signal_shutdown('arrived')\n",
        tmp_path,
    )
    assert len(yields) == 4
    assert exited.outcome is Outcome.FINISHED and exited.reason == "signal_shutdown: arrived"


def robot_info(robot_id: str) -> NodeInfo:
    robot = get_robot(robot_id)
    return NodeInfo(
        node_name="example",
        robot=robot_id,
        robot_topics=[
            RobotTopic(t.name, t.type_name, str(t.direction), t.rate_hz) for t in robot.topics()
        ],
        velocity_topic=VELOCITY_TOPIC.get(robot_id, "cmd_vel"),
        clock=Clock.LOCKSTEP,
    )


@pytest.mark.parametrize(
    "robot_id", ["crowbot", "crop_rover", "ir_scout", "turtlebot", "turtlebot3"]
)
def test_each_robot_example_runs_against_synthetic_sensors(tmp_path: Path, robot_id: str) -> None:
    info = robot_info(robot_id)
    sensors = [t for t in info.robot_topics if t.direction == "publish"]

    def readings(k: int) -> list:
        # Default-valued messages of every sensor type, plus a near obstacle from step 3 on.
        out = []
        for topic in sensors:
            message = get_message_class(topic.type)()
            if topic.type == "std_msgs/Int32":
                message.data = 10 if k >= 3 else 80
            if topic.type == "sensor_msgs/Range":
                message.range = 0.1 if k >= 3 else 0.7
            if topic.type == "sensor_msgs/LaserScan":
                message.ranges = [0.4 if k >= 3 else 2.0] * 8
                message.range_max = 3.0
            out.append(envelope(topic.name, message))
        return out

    code = (EXAMPLES / f"{robot_id}.py").read_text()
    parent = Parent(code, tmp_path, info=info, filename=f"{robot_id}.py")
    frames = steps(parent, 6, readings)
    assert all(isinstance(f, Yield) for f in frames), frames[-1]
    commands = {e.topic for f in frames for e in f.published}
    command_topics = {t.name for t in info.robot_topics if t.direction == "subscribe"}
    assert commands and commands <= command_topics
    exited = parent.shutdown()
    assert exited.outcome is Outcome.SHUTDOWN, exited.error
