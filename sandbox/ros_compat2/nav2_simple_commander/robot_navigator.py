"""nav2_simple_commander.robot_navigator: BasicNavigator, the Python API of Nav2 (as Nav2 Jazzy's
nav2_simple_commander/robot_navigator.py), over the run's built-in navigation server.

    navigator = BasicNavigator()
    navigator.setInitialPose(initial_pose)
    navigator.waitUntilNav2Active()
    navigator.goToPose(goal_pose)
    while not navigator.isTaskComplete():
        feedback = navigator.getFeedback()
    if navigator.getResult() == TaskResult.SUCCEEDED: ...

A BasicNavigator is an rclpy Node with an ActionClient per Nav2 action: navigate_to_pose
(goToPose), navigate_through_poses (goThroughPoses), follow_waypoints (followWaypoints),
compute_path_to_pose / compute_path_through_poses (getPath / getPathThroughPoses). Each call
sends a goal, spins the node until the server accepts or rejects it, and keeps the result's
Future; isTaskComplete() spins up to 0.1 s for it, getFeedback() is the latest feedback,
getResult() the TaskResult of the finished task, cancelTask() cancels it. An action this run's
server does not offer makes its call wait for the server, as in Nav2, saying so once a second.

What differs from a Nav2 system: there are no lifecycle nodes in a RoboDojo run, so
waitUntilNav2Active() waits for the navigate_to_pose action server (the run's navigation node)
instead of bt_navigator's and amcl's lifecycle states, and does not wait for amcl_pose (the
run's localization knows the robot's pose from the start); lifecycleStartup() and
lifecycleShutdown() only log a line. The costmap, map, docking and behavior calls (spin,
backup, clearAllCostmaps, changeMap, ...) fail with a sentence: the run has no such servers.
"""

from __future__ import annotations

from enum import Enum
from typing import Any

import rclpy
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from sandbox.action_goals import GoalStatus
from sandbox.msgs import get_message_class

SERVER_WAIT_S = 1.0  # [s] between "server not available" lines, as Nav2's loop
COMPLETE_CHECK_S = 0.10  # [s] isTaskComplete() spins this long for the result, as Nav2

# The Nav2 actions this class is a client of: attribute -> (action name, interface).
_ACTIONS = {
    "nav_to_pose_client": ("navigate_to_pose", "nav2_msgs/action/NavigateToPose"),
    "nav_through_poses_client": (
        "navigate_through_poses",
        "nav2_msgs/action/NavigateThroughPoses",
    ),
    "follow_waypoints_client": ("follow_waypoints", "nav2_msgs/action/FollowWaypoints"),
    "compute_path_to_pose_client": (
        "compute_path_to_pose",
        "nav2_msgs/action/ComputePathToPose",
    ),
    "compute_path_through_poses_client": (
        "compute_path_through_poses",
        "nav2_msgs/action/ComputePathThroughPoses",
    ),
}

_NO_SERVER = (
    "a RoboDojo run has no {what}; navigate with goToPose, goThroughPoses or followWaypoints"
)
# BasicNavigator methods that need Nav2 servers a run does not have -> what is missing.
_NOT_PROVIDED = {
    "followGpsWaypoints": "GPS waypoint follower",
    "spin": "behavior server (spin)",
    "backup": "behavior server (backup)",
    "driveOnHeading": "behavior server (drive_on_heading)",
    "assistedTeleop": "behavior server (assisted_teleop)",
    "followPath": "controller server action (follow_path)",
    "dockRobotByPose": "docking server",
    "dockRobotByID": "docking server",
    "undockRobot": "docking server",
    "smoothPath": "smoother server",
    "changeMap": "map server load_map service (the map is the run's world)",
    "clearAllCostmaps": "costmaps",
    "clearLocalCostmap": "costmaps",
    "clearGlobalCostmap": "costmaps",
    "clearCostmapExceptRegion": "costmaps",
    "clearCostmapAroundRobot": "costmaps",
    "clearCostmapAroundPose": "costmaps",
    "getGlobalCostmap": "costmaps (the map is on the 'map' topic)",
    "getLocalCostmap": "costmaps",
}


class TaskResult(Enum):
    """How a navigation task ended."""

    UNKNOWN = 0
    SUCCEEDED = 1
    CANCELED = 2
    FAILED = 3


def _action_class(name: str) -> Any:
    from sandbox.msgs2 import get_action_class

    try:
        return get_action_class(name)
    except (KeyError, LookupError, ValueError):
        return None


