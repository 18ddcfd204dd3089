"""The nav2 built-in's rcl_action wire, spoken by hand: an rclpy node calls the action's
services (`navigate_to_pose/_action/send_goal`, `get_result`, `cancel_goal`) and listens to its
feedback and status topics, as rclpy.action's ActionClient does underneath."""

from __future__ import annotations

import pytest

from sandbox.protocol import Clock
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState

pytestmark = pytest.mark.slow  # a whole Nav2 action exchange through the sandbox

RAW = """
import rclpy
from rclpy.node import Node
from action_msgs.msg import GoalStatusArray
from action_msgs.srv import CancelGoal
from nav2_msgs.action import NavigateToPose
from unique_identifier_msgs.msg import UUID

ACTION = "navigate_to_pose/_action/"


def call(node, client, request):
    future = client.call_async(request)
    rclpy.spin_until_future_complete(node, future)
    return future.result()


def main():
    rclpy.init()
    node = Node("raw")
    impl = NavigateToPose.Impl
    send = node.create_client(impl.SendGoalService, ACTION + "send_goal")
    result = node.create_client(impl.GetResultService, ACTION + "get_result")
    cancel = node.create_client(CancelGoal, ACTION + "cancel_goal")
    feedback, statuses = [], []
    node.create_subscription(
        impl.FeedbackMessage, ACTION + "feedback", lambda m: feedback.append(m), 10
    )
    node.create_subscription(
        GoalStatusArray, ACTION + "status",
        lambda m: statuses.append([s.status for s in m.status_list]), 10,
    )
    print("ready", send.wait_for_service(timeout_sec=2.0))
    goal_id = UUID(uuid=list(range(16)))
    request = impl.SendGoalService.Request(goal_id=goal_id)
    request.goal.pose.header.frame_id = "map"
    request.goal.pose.pose.position.x = 3.0
    request.goal.pose.pose.position.y = 2.2
    request.goal.pose.pose.orientation.w = 1.0
    print("accepted", call(node, send, request).accepted)
    print("again", call(node, send, request).accepted)  # the same goal id twice: refused
    unknown = call(node, result, impl.GetResultService.Request(goal_id=UUID(uuid=[9] * 16)))
    print("unknown", unknown.status)
    done = call(node, result, impl.GetResultService.Request(goal_id=goal_id))
    print("status", done.status, "feedback", len(feedback),
          bytes(feedback[0].goal_id.uuid) == bytes(range(16)) if feedback else None)
    print("statuses", statuses[0], statuses[-1])
    late = CancelGoal.Request()
    late.goal_info.goal_id = goal_id
    answer = call(node, cancel, late)
    print("cancel", answer.return_code, len(answer.goals_canceling))
    rclpy.shutdown()


main()
"""


def test_the_action_wire_as_rcl_action_defines_it(tmp_path, launcher):
    spec = RunSpec(
        "turtlebot",
        "office",
        (NodeSpec("raw", RAW, "raw.py"),),
        clock=Clock.LOCKSTEP,
        duration_s=20.0,
        spawn="start",
        builtin_nodes=("map_server", "localization", "nav2"),
    )
    run = Run(spec, launcher, tmp_path / "run")
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    lines = {line.split()[0]: line.split()[1:] for line in run.slots["raw"].logs if line[:1] != "["}
    assert lines["ready"] == ["True"]
    assert lines["accepted"] == ["True"] and lines["again"] == ["False"]
    assert lines["unknown"] == ["0"]  # STATUS_UNKNOWN, answered at once
    status, _, count, ours = lines["status"]
    assert status == "4" and int(count) > 10 and ours == "True"  # SUCCEEDED, with feedback
    assert lines["statuses"] == ["[2]", "[4]"]  # EXECUTING, then SUCCEEDED
    assert lines["cancel"] == ["3", "0"]  # ERROR_GOAL_TERMINATED: it had ended
