"""ROS 1 patterns through the real run engine and sandbox, on both clocks: services between
nodes, wait_for_message, a busy loop that drives the robot, tf for nodes, and figures saved
after signal_shutdown coming back as artifacts."""

from __future__ import annotations

import pytest
from mcap.reader import make_reader

from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.std_msgs import Int32
from sandbox.protocol import Clock
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState

CLOCKS = [Clock.LOCKSTEP, Clock.REALTIME]


def crowbot_run(tmp_path, launcher, *nodes: NodeSpec, **options) -> Run:
    spec = RunSpec(robot="crowbot", world="wall_approach", nodes=tuple(nodes), **options)
    return Run(spec, launcher, tmp_path / "run")


def node(code: str, name: str) -> NodeSpec:
    return NodeSpec(name=name, code=code, filename=f"{name}.py")


def recorded(run_dir, topic: str) -> list[tuple[int, bytes]]:
    with open(run_dir / "recording.mcap", "rb") as f:
        return [
            (message.log_time, message.data)
            for _, channel, message in make_reader(f).iter_messages()
            if channel.topic == "/" + topic
        ]


def log_of(run_dir, name: str) -> str:
    return (run_dir / "logs" / f"{name}.log").read_text()


SERVER = """
import rospy
from std_srvs.srv import SetBool, SetBoolResponse
from geometry_msgs.msg import Twist

driving = False

def on_enable(req):
    global driving
    driving = req.data
    return SetBoolResponse(success=True, message="driving" if driving else "stopped")

rospy.init_node('base')
rospy.Service('enable', SetBool, on_enable)
pub = rospy.Publisher('Control', Twist, queue_size=1)
rate = rospy.Rate(20)
while not rospy.is_shutdown():
    cmd = Twist()
    cmd.linear.x = 0.1 if driving else 0.0
    pub.publish(cmd)
    rate.sleep()
"""

CLIENT = """
import rospy
from std_srvs.srv import SetBool

rospy.init_node('operator')
rospy.wait_for_service('enable', timeout=5)
enable = rospy.ServiceProxy('enable', SetBool)
rospy.sleep(1.0)
reply = enable(True)
rospy.loginfo("reply %s %s at %.2f", reply.success, reply.message, rospy.get_time())
try:
    rospy.ServiceProxy('missing', SetBool)(True)
except rospy.ServiceException as error:
    rospy.loginfo("as expected: %s", error)
rospy.sleep(1.0)
reply = enable(data=False)
rospy.loginfo("reply %s %s", reply.success, reply.message)
"""


@pytest.mark.slow
@pytest.mark.parametrize("clock", CLOCKS)
def test_a_service_between_two_nodes_switches_the_robot(tmp_path, launcher, clock) -> None:
    run = crowbot_run(
        tmp_path,
        launcher,
        node(SERVER, "base"),
        node(CLIENT, "operator"),
        duration_s=3.0,
        clock=clock,
    )
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    log = log_of(tmp_path / "run", "operator")
    answered_at = float(log.split("reply True driving at ")[1].split()[0])
    # Lockstep: within the instant the call was made; realtime: well before the 1 s re-check.
    assert answered_at == pytest.approx(1.0, abs=0.0 if clock is Clock.LOCKSTEP else 0.3)
    assert "as expected: service [/missing] unavailable" in log
    assert "reply True stopped" in log
    speeds = [
        (t / 1e9, Twist.deserialize(d).linear.x) for t, d in recorded(tmp_path / "run", "Control")
    ]
    moving = [t for t, v in speeds if v > 0]
    assert moving, speeds
    assert 0.95 <= moving[0] <= 1.2 and 1.9 <= moving[-1] <= 2.3
    assert result.graph["topics"]  # the service's topics are in the graph
    assert any(t["name"] == "__srv__/enable" for t in result.graph["topics"])


WAITER = """
import rospy
from std_msgs.msg import Int32
rospy.init_node('waiter')
first = rospy.wait_for_message('Distance', Int32, timeout=5)
rospy.loginfo("first reading %d cm after %.3f s", first.data, rospy.get_time())
"""


@pytest.mark.parametrize("clock", CLOCKS)
def test_wait_for_message_returns_at_the_first_message(tmp_path, launcher, clock) -> None:
    result = crowbot_run(
        tmp_path, launcher, node(WAITER, "waiter"), duration_s=6.0, clock=clock
    ).execute()
    assert result.state is RunState.FINISHED, result.reason
    assert result.reason == "finished: every node ended"
    log = log_of(tmp_path / "run", "waiter")
    waited = float(log.split("after ")[1].split(" s")[0])
    assert waited < 0.2  # the CrowBot's Distance comes at 20 Hz, not after the 5 s timeout


BUSY_DRIVER = """
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

distance = 100

def on_distance(msg):
    global distance
    distance = msg.data

rospy.init_node('wall_stop')
pub = rospy.Publisher('Control', Twist, queue_size=1)
rospy.Subscriber('Distance', Int32, on_distance)
while not rospy.is_shutdown():
    cmd = Twist()
    cmd.linear.x = 0.15 if distance > 25 else 0.0
    pub.publish(cmd)
"""


@pytest.mark.slow
@pytest.mark.parametrize("clock", CLOCKS)
def test_a_busy_loop_drives_the_robot_and_sees_its_sensor(tmp_path, launcher, clock) -> None:
    result = crowbot_run(
        tmp_path, launcher, node(BUSY_DRIVER, "wall_stop"), duration_s=6.0, clock=clock
    ).execute()
    assert result.state is RunState.FINISHED, result.reason
    assert result.reason == "finished: duration reached"
    # It drove from 60 cm and stopped near 25 cm: its callback saw the wall coming.
    readings = [Int32.deserialize(d).data for _, d in recorded(tmp_path / "run", "Distance")]
    assert readings[0] > 50
    assert 18 <= readings[-1] <= 27, readings[-20:]


