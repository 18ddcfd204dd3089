"""Runs through the real sandbox: controllers drive the CrowBot, crashes end runs with a reason,
nodes talk both ways, lockstep is deterministic, realtime keeps time, the recording holds every
topic, controls act while running, and a failing run leaves the others alone."""

from __future__ import annotations

import threading
import time

import pytest
from mcap.reader import make_reader

from sandbox.msgs.geometry_msgs import Twist
from sandbox.protocol import Clock
from server.runs.commands import Button, Goal, InjectFault, Pause, Resume
from server.runs.faults import FaultKind
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec, RunSpecError
from server.runs.state import RunState
from tests.waiting import wait_until

STEP_APPROACH = """
RATE_HZ = 10
SUBSCRIBE = ["Distance"]

def step(obs):
    if obs.Distance is None or obs.Distance.data == 0:
        return (0.0, 0.0)
    return (0.5 * (obs.Distance.data / 100 - 0.2), 0.0)
"""

ROSPY_APPROACH = """
import rospy
from std_msgs.msg import Int32
from geometry_msgs.msg import Twist

distance = None

def on_distance(msg):
    global distance
    distance = msg.data

rospy.init_node("approach")
rospy.Subscriber("Distance", Int32, on_distance)
pub = rospy.Publisher("Control", Twist, queue_size=1)
rate = rospy.Rate(20)
while not rospy.is_shutdown():
    cmd = Twist()
    if distance:
        cmd.linear.x = 0.5 * (distance / 100 - 0.2)
    pub.publish(cmd)
    rate.sleep()
"""


def crowbot_run(tmp_path, launcher, *nodes: NodeSpec, **options) -> Run:
    spec = RunSpec(robot="crowbot", world="wall_approach", nodes=tuple(nodes), **options)
    return Run(spec, launcher, tmp_path / "run")


def node(code: str, name: str = "controller") -> NodeSpec:
    return NodeSpec(name=name, code=code, filename=f"{name}.py")


def read_recording(path) -> dict[str, list[tuple[int, bytes]]]:
    topics: dict[str, list[tuple[int, bytes]]] = {}
    with open(path, "rb") as f:
        for _schema, channel, message in make_reader(f).iter_messages():
            topics.setdefault(channel.topic, []).append((message.log_time, message.data))
    return topics


@pytest.mark.parametrize("code", [STEP_APPROACH, ROSPY_APPROACH], ids=["step", "rospy"])
def test_a_controller_drives_the_crowbot_to_the_wall(tmp_path, launcher, code):
    run = crowbot_run(tmp_path, launcher, node(code), duration_s=15.0)
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    assert result.reason == "finished: duration reached"
    assert result.duration_s == pytest.approx(15.0)
    # Started with the sensor 0.6 m from the board; held near 0.2 m.
    assert run.sim.state.pose.x == pytest.approx(1.35 - 0.2, abs=0.03)
    assert result.metrics["collisions"] == 0
    period = result.nodes["controller"]["period"]
    assert period["p50_s"] == pytest.approx(0.1 if "RATE_HZ" in code else 0.05)
    # Lockstep wakes every node at the time it asked for.
    assert result.nodes["controller"]["wake_lateness"]["count"] > 100
    assert result.nodes["controller"]["wake_lateness"]["max_s"] == 0.0
    assert result.nodes["controller"]["latest_wakes"] == []
    assert (tmp_path / "run" / "recording.mcap").is_file()


def test_a_crashing_node_ends_the_run_with_its_line(tmp_path, launcher):
    code = "RATE_HZ = 10\n\ndef step(obs):\n    if obs.time > 0.25:\n        return 1 / 0\n"
    run = crowbot_run(tmp_path, launcher, node(code, "follower"), duration_s=5.0)
    result = run.execute()
    assert result.state is RunState.FAILED
    assert result.reason == "failed: node follower raised ZeroDivisionError at line 5"
    assert result.duration_s == pytest.approx(0.3)
    log = (tmp_path / "run" / "logs" / "follower.log").read_text()
    assert 'File "follower.py", line 5, in step' in log
    assert "ZeroDivisionError: division by zero" in log


TALKER = """
import rospy
from std_msgs.msg import Int32
rospy.init_node("talker")
heard = []
rospy.Subscriber("reply", Int32, lambda m: heard.append(m.data))
pub = rospy.Publisher("ping", Int32, queue_size=10)
rate = rospy.Rate(10)
for i in range(5):
    pub.publish(Int32(i))
    rate.sleep()
rate.sleep()
assert heard == [0, 10, 20, 30, 40], heard
rospy.loginfo("heard %s", heard)
"""

ECHO = """
import rospy
from std_msgs.msg import Int32
rospy.init_node("echo")
pub = rospy.Publisher("reply", Int32, queue_size=10)
rospy.Subscriber("ping", Int32, lambda m: pub.publish(Int32(m.data * 10)))
rospy.spin()
"""


