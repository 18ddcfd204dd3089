"""nav2_simple_commander's BasicNavigator in a real node, against a NavigateToPose server
written as a course would write one (rclpy.action.ActionServer in another node of the run):
the initial pose reaches the localization topic, waitUntilNav2Active returns once the server is
there, goToPose / isTaskComplete / getFeedback / getResult follow a goal to success, and
cancelTask ends one as CANCELED."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from tests.ros2libs.runs import run_nodes

# The server keeps its executor free while a goal runs (an async execute callback awaiting a
# Future its timer completes), so cancel requests are taken mid-goal, as Nav2's servers do.
NAV_SERVER = """
import rclpy
from rclpy.action import ActionServer, CancelResponse
from rclpy.node import Node
from rclpy.task import Future
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav2_msgs.action import NavigateToPose


class FakeNav2(Node):
    def __init__(self):
        super().__init__("fake_nav2")
        self.create_subscription(PoseWithCovarianceStamped, "initialpose", self.on_initial, 10)
        self.server = ActionServer(self, NavigateToPose, "navigate_to_pose", self.execute,
                                   cancel_callback=lambda handle: CancelResponse.ACCEPT)
        self.goal = None
        self.create_timer(0.1, self.step)

    def on_initial(self, message):
        p = message.pose.pose.position
        self.get_logger().info(f"initial pose {p.x:.1f} {p.y:.1f} in {message.header.frame_id}")

    async def execute(self, goal_handle):
        target = goal_handle.request.pose.pose.position
        self.get_logger().info(f"navigating to {target.x:.1f} {target.y:.1f}")
        self.goal, self.steps, self.done = goal_handle, 0, Future()
        return await self.done

    def step(self):
        goal = self.goal
        if goal is None:
            return
        if goal.is_cancel_requested:
            goal.canceled()
        elif self.steps == 10:
            goal.succeed()
        else:
            feedback = NavigateToPose.Feedback()
            feedback.distance_remaining = 1.0 - 0.1 * self.steps
            goal.publish_feedback(feedback)
            self.steps += 1
            return
        self.goal = None
        self.done.set_result(NavigateToPose.Result())


rclpy.init()
rclpy.spin(FakeNav2())
"""

COMMANDER = """
import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult


def pose(x, y):
    p = PoseStamped()
    p.header.frame_id = "map"
    p.pose.position.x, p.pose.position.y = x, y
    p.pose.orientation.w = 1.0
    return p


rclpy.init()
navigator = BasicNavigator()
navigator.setInitialPose(pose(0.5, 0.0))
navigator.waitUntilNav2Active()
navigator.get_logger().info(f"accepted {navigator.goToPose(pose(2.0, 1.0))}")
remaining = []
while not navigator.isTaskComplete():
    feedback = navigator.getFeedback()
    value = None if feedback is None else round(feedback.distance_remaining, 1)
    if value is not None and (not remaining or remaining[-1] != value):
        remaining.append(value)
navigator.get_logger().info(f"first {navigator.getResult()} remaining {remaining}")
navigator.goToPose(pose(3.0, 0.0))
while not navigator.isTaskComplete():
    feedback = navigator.getFeedback()
    if feedback is not None and feedback.distance_remaining < 0.75:
        navigator.cancelTask()
navigator.get_logger().info(f"second {navigator.getResult()}")
navigator.lifecycleShutdown()
try:
    navigator.clearAllCostmaps()
except AttributeError as error:
    navigator.get_logger().info(f"costmaps: {error}")
rclpy.shutdown()
"""


@pytest.mark.slow
def test_a_goal_to_success_and_one_canceled(launcher, tmp_path: Path) -> None:
    outcome = run_nodes(
        launcher, tmp_path, {"fake_nav2": NAV_SERVER, "commander": COMMANDER}, duration_s=6.0
    )
    commander, server = outcome.log("commander"), outcome.log("fake_nav2")
    assert "initial pose 0.5 0.0 in map" in server, outcome.describe()
    assert "Nav2 is ready for use!" in commander
    assert "accepted True" in commander and "navigating to 2.0 1.0" in server
    match = re.search(r"first TaskResult.SUCCEEDED remaining \[([0-9., ]*)\]", commander)
    assert match, commander
    remaining = [float(value) for value in match.group(1).split(",")]
    # getFeedback() is the latest: isTaskComplete() spins 0.1 s, the fake server sends every 0.1 s
    assert remaining == sorted(remaining, reverse=True) and len(remaining) >= 5
    assert remaining[0] >= 0.9 and remaining[-1] <= 0.2
    assert "second TaskResult.CANCELED" in commander
    assert "costmaps: BasicNavigator.clearAllCostmaps() is not available" in commander


WAYPOINTS = """
import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult


def pose(x, y, z=0.0, w=1.0):
    p = PoseStamped()
    p.header.frame_id = "map"
    p.pose.position.x, p.pose.position.y = x, y
    p.pose.orientation.z, p.pose.orientation.w = z, w
    return p


rclpy.init()
navigator = BasicNavigator()
start = pose(2.0, 1.3, 0.7071068, 0.7071068)
navigator.setInitialPose(start)
navigator.waitUntilNav2Active()
path = navigator.getPath(start, pose(2.5, 2.0))
first, last = path.poses[0].pose.position, path.poses[-1].pose.position
ends = f"from {first.x:.2f} {first.y:.2f} to {last.x:.2f} {last.y:.2f}"
navigator.get_logger().info(f"path of {len(path.poses)} poses {ends}")
navigator.followWaypoints([pose(2.0, 1.7), pose(2.5, 2.0)])
reached = set()
while not navigator.isTaskComplete():
    feedback = navigator.getFeedback()
    if feedback is not None:
        reached.add(feedback.current_waypoint)
navigator.get_logger().info(f"waypoints {navigator.getResult()} feedback {sorted(reached)}")
navigator.goThroughPoses([pose(2.2, 1.6), pose(2.0, 1.4)])
remaining = set()
while not navigator.isTaskComplete():
    feedback = navigator.getFeedback()
    if feedback is not None:
        remaining.add(feedback.number_of_poses_remaining)
navigator.get_logger().info(f"through poses {navigator.getResult()} remaining {sorted(remaining)}")
rclpy.shutdown()
"""


@pytest.mark.slow
def test_waypoints_and_a_path_from_the_runs_navigation(launcher, tmp_path: Path) -> None:
    outcome = run_nodes(
        launcher,
        tmp_path,
        {"waypoints": WAYPOINTS},
        robot="turtlebot3",
        world="office",
        spawn="start",
        duration_s=45.0,
        builtin_nodes=("map_server", "localization", "nav2"),
    )
    log = outcome.log("waypoints")
    match = re.search(r"path of (\d+) poses from (\S+) (\S+) to (\S+) (\S+)", log)
    assert match, outcome.describe()
    count, x0, y0, x1, y1 = (float(value) for value in match.groups())
    assert count >= 2 and math.hypot(x1 - 2.5, y1 - 2.0) < 0.1
    assert math.hypot(x0 - 2.0, y0 - 1.3) < 0.3  # planned from where the robot is
    assert "waypoints TaskResult.SUCCEEDED feedback [0, 1]" in log
    through = re.search(r"through poses TaskResult.SUCCEEDED remaining \[([0-9, ]+)\]", log)
    assert through, log  # the feedback counted the poses still ahead
    assert {int(n) for n in through.group(1).split(",")} <= {0, 1, 2}
    assert math.hypot(outcome.end.x - 2.0, outcome.end.y - 1.4) < 0.25, outcome.end