@pytest.mark.slow
def test_a_busy_loop_run_is_reproducible(tmp_path, launcher) -> None:
    first = crowbot_run(tmp_path / "a", launcher, node(BUSY_DRIVER, "wall_stop"), duration_s=3.0)
    second = crowbot_run(tmp_path / "b", launcher, node(BUSY_DRIVER, "wall_stop"), duration_s=3.0)
    assert first.execute().state is RunState.FINISHED
    assert second.execute().state is RunState.FINISHED
    assert recorded(tmp_path / "a" / "run", "Control") == recorded(
        tmp_path / "b" / "run", "Control"
    )


TF_READER = """
import rospy
from tf2_msgs.msg import TFMessage

frames = set()

def on_tf(msg):
    for t in msg.transforms:
        frames.add((t.header.frame_id, t.child_frame_id))

rospy.init_node('tf_reader')
rospy.Subscriber('/tf', TFMessage, on_tf)
rospy.sleep(0.5)
rospy.loginfo("frames %s", sorted(frames))
"""


def test_nodes_see_the_transform_tree_on_tf(tmp_path, launcher) -> None:
    result = crowbot_run(tmp_path, launcher, node(TF_READER, "tf_reader"), duration_s=2.0).execute()
    assert result.state is RunState.FINISHED, result.reason
    assert "('map', 'base_link')" in log_of(tmp_path / "run", "tf_reader")


PLOTTER = """
import rospy
import matplotlib.pyplot as plt
from std_msgs.msg import Int32
from geometry_msgs.msg import Twist

readings = []
rospy.init_node('logger')
rospy.Subscriber('Distance', Int32, lambda m: readings.append(m.data))
pub = rospy.Publisher('Control', Twist, queue_size=1)
rospy.on_shutdown(lambda: pub.publish(Twist()))
rate = rospy.Rate(10)
for _ in range(20):
    cmd = Twist()
    cmd.linear.x = 0.05
    pub.publish(cmd)
    rate.sleep()
rospy.signal_shutdown("logged enough")
for name in ("distance", "histogram"):
    fig = plt.figure(figsize=(12, 6), dpi=200)   # 2400 x 1200 pixels, as the paper's scripts
    plt.plot(readings) if name == "distance" else plt.hist(readings)
    fig.savefig(name + ".png")
    plt.close(fig)
"""


@pytest.mark.slow
@pytest.mark.parametrize("clock", CLOCKS)
def test_figures_saved_after_signal_shutdown_come_back(tmp_path, launcher, clock) -> None:
    result = crowbot_run(
        tmp_path, launcher, node(PLOTTER, "logger"), duration_s=10.0, clock=clock
    ).execute()
    assert result.state is RunState.FINISHED, result.reason
    assert result.reason == "finished: every node ended"
    artifacts = tmp_path / "run" / "artifacts" / "logger"
    for name in ("distance.png", "histogram.png"):
        data = (artifacts / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
        assert (width, height) == (2400, 1200)
    # The hook's zero Twist was the last command the robot got from the node.
    commands = recorded(tmp_path / "run", "Control")
    assert Twist.deserialize(commands[-1][1]) == Twist()
    assert result.duration_s < 3.0  # the run ended with its only node, not at 10 s


def test_an_error_while_finishing_fails_the_run(tmp_path, launcher) -> None:
    code = "import rospy\nrospy.init_node('n')\nrospy.signal_shutdown('done')\n1 / 0\n"
    result = crowbot_run(tmp_path, launcher, node(code, "n"), duration_s=2.0).execute()
    assert result.state is RunState.FAILED
    assert result.reason == "failed: node n raised ZeroDivisionError at line 4"


LATCHER = """
import rospy
from std_msgs.msg import String
rospy.init_node('map_maker')
rospy.Publisher('map_name', String, queue_size=1, latch=True).publish("office")
rospy.Publisher('news', String, queue_size=1).publish("old news")
rospy.spin()
"""

LATE_LISTENER = """
import rospy
from std_msgs.msg import String
rospy.init_node('late')
rospy.sleep(1.0)
rospy.Subscriber('map_name', String, lambda m: rospy.loginfo("latched %s", m.data))
rospy.Subscriber('news', String, lambda m: rospy.loginfo("news %s", m.data))
rospy.sleep(0.5)
"""


@pytest.mark.slow
def test_a_latched_topic_reaches_a_late_subscriber(tmp_path, launcher) -> None:
    result = crowbot_run(
        tmp_path,
        launcher,
        node(LATCHER, "map_maker"),
        node(LATE_LISTENER, "late"),
        duration_s=2.0,
    ).execute()
    assert result.state is RunState.FINISHED, result.reason
    log = log_of(tmp_path / "run", "late")
    assert "latched office" in log
    assert "news" not in log  # not latched: gone before the subscriber came


def test_a_tf_listener_gets_the_tree_at_30_hz_in_lockstep(tmp_path, launcher) -> None:
    code = TF_READER.replace(
        "rospy.sleep(0.5)",
        "count = [0]\nrospy.Subscriber('tf', TFMessage, "
        "lambda m: count.__setitem__(0, count[0] + 1))\nrospy.sleep(1.0)\n"
        "rospy.loginfo('tf messages %d', count[0])",
    )
    result = crowbot_run(tmp_path, launcher, node(code, "tf_reader"), duration_s=2.0).execute()
    assert result.state is RunState.FINISHED, result.reason
    count = int(log_of(tmp_path / "run", "tf_reader").split("tf messages ")[1].split()[0])
    assert 28 <= count <= 31  # 1 s of a 30 Hz tree, though the node sleeps for a whole second