def test_two_nodes_pass_messages_both_ways(tmp_path, launcher):
    run = crowbot_run(
        tmp_path, launcher, node(TALKER, "talker"), node(ECHO, "echo"), duration_s=3.0
    )
    result = run.execute()
    assert result.state is RunState.FINISHED, (result.reason, list(run.slots["talker"].logs))
    assert any("heard [0, 10, 20, 30, 40]" in line for line in run.slots["talker"].logs)
    graph = {t["name"]: t for t in result.graph["topics"]}
    assert graph["ping"]["publishers"] == ["talker"] and graph["ping"]["subscribers"] == ["echo"]
    assert graph["reply"]["publishers"] == ["echo"] and graph["reply"]["subscribers"] == ["talker"]


def test_lockstep_runs_with_one_seed_record_identical_payloads(tmp_path, launcher):
    recordings = []
    for attempt in range(2):
        spec = RunSpec(
            robot="crowbot",
            world="light_arena",
            nodes=(node("def step(obs):\n    return (0.05, 0.8)\n"),),
            duration_s=4.0,
            seed=7,
        )
        Run(spec, launcher, tmp_path / f"run{attempt}").execute()
        recordings.append(read_recording(tmp_path / f"run{attempt}" / "recording.mcap"))
    assert recordings[0] == recordings[1]
    assert len(recordings[0]["/Light"]) == 4 * 20 + 1


@pytest.mark.slow
def test_realtime_run_keeps_wall_time(tmp_path, launcher):
    run = crowbot_run(tmp_path, launcher, node(STEP_APPROACH), duration_s=3.0, clock=Clock.REALTIME)
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    assert 3.0 <= result.metrics["clock_wall_s"] < 3.3  # real-time factor 1
    assert result.nodes["controller"]["period"]["p50_s"] == pytest.approx(0.1, abs=0.01)
    # Each wake comes some microseconds or more after its time, and the run says when.
    late = result.nodes["controller"]["latest_wakes"]
    assert late and all(0.0 < wake["late_s"] < 0.1 and 0.0 < wake["at_s"] < 3.0 for wake in late)


