"""The built-in Nav2 server end to end: rclpy action clients in the sandbox send NavigateToPose
and FollowWaypoints goals over the rcl_action wire; the robot drives in the office world."""

from __future__ import annotations

import math

import pytest

from sandbox.protocol import Clock
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState

NAV2 = ("map_server", "localization", "nav2")

# The robot starts at (2.0, 1.3) facing +y in the office's lab room.
CLIENT = """
import math
import sys
import rclpy
from rclpy.action import ActionClient
from rclpy.duration import Duration
from rclpy.node import Node
from nav2_msgs.action import NavigateToPose

X, Y, YAW, CANCEL_AFTER_S = (float(a) for a in sys.argv[1:5])


class Client(Node):
    def __init__(self):
        super().__init__("client")
        self.action = ActionClient(self, NavigateToPose, "navigate_to_pose")
        self.feedback = []

    def on_feedback(self, message):
        fb = message.feedback
        self.feedback.append(
            (fb.navigation_time.sec + fb.navigation_time.nanosec * 1e-9, fb.distance_remaining)
        )


def main():
    rclpy.init()
    node = Client()
    print("server", node.action.wait_for_server(timeout_sec=5.0))
    goal = NavigateToPose.Goal()
    goal.pose.header.frame_id = "map"
    goal.pose.pose.position.x = X
    goal.pose.pose.position.y = Y
    goal.pose.pose.orientation.z = math.sin(YAW / 2)
    goal.pose.pose.orientation.w = math.cos(YAW / 2)
    sent = node.action.send_goal_async(goal, feedback_callback=node.on_feedback)
    rclpy.spin_until_future_complete(node, sent)
    handle = sent.result()
    print("accepted", handle.accepted)
    result = handle.get_result_async()
    if CANCEL_AFTER_S > 0:
        rclpy.spin_until_future_complete(node, result, timeout_sec=CANCEL_AFTER_S)
        canceled = handle.cancel_goal_async()
        rclpy.spin_until_future_complete(node, canceled)
        print("cancel", canceled.result().return_code, len(canceled.result().goals_canceling))
    rclpy.spin_until_future_complete(node, result)
    print("status", result.result().status, "error", repr(result.result().result.error_msg))
    times = [t for t, _ in node.feedback]
    distances = [d for _, d in node.feedback]
    ends = [round(distances[0], 2), round(distances[-1], 2)] if distances else [None, None]
    print("feedback", len(node.feedback), times == sorted(times), *ends)
    settled = node.get_clock().now() + Duration(seconds=1.0)  # the robot comes to rest
    while node.get_clock().now() < settled:
        rclpy.spin_once(node, timeout_sec=0.1)
    rclpy.shutdown()


main()
"""