class BasicNavigator(Node):
    """Nav2's Python commander: BasicNavigator(node_name='basic_navigator', namespace='')."""

    def __init__(self, node_name: str = "basic_navigator", namespace: str = "") -> None:
        super().__init__(node_name=node_name, namespace=namespace)
        pose_class = get_message_class("geometry_msgs/msg/PoseStamped")
        self.initial_pose = pose_class()
        self.initial_pose.header.frame_id = "map"
        self.goal_handle: Any = None
        self.result_future: Any = None
        self.feedback: Any = None
        self.status: Any = None
        self.initial_pose_received = False
        self._action_types: dict[str, Any] = {}
        for attribute, (action_name, interface) in _ACTIONS.items():
            action_type = _action_class(interface)
            self._action_types[attribute] = action_type
            client = None if action_type is None else ActionClient(self, action_type, action_name)
            setattr(self, attribute, client)
        amcl_pose_qos = QoSProfile(
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
            reliability=ReliabilityPolicy.RELIABLE,
            history=HistoryPolicy.KEEP_LAST,
            depth=1,
        )
        covariance_pose = get_message_class("geometry_msgs/msg/PoseWithCovarianceStamped")
        self.localization_pose_sub = self.create_subscription(
            covariance_pose, "amcl_pose", self._amclPoseCallback, amcl_pose_qos
        )
        self.initial_pose_pub = self.create_publisher(covariance_pose, "initialpose", 10)

    def __getattr__(self, name: str) -> Any:
        if name in _NOT_PROVIDED:
            raise AttributeError(
                f"BasicNavigator.{name}() is not available: "
                + _NO_SERVER.format(what=_NOT_PROVIDED[name])
            )
        raise AttributeError(f"'BasicNavigator' object has no attribute '{name}'")

    def destroyNode(self) -> None:
        self.destroy_node()

    def destroy_node(self) -> None:
        for attribute in _ACTIONS:
            client = getattr(self, attribute, None)
            if client is not None:
                client.destroy()
        super().destroy_node()

    # ------------------------------------------------------------------ starting
    def setInitialPose(self, initial_pose: Any) -> None:
        """Tell the localization where the robot is (published on initialpose)."""
        self.initial_pose_received = False
        self.initial_pose = initial_pose
        self._setInitialPose()

    def waitUntilNav2Active(self, navigator: str = "bt_navigator", localizer: str = "amcl") -> None:
        """Block until the run's navigation server takes goals. A RoboDojo run has no lifecycle
        nodes (no bt_navigator/get_state, no amcl): this waits for the navigate_to_pose action
        server instead, and not for amcl_pose."""
        self.debug(f"Waiting for {navigator} to become active..")
        client = self._client("nav_to_pose_client", "waitUntilNav2Active")
        while not client.wait_for_server(timeout_sec=SERVER_WAIT_S):
            self.info("'NavigateToPose' action server not available, waiting...")
        self.info("Nav2 is ready for use!")

    def lifecycleStartup(self) -> None:
        """Nothing to start: a RoboDojo run has no lifecycle nodes (its navigation is up)."""
        self.info("Starting up lifecycle nodes: none in a RoboDojo run, Nav2 is already up.")

    def lifecycleShutdown(self) -> None:
        """Nothing to shut down: a RoboDojo run has no lifecycle nodes."""
        self.info("Shutting down lifecycle nodes: none in a RoboDojo run, nothing to do.")

    # ------------------------------------------------------------------ tasks
    def _client(self, attribute: str, what: str) -> Any:
        client = getattr(self, attribute)
        if client is None:
            name, interface = _ACTIONS[attribute]
            raise RuntimeError(
                f"BasicNavigator.{what}() needs the {interface} action ('{name}'), whose "
                "messages RoboDojo does not provide; use goToPose or followWaypoints"
            )
        return client

    def _send(self, attribute: str, what: str, goal: Any, server_name: str) -> bool:
        client = self._client(attribute, what)
        self.debug(f"Waiting for '{server_name}' action server")
        while not client.wait_for_server(timeout_sec=SERVER_WAIT_S):
            self.info(f"'{server_name}' action server not available, waiting...")
        future = client.send_goal_async(goal, self._feedbackCallback)
        rclpy.spin_until_future_complete(self, future)
        self.goal_handle = future.result()
        if not self.goal_handle.accepted:
            return False
        self.result_future = self.goal_handle.get_result_async()
        return True

    def goToPose(self, pose: Any, behavior_tree: str = "") -> bool:
        """Send a NavigateToPose goal; whether the server accepted it."""
        self._client("nav_to_pose_client", "goToPose")
        goal_msg = self._action_types["nav_to_pose_client"].Goal()
        goal_msg.pose = pose
        goal_msg.behavior_tree = behavior_tree
        where = f"{pose.pose.position.x} {pose.pose.position.y}"
        self.info(f"Navigating to goal: {where}...")
        if not self._send("nav_to_pose_client", "goToPose", goal_msg, "NavigateToPose"):
            self.error(f"Goal to {where} was rejected!")
            return False
        return True

    def goThroughPoses(self, poses: Any, behavior_tree: str = "") -> bool:
        """Send a NavigateThroughPoses goal; whether the server accepted it."""
        self._client("nav_through_poses_client", "goThroughPoses")
        goal_msg = self._action_types["nav_through_poses_client"].Goal()
        goal_msg.poses = poses
        goal_msg.behavior_tree = behavior_tree
        self.info(f"Navigating with {len(goal_msg.poses)} goals....")
        if not self._send(
            "nav_through_poses_client", "goThroughPoses", goal_msg, "NavigateThroughPoses"
        ):
            self.error(f"Goal with {len(poses)} poses was rejected!")
            return False
        return True

    def followWaypoints(self, poses: Any) -> bool:
        """Send a FollowWaypoints goal (a list of PoseStamped); whether it was accepted."""
        self._client("follow_waypoints_client", "followWaypoints")
        goal_msg = self._action_types["follow_waypoints_client"].Goal()
        goal_msg.poses = poses
        self.info(f"Following {len(goal_msg.poses)} goals....")
        attribute = "follow_waypoints_client"
        if not self._send(attribute, "followWaypoints", goal_msg, "FollowWaypoints"):
            self.error(f"Following {len(poses)} waypoints request was rejected!")
            return False
        return True

    def cancelTask(self) -> None:
        """Cancel the running task."""
        self.info("Canceling current task.")
        if self.result_future:
            future = self.goal_handle.cancel_goal_async()
            rclpy.spin_until_future_complete(self, future)

    def isTaskComplete(self, task: Any = None) -> bool:
        """Whether the running task has ended (spins the node up to 0.1 s to find out)."""
        if not self.result_future:
            return True  # canceled or never started
        rclpy.spin_until_future_complete(self, self.result_future, timeout_sec=COMPLETE_CHECK_S)
        if not self.result_future.done():
            return False
        self.status = self.result_future.result().status
        if self.status != GoalStatus.SUCCEEDED:
            self.debug(f"Task with failed with status code: {self.status}")
            return True
        self.debug("Task succeeded!")
        return True

    def getFeedback(self, task: Any = None) -> Any:
        """The latest feedback of the running task (None before the first)."""
        return self.feedback

    def getResult(self) -> TaskResult:
        """How the finished task ended."""
        return {
            GoalStatus.SUCCEEDED: TaskResult.SUCCEEDED,
            GoalStatus.ABORTED: TaskResult.FAILED,
            GoalStatus.CANCELED: TaskResult.CANCELED,
        }.get(self.status, TaskResult.UNKNOWN)

    # ------------------------------------------------------------------ planning
    def _path(self, attribute: str, what: str, goal_msg: Any, server_name: str) -> Any:
        client = self._client(attribute, what)
        self.debug(f"Waiting for '{server_name}' action server")
        while not client.wait_for_server(timeout_sec=SERVER_WAIT_S):
            self.info(f"'{server_name}' action server not available, waiting...")
        self.info("Getting path...")
        future = client.send_goal_async(goal_msg)
        rclpy.spin_until_future_complete(self, future)
        self.goal_handle = future.result()
        if not self.goal_handle.accepted:
            self.error("Get path was rejected!")
            return None
        self.result_future = self.goal_handle.get_result_async()
        rclpy.spin_until_future_complete(self, self.result_future)
        self.status = self.result_future.result().status
        if self.status != GoalStatus.SUCCEEDED:
            self.warn(f"Getting path failed with status code: {self.status}")
            return None
        return self.result_future.result().result.path

    def getPath(self, start: Any, goal: Any, planner_id: str = "", use_start: bool = False) -> Any:
        """A nav_msgs/msg/Path from start (or the robot, use_start=False) to goal; None if
        planning failed."""
        self._client("compute_path_to_pose_client", "getPath")
        goal_msg = self._action_types["compute_path_to_pose_client"].Goal()
        goal_msg.start, goal_msg.goal = start, goal
        goal_msg.planner_id, goal_msg.use_start = planner_id, use_start
        return self._path("compute_path_to_pose_client", "getPath", goal_msg, "ComputePathToPose")

    def getPathThroughPoses(
        self, start: Any, goals: Any, planner_id: str = "", use_start: bool = False
    ) -> Any:
        """A nav_msgs/msg/Path through `goals`; None if planning failed."""
        attribute = "compute_path_through_poses_client"
        self._client(attribute, "getPathThroughPoses")
        goal_msg = self._action_types[attribute].Goal()
        goal_msg.start, goal_msg.goals = start, goals
        goal_msg.planner_id, goal_msg.use_start = planner_id, use_start
        return self._path(attribute, "getPathThroughPoses", goal_msg, "ComputePathThroughPoses")

    # ------------------------------------------------------------------ callbacks, logging
    def _amclPoseCallback(self, msg: Any) -> None:
        self.debug("Received amcl pose")
        self.initial_pose_received = True

    def _feedbackCallback(self, msg: Any) -> None:
        self.debug("Received action feedback message")
        self.feedback = msg.feedback

    def _setInitialPose(self) -> None:
        msg = get_message_class("geometry_msgs/msg/PoseWithCovarianceStamped")()
        msg.pose.pose = self.initial_pose.pose
        msg.header.frame_id = self.initial_pose.header.frame_id
        msg.header.stamp = self.initial_pose.header.stamp
        self.info("Publishing Initial Pose")
        self.initial_pose_pub.publish(msg)

    def info(self, msg: str) -> None:
        self.get_logger().info(msg)

    def warn(self, msg: str) -> None:
        self.get_logger().warning(msg)

    def error(self, msg: str) -> None:
        self.get_logger().error(msg)

    def debug(self, msg: str) -> None:
        self.get_logger().debug(msg)