def test_recording_has_every_declared_topic_with_its_schema(tmp_path, launcher):
    spec = RunSpec(
        robot="crop_rover",
        world="crop_rows",
        nodes=(node("def step(obs):\n    return (0.1, 0.0)\n"),),
        duration_s=2.0,
    )
    run = Run(spec, launcher, tmp_path / "run")
    assert run.execute().state is RunState.FINISHED
    with open(tmp_path / "run" / "recording.mcap", "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        channels = {c.topic: summary.schemas[c.schema_id] for c in summary.channels.values()}
    for topic in ("/scan", "/psi", "/imu", "/odom", "/u", "/cmd_vel", "/tf", "/goal"):
        assert topic in channels, topic
        assert channels[topic].encoding == "ros1msg"
    assert channels["/scan"].name == "sensor_msgs/LaserScan"
    assert b"float32[] ranges" in channels["/scan"].data
    counts = {
        topic: len(v) for topic, v in read_recording(tmp_path / "run" / "recording.mcap").items()
    }
    assert counts["/scan"] == pytest.approx(2.0 * 7, abs=1)
    assert counts["/cmd_vel"] == 20 + 1  # the node's 20 commands, then the run's zero at the end
    _, last_command = read_recording(tmp_path / "run" / "recording.mcap")["/cmd_vel"][-1]
    assert Twist.deserialize(last_command) == Twist()


CONTROLLED = """
import rospy
from std_msgs.msg import Bool, Int32
from geometry_msgs.msg import PoseStamped

GAP_S = 0.2  # [s] four Distance periods (20 Hz): longer than any jitter, shorter than a fault
last = [None]
pressed = [False]

def on_distance(msg):
    now = rospy.get_time()
    if last[0] is not None and now - last[0] > GAP_S:
        print("distance gap", last[0], now)
    last[0] = now

def on_button(msg):
    if msg.data and not pressed[0]:
        print("button at", round(rospy.get_time(), 2))
    pressed[0] = msg.data

rospy.init_node("controlled")
rospy.Subscriber("Distance", Int32, on_distance)
rospy.Subscriber("Button", Bool, on_button)
rospy.Subscriber("goal", PoseStamped, lambda m: print("goal", m.pose.position.x))
rospy.spin()
"""

FAULT_S = 1.0  # [s] of run time that Distance is dropped
SENSOR_PERIOD_S = 0.05  # [s] the CrowBot publishes Distance at 20 Hz


def test_controls_stop_pause_button_goal_and_faults(tmp_path, launcher):
    run = crowbot_run(tmp_path, launcher, node(CONTROLLED), duration_s=600.0)
    thread = threading.Thread(target=lambda: setattr(run, "result", run.execute()))
    thread.start()
    logs = run.slots["controller"].logs

    def printed(prefix: str) -> list[str]:
        return [line for line in list(logs) if line.startswith(prefix)]

    try:
        wait_until(lambda: run.progress[0] >= 1.0, 30, "the run reached 1 s of run time")
        run.command(Pause())
        wait_until(lambda: run.state is RunState.PAUSED, 10, "the run paused")
        paused_at = run.progress[0]
        # Behaviour under test, not a wait: a paused run's time stays still for a while.
        time.sleep(0.3)
        assert run.progress[0] == paused_at and run.state is RunState.PAUSED
        run.command(Button(True))
        run.command(Goal(1.2, 0.4))
        run.command(InjectFault(FaultKind.DROP_TOPIC, "Distance", FAULT_S))
        run.command(Resume())
        gaps = wait_until(
            lambda: printed("distance gap"), 30, "Distance reached the node again after the fault"
        )
        wait_until(
            lambda: printed("button at") and printed("goal"),
            10,
            "the node saw the button and the goal",
        )
    finally:
        run.stop("stopped by the test")
        thread.join(timeout=30)
    result = run.result
    assert result.state is RunState.INTERRUPTED
    assert result.reason == "interrupted: stopped by the test"
    assert printed("goal") == ["goal 1.2"]
    (pressed,) = printed("button at")
    assert float(pressed.split()[-1]) >= paused_at
    # One gap, the fault's: Distance stopped at the pause and came back once the fault's run
    # time was over, within one sensor period.
    assert len(gaps) == 1, gaps
    last_before, first_after = (float(t) for t in gaps[0].split()[2:])
    tolerance_s = 1e-6  # run times are printed as floats
    assert last_before <= paused_at + tolerance_s
    assert first_after - last_before >= FAULT_S - tolerance_s
    assert paused_at + FAULT_S - tolerance_s <= first_after <= paused_at + FAULT_S + SENSOR_PERIOD_S


@pytest.mark.slow
def test_a_failing_run_leaves_a_concurrent_run_alone(tmp_path, launcher):
    good = crowbot_run(tmp_path / "a", launcher, node(STEP_APPROACH), duration_s=30.0)
    results = {}
    thread = threading.Thread(target=lambda: results.setdefault("good", good.execute()))
    thread.start()
    bad = crowbot_run(tmp_path / "b", launcher, node("import os\nos._exit(3)\n"), duration_s=5)
    assert bad.execute().state is RunState.FAILED
    thread.join(timeout=60)
    assert results["good"].state is RunState.FINISHED


def test_robot_leaving_the_map_fails_the_run(tmp_path, launcher):
    spec = RunSpec(
        robot="crowbot",
        world="line_track",
        nodes=(node("def step(obs):\n    return (0.2, 0.0)\n"),),
        duration_s=60.0,
    )
    result = Run(spec, launcher, tmp_path / "run").execute()
    assert result.state is RunState.FAILED
    assert result.reason == "failed: robot left the map"


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"robot": "crowbotz"}, "valid robot ids: crop_rover, crowbot"),
        ({"world": "mars"}, "valid world ids: crop_rows"),
        ({"world": "crop_rows"}, "cannot be placed in world 'crop_rows'"),
        ({"duration_s": -1}, "positive number of seconds"),
        ({"duration_s": float("nan")}, "positive number of seconds"),
        ({"nodes": ()}, "at least one node"),
    ],
)
def test_bad_specs_are_sentences(changes, message):
    base = {"robot": "crowbot", "world": "wall_approach", "nodes": (node("x = 1\n"),)}
    with pytest.raises(RunSpecError, match=message):
        RunSpec(**{**base, **changes}).validate()


def test_missing_node_file_is_a_sentence(tmp_path):
    with pytest.raises(RunSpecError, match="does not exist"):
        NodeSpec.from_file(tmp_path / "nope.py")