def run_client(tmp_path, launcher, clock, *args, duration_s=20.0, params=None):
    spec = RunSpec(
        "turtlebot",
        "office",
        (NodeSpec("client", CLIENT, "client.py", args=tuple(str(a) for a in args)),),
        clock=clock,
        duration_s=duration_s,
        spawn="start",
        builtin_nodes=NAV2,
        params=params or {},
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    lines = list(run.slots["client"].logs)
    return run, result, lines


def line(lines, prefix):
    found = [entry for entry in lines if entry.startswith(prefix)]
    assert found, f"no line starting {prefix!r} in {lines}"
    return found[-1].split()


@pytest.mark.slow
@pytest.mark.parametrize("clock", [Clock.LOCKSTEP, Clock.REALTIME])
def test_navigate_to_pose_drives_there_with_feedback_and_succeeds(tmp_path, launcher, clock):
    run, result, lines = run_client(tmp_path, launcher, clock, 3.0, 2.2, 0.0, 0)
    assert result.state is RunState.FINISHED, (result.reason, lines)
    assert line(lines, "server") == ["server", "True"]
    assert line(lines, "accepted") == ["accepted", "True"]
    assert line(lines, "status")[:2] == ["status", "4"]  # SUCCEEDED
    _, count, ordered, first, last = line(lines, "feedback")
    assert int(count) > 10 and ordered == "True"
    assert float(first) > 1.0 and float(last) < 0.3  # the distance along the plan came down
    pose = run.sim.state.pose
    assert math.hypot(pose.x - 3.0, pose.y - 2.2) <= 0.25
    assert abs(math.remainder(pose.yaw, 2 * math.pi)) <= 0.25 + 0.05  # turned to the goal's yaw
    topics = {t["name"]: t for t in result.graph["topics"]}
    assert topics["plan"]["messages"] == 1
    assert "nav2" in topics["navigate_to_pose/_action/status"]["publishers"]


def test_a_canceled_goal_ends_canceled_and_the_robot_stops(tmp_path, launcher):
    run, result, lines = run_client(tmp_path, launcher, Clock.LOCKSTEP, 3.0, 2.2, 0.0, 1.5)
    assert result.state is RunState.FINISHED, (result.reason, lines)
    assert line(lines, "cancel") == ["cancel", "0", "1"]  # ERROR_NONE, one goal canceling
    assert line(lines, "status")[:2] == ["status", "5"]  # CANCELED
    assert run.sim.state.linear_m_s == pytest.approx(0.0, abs=1e-3)


def test_an_unreachable_goal_is_aborted_with_a_sentence(tmp_path, launcher):
    # (0.5, 0.5) lies in the office's outer wall.
    run, result, lines = run_client(tmp_path, launcher, Clock.LOCKSTEP, 0.5, 0.5, 0.0, 0)
    assert result.state is RunState.FINISHED, (result.reason, lines)
    words = line(lines, "status")
    assert words[:2] == ["status", "6"]  # ABORTED
    sentence = " ".join(words[3:])
    assert "(0.50, 0.50) is in or too close to an obstacle" in sentence
    nav2_log = (run.out_dir / "logs").glob("nav2*")
    assert any("too close to an obstacle" in path.read_text() for path in nav2_log)


@pytest.mark.slow
def test_without_the_controller_service_the_goal_aborts_naming_it(tmp_path, launcher):
    params = {"controller_service": "compute_velocity_commands"}
    _, result, lines = run_client(
        tmp_path, launcher, Clock.LOCKSTEP, 3.0, 2.2, 0.0, 0, params=params
    )
    assert result.state is RunState.FINISHED, (result.reason, lines)
    words = line(lines, "status")
    assert words[:2] == ["status", "6"]
    assert "no node serves 'compute_velocity_commands'" in " ".join(words)


WAYPOINTS = """
import rclpy
from rclpy.action import ActionClient
from rclpy.node import Node
from geometry_msgs.msg import PoseStamped
from nav2_msgs.action import FollowWaypoints


def pose(x, y):
    p = PoseStamped()
    p.header.frame_id = "map"
    p.pose.position.x, p.pose.position.y = x, y
    p.pose.orientation.w = 1.0
    return p


def main():
    rclpy.init()
    node = Node("waypoints")
    action = ActionClient(node, FollowWaypoints, "follow_waypoints")
    action.wait_for_server()
    seen = []
    goal = FollowWaypoints.Goal(poses=[pose(2.0, 2.2), pose(2.8, 2.2), pose(0.5, 0.5)])
    sent = action.send_goal_async(
        goal, feedback_callback=lambda m: seen.append(m.feedback.current_waypoint)
    )
    rclpy.spin_until_future_complete(node, sent)
    result = sent.result().get_result_async()
    rclpy.spin_until_future_complete(node, result)
    missed = result.result().result.missed_waypoints
    print("status", result.result().status, "waypoints", sorted(set(seen)),
          "missed", [m.index for m in missed])
    rclpy.shutdown()


main()
"""


def test_follow_waypoints_visits_each_and_stops_at_the_unreachable_one(tmp_path, launcher):
    spec = RunSpec(
        "turtlebot",
        "office",
        (NodeSpec("waypoints", WAYPOINTS, "waypoints.py"),),
        clock=Clock.LOCKSTEP,
        duration_s=30.0,
        spawn="start",
        builtin_nodes=NAV2,
        params={"yaw_goal_tolerance": math.pi},
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    lines = list(run.slots["waypoints"].logs)
    # stop_on_failure (Nav2's default): the third waypoint is missed and the goal ABORTED
    assert line(lines, "status") == ["status", "6", "waypoints", "[0,", "1,", "2]", "missed", "[2]"]
    topics = {t["name"]: t for t in result.graph["topics"]}
    assert topics["plan"]["messages"] == 2


SLOW_CONTROLLER = """
import time
import rclpy
from rclpy.node import Node
from robodojo_msgs.srv import ComputeVelocityCommands


def compute(request, response):
    time.sleep(0.3)  # longer than the 0.2 s control period
    response.cmd_vel.linear.x = 0.1
    return response


rclpy.init()
node = Node("slow_controller")
node.create_service(ComputeVelocityCommands, "compute_velocity_commands", compute)
rclpy.spin(node)
"""


@pytest.mark.slow
def test_a_controller_service_slower_than_the_control_period_is_warned_about(tmp_path, launcher):
    spec = RunSpec(
        "turtlebot",
        "office",
        (
            NodeSpec("client", CLIENT, "client.py", args=("3.0", "2.2", "0.0", "2.0")),
            NodeSpec("slow", SLOW_CONTROLLER, "slow.py"),
        ),
        clock=Clock.REALTIME,
        duration_s=4.0,
        spawn="start",
        builtin_nodes=NAV2,
        params={"controller_service": "compute_velocity_commands", "controller_frequency": 5.0},
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    log = "".join(path.read_text() for path in (tmp_path / "run" / "logs").glob("nav2*"))
    assert "took longer than one control period (0.200 s) to answer" in log
    assert run.sim.state.distance_travelled_m > 0.02  # its answers still drove the robot


PREEMPT = """
import rclpy
from rclpy.action import ActionClient
from rclpy.node import Node
from nav2_msgs.action import NavigateToPose


def goal(x, y):
    g = NavigateToPose.Goal()
    g.pose.header.frame_id = "map"
    g.pose.pose.position.x, g.pose.pose.position.y = x, y
    g.pose.pose.orientation.w = 1.0
    return g


rclpy.init()
node = Node("preempt")
action = ActionClient(node, NavigateToPose, "navigate_to_pose")
action.wait_for_server()
handles = []
for target in (goal(3.0, 2.2), goal(2.0, 2.3)):
    sent = action.send_goal_async(target)
    rclpy.spin_until_future_complete(node, sent)
    handles.append(sent.result())
results = [h.get_result_async() for h in handles]
for future in results:
    rclpy.spin_until_future_complete(node, future)
print("statuses", [f.result().status for f in results], repr(results[0].result().result.error_msg))
rclpy.shutdown()
"""


def test_a_new_goal_preempts_the_running_one_which_ends_aborted(tmp_path, launcher):
    spec = RunSpec(
        "turtlebot",
        "office",
        (NodeSpec("preempt", PREEMPT, "preempt.py"),),
        clock=Clock.LOCKSTEP,
        duration_s=20.0,
        spawn="start",
        builtin_nodes=NAV2,
        params={"yaw_goal_tolerance": math.pi},
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    words = line(list(run.slots["preempt"].logs), "statuses")
    assert words[1:3] == ["[6,", "4]"]  # the first ABORTED, the second SUCCEEDED
    assert "preempted" in " ".join(words)
    pose = run.sim.state.pose
    assert math.hypot(pose.x - 2.0, pose.y - 2.3) <= 0.25


CANCEL_WAYPOINTS = """
import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult
from rclpy.duration import Duration


def pose(navigator, x, y):
    p = PoseStamped()
    p.header.frame_id = "map"
    p.header.stamp = navigator.get_clock().now().to_msg()
    p.pose.position.x, p.pose.position.y = x, y
    p.pose.orientation.w = 1.0
    return p


rclpy.init()
navigator = BasicNavigator()
navigator.waitUntilNav2Active()
navigator.followWaypoints([pose(navigator, 2.0, 2.2), pose(navigator, 3.0, 2.2)])
start = navigator.get_clock().now()
while not navigator.isTaskComplete():
    if navigator.get_clock().now() - start > Duration(seconds=2.0):
        navigator.cancelTask()
print("result", navigator.getResult() == TaskResult.CANCELED)
rclpy.shutdown()
"""


def test_canceling_follow_waypoints_cancels_its_navigation_and_stops(tmp_path, launcher):
    spec = RunSpec(
        "turtlebot",
        "office",
        (NodeSpec("mission", CANCEL_WAYPOINTS, "mission.py"),),
        clock=Clock.LOCKSTEP,
        duration_s=10.0,
        spawn="start",
        builtin_nodes=NAV2,
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    assert line(list(run.slots["mission"].logs), "result") == ["result", "True"]
    log = "".join(path.read_text() for path in (tmp_path / "run" / "logs").glob("nav2*"))
    assert "navigate_to_pose: canceled by a client" in log
    assert "heading to (3.00, 2.20)" not in log  # the second waypoint never started


THROUGH = """
import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult


def pose(navigator, x, y):
    p = PoseStamped()
    p.header.frame_id = "map"
    p.pose.position.x, p.pose.position.y = x, y
    p.pose.orientation.w = 1.0
    return p


rclpy.init()
navigator = BasicNavigator()
navigator.waitUntilNav2Active()
navigator.goThroughPoses([pose(navigator, 2.0, 2.2), pose(navigator, 3.0, 2.2)])
remaining = []
while not navigator.isTaskComplete():
    feedback = navigator.getFeedback()
    if feedback and (not remaining or remaining[-1] != feedback.number_of_poses_remaining):
        remaining.append(feedback.number_of_poses_remaining)
print("result", navigator.getResult() == TaskResult.SUCCEEDED, "remaining", remaining)
rclpy.shutdown()
"""


def test_navigate_through_poses_passes_each_and_counts_them_down(tmp_path, launcher):
    spec = RunSpec(
        "turtlebot",
        "office",
        (NodeSpec("through", THROUGH, "through.py"),),
        clock=Clock.LOCKSTEP,
        duration_s=20.0,
        spawn="start",
        builtin_nodes=NAV2,
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    words = line(list(run.slots["through"].logs), "result")
    assert words == ["result", "True", "remaining", "[2,", "1]"]
    pose = run.sim.state.pose
    assert math.hypot(pose.x - 3.0, pose.y - 2.2) <= 0.25
    topics = {t["name"]: t for t in result.graph["topics"]}
    assert topics["plan"]["messages"] == 1  # one path through both poses


GET_PATH = """
import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator


def pose(x, y):
    p = PoseStamped()
    p.header.frame_id = "map"
    p.pose.position.x, p.pose.position.y = x, y
    p.pose.orientation.w = 1.0
    return p


rclpy.init()
navigator = BasicNavigator()
navigator.waitUntilNav2Active()
path = navigator.getPath(pose(2.0, 1.3), pose(3.0, 2.2))
end = path.poses[-1].pose.position
print("path", len(path.poses), round(end.x, 2), round(end.y, 2))
print("wall", navigator.getPath(pose(2.0, 1.3), pose(0.5, 0.5)))
rclpy.shutdown()
"""


def test_get_path_plans_without_driving_and_says_none_for_a_wall(tmp_path, launcher):
    spec = RunSpec(
        "turtlebot",
        "office",
        (NodeSpec("planner", GET_PATH, "get_path.py"),),
        clock=Clock.LOCKSTEP,
        duration_s=5.0,
        spawn="start",
        builtin_nodes=NAV2,
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    lines = list(run.slots["planner"].logs)
    _, count, x, y = line(lines, "path")
    assert int(count) > 15 and (x, y) == ("3.0", "2.2")
    assert line(lines, "wall") == ["wall", "None"]
    assert run.sim.state.distance_travelled_m == 0.0  # planning only
    topics = {t["name"]: t for t in result.graph["topics"]}
    assert "plan" not in topics or topics["plan"]["messages"] == 0