# The four nodes of 002_3fcfeb7b4c14107a.txt (Fig. 8) with the paper's topic names, each a
# sandboxed node: sensor -> distance_detect -> servo -> dist_detect_left/right -> compare_distance
# -> direction -> dc_motor -> forward -> servo. Minimal logic: the point is the graph.
PAPER_NODES = {
    "sensor": """
import rospy
from std_msgs.msg import Int32, Float32
rospy.init_node("sensor")
pub = rospy.Publisher("distance_detect", Float32, queue_size=1)
rospy.Subscriber("ir_adc", Int32, lambda m: pub.publish(Float32(m.data / 10.0)))
rospy.spin()
""",
    "servo": """
import rospy
from std_msgs.msg import Float32, Int16, Int32
rospy.init_node("servo")
right = rospy.Publisher("dist_detect_right", Int16, queue_size=1)
left = rospy.Publisher("dist_detect_left", Int16, queue_size=1)
stop = rospy.Publisher("dist_detect", Int16, queue_size=1)
angle = rospy.Publisher("servo_angle", Int16, queue_size=1)
def on_distance(msg):
    right.publish(Int16(int(msg.data)))
    left.publish(Int16(int(msg.data) + 1))
    stop.publish(Int16(0))
rospy.Subscriber("distance_detect", Float32, on_distance)
rospy.Subscriber("forward", Int32, lambda m: angle.publish(Int16(90)))
rospy.spin()
""",
    "compare_distance": """
import rospy
from std_msgs.msg import Int16, String
rospy.init_node("compare_distance")
direction = rospy.Publisher("direction", String, queue_size=1)
seen = {}
def compare(side):
    def on(msg):
        seen[side] = msg.data
        if len(seen) == 2:
            direction.publish(String("left" if seen["left"] > seen["right"] else "right"))
    return on
rospy.Subscriber("dist_detect_left", Int16, compare("left"))
rospy.Subscriber("dist_detect_right", Int16, compare("right"))
rospy.spin()
""",
    "dc_motor": """
import rospy
from std_msgs.msg import Int16, Int32, String
rospy.init_node("dc_motor")
motor = rospy.Publisher("motor_command", String, queue_size=1)
forward = rospy.Publisher("forward", Int32, queue_size=1)
rospy.Subscriber("dist_detect", Int16, lambda m: None)
def on_direction(msg):
    motor.publish(String(msg.data))
    forward.publish(Int32(1))
rospy.Subscriber("direction", String, on_direction)
rospy.spin()
""",
}


@pytest.mark.slow
def test_the_papers_four_node_graph_runs_as_four_sandboxes(tmp_path, launcher):
    nodes = tuple(node(code, name) for name, code in PAPER_NODES.items())
    spec = RunSpec(robot="ir_scout", world="obstacle_maze", nodes=nodes, duration_s=2.0)
    result = Run(spec, launcher, tmp_path / "run").execute()
    assert result.state is RunState.FINISHED, result.reason
    topics = {t["name"]: t for t in result.graph["topics"]}
    expected = {
        "ir_adc": (["robot"], ["sensor"]),
        "distance_detect": (["sensor"], ["servo"]),
        "dist_detect_right": (["servo"], ["compare_distance"]),
        "dist_detect_left": (["servo"], ["compare_distance"]),
        "dist_detect": (["servo"], ["dc_motor"]),
        "direction": (["compare_distance"], ["dc_motor"]),
        "forward": (["dc_motor"], ["servo"]),
        "motor_command": (["dc_motor"], []),
        "servo_angle": (["servo"], []),
    }
    for name, (publishers, subscribers) in expected.items():
        assert (topics[name]["publishers"], topics[name]["subscribers"]) == (
            publishers,
            subscribers,
        ), name
        assert topics[name]["messages"] > 0, name
    # ir_adc comes at 25 Hz; compare_distance answers each of its two inputs: 50 Hz downstream.
    assert topics["ir_adc"]["rate_hz"] == pytest.approx(25.0, rel=0.1)
    assert topics["motor_command"]["rate_hz"] == pytest.approx(50.0, rel=0.1)


def failing_sim_run(spec: RunSpec, launcher, out_dir) -> Run:
    """A run whose robot backend raises after a while (the fault a broken driver would cause)."""
    run = Run(spec, launcher, out_dir)
    prepare = run.core.prepare

    def prepare_failing() -> None:
        prepare()
        real_step = run.sim.step

        def step(dt_s: float):
            if run.sim.time_s > 1.0:
                raise RuntimeError("motor controller stopped answering")
            return real_step(dt_s)

        run.sim.step = step

    run.core.prepare = prepare_failing
    return run


def test_a_raising_robot_backend_or_recorder_ends_only_its_run(tmp_path, launcher):
    good = crowbot_run(tmp_path / "good", launcher, node(STEP_APPROACH), duration_s=6.0)
    results = {}
    thread = threading.Thread(target=lambda: results.setdefault("good", good.execute()))
    thread.start()
    spec = RunSpec("crowbot", "wall_approach", (node(STEP_APPROACH),), duration_s=5.0)
    broken = failing_sim_run(spec, launcher, tmp_path / "broken").execute()
    assert broken.state is RunState.FAILED
    assert "motor controller stopped answering" in broken.reason
    full_disk = tmp_path / "full"
    full_disk.mkdir()
    (full_disk / "recording.mcap").symlink_to("/dev/full")
    recorder_fails = Run(spec, launcher, full_disk).execute()
    assert recorder_fails.state is RunState.FAILED
    assert "recording failed" in recorder_fails.reason and "No space left" in recorder_fails.reason
    thread.join(timeout=60)
    assert results["good"].state is RunState.FINISHED
