"""rclpy.action between two real nodes of one run: the tutorial Fibonacci server and client
(feedback in order, the result, the final status), cancelling (accepted by the server's
cancel_callback, refused by the default one), rejected goals, an execute callback that forgets
to set a terminal state, and the wire as rcl_action names it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from sandbox.protocol import Clock
from tests.ros2libs.runs import run_nodes

SERVER = """
import time
import rclpy
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.node import Node
from example_interfaces.action import Fibonacci


class Server(Node):
    def __init__(self):
        super().__init__("fibonacci_server")
        self._server = ActionServer(
            self, Fibonacci, "fibonacci", self.execute,
            goal_callback=self.on_goal, cancel_callback=self.on_cancel)

    def on_goal(self, goal):
        self.get_logger().info(f"goal request order={goal.order}")
        return GoalResponse.REJECT if goal.order > 20 else GoalResponse.ACCEPT

    def on_cancel(self, goal_handle):
        return CancelResponse.ACCEPT if ACCEPT_CANCEL else CancelResponse.REJECT

    def execute(self, goal_handle):
        feedback = Fibonacci.Feedback()
        feedback.sequence = [0, 1]
        for i in range(1, goal_handle.request.order):
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                self.get_logger().info("canceled")
                return Fibonacci.Result(sequence=feedback.sequence)
            feedback.sequence.append(feedback.sequence[i] + feedback.sequence[i - 1])
            goal_handle.publish_feedback(feedback)
            time.sleep(0.2)
        if FORGET_TO_SUCCEED:
            return Fibonacci.Result(sequence=feedback.sequence)
        goal_handle.succeed()
        return Fibonacci.Result(sequence=feedback.sequence)


rclpy.init()
rclpy.spin(Server())
"""

# A server that keeps its executor free while a goal runs (an async execute callback awaiting a
# Future a timer completes), so a single-threaded executor still takes cancel requests; a
# server that sleeps in its execute callback only sees them once the goal has ended, in ROS 2
# as here.
STEPPING_SERVER = """
import rclpy
from rclpy.action import ActionServer, CancelResponse
from rclpy.node import Node
from rclpy.task import Future
from example_interfaces.action import Fibonacci


class Server(Node):
    def __init__(self):
        super().__init__("fibonacci_server")
        self._server = ActionServer(
            self, Fibonacci, "fibonacci", self.execute, cancel_callback=self.on_cancel)
        self.goal = None
        self.create_timer(0.2, self.step)

    def on_cancel(self, goal_handle):
        return CancelResponse.ACCEPT if ACCEPT_CANCEL else CancelResponse.REJECT

    async def execute(self, goal_handle):
        self.goal, self.done, self.sequence = goal_handle, Future(), [0, 1]
        return await self.done

    def step(self):
        goal = self.goal
        if goal is None:
            return
        if goal.is_cancel_requested:
            goal.canceled()
            self.get_logger().info("canceled")
        elif len(self.sequence) > goal.request.order:
            goal.succeed()
        else:
            self.sequence.append(self.sequence[-1] + self.sequence[-2])
            goal.publish_feedback(Fibonacci.Feedback(sequence=self.sequence))
            return
        self.goal = None
        self.done.set_result(Fibonacci.Result(sequence=self.sequence))


rclpy.init()
rclpy.spin(Server())
"""

CLIENT = """
import rclpy
import rclpy.action
from rclpy.action import ActionClient
from rclpy.node import Node
from example_interfaces.action import Fibonacci


class Client(Node):
    def __init__(self):
        super().__init__("fibonacci_client")
        self.client = ActionClient(self, Fibonacci, "fibonacci")
        self.feedbacks = 0
        self.canceling = False

    def on_feedback(self, message):
        self.feedbacks += 1
        self.get_logger().info(f"feedback {list(message.feedback.sequence)}")
        handle = getattr(self, "goal_handle", None)  # feedback may come before the answer
        if CANCEL_AFTER and self.feedbacks >= CANCEL_AFTER and handle and not self.canceling:
            self.canceling = True
            self.get_logger().info("canceling")
            self.cancel_future = handle.cancel_goal_async()
            self.cancel_future.add_done_callback(self.on_cancel_response)

    def on_cancel_response(self, future):
        response = future.result()
        self.get_logger().info(
            f"cancel code={response.return_code} canceling={len(response.goals_canceling)}")


rclpy.init()
node = Client()
assert node.client.wait_for_server(timeout_sec=5.0)
node.get_logger().info(f"server ready={node.client.server_is_ready()}")
node.get_logger().info(f"actions {rclpy.action.get_action_names_and_types(node)}")
goal = Fibonacci.Goal(order=ORDER)
future = node.client.send_goal_async(goal, feedback_callback=node.on_feedback)
rclpy.spin_until_future_complete(node, future)
node.goal_handle = future.result()
node.get_logger().info(f"accepted={node.goal_handle.accepted}")
if node.goal_handle.accepted:
    result_future = node.goal_handle.get_result_async()
    rclpy.spin_until_future_complete(node, result_future)
    response = result_future.result()
    node.get_logger().info(
        f"result status={response.status} sequence={list(response.result.sequence)} "
        f"handle status={node.goal_handle.status}")
rclpy.shutdown()
"""


# ros2/examples' minimal_action_server: the execute callback sleeps, a MultiThreadedExecutor and a
# ReentrantCallbackGroup let the cancel request in meanwhile.
MULTI_THREADED_SERVER = (
    SERVER.replace(
        "rclpy.spin(Server())",
        "rclpy.spin(Server(), executor=MultiThreadedExecutor())",
    )
    .replace(
        "goal_callback=self.on_goal,",
        "goal_callback=self.on_goal, callback_group=ReentrantCallbackGroup(),",
    )
    .replace(
        "from rclpy.node import Node",
        "from rclpy.node import Node\n"
        "from rclpy.callback_groups import ReentrantCallbackGroup\n"
        "from rclpy.executors import MultiThreadedExecutor",
    )
)


def run_fibonacci(
    launcher,
    out_dir: Path,
    *,
    order: int = 6,
    cancel_after: int = 0,
    accept_cancel: bool = True,
    forget_to_succeed: bool = False,
    clock: Clock = Clock.LOCKSTEP,
    stepping: bool = False,
    multi_threaded: bool = False,
):
    base = STEPPING_SERVER if stepping else MULTI_THREADED_SERVER if multi_threaded else SERVER
    server = base.replace("ACCEPT_CANCEL", repr(accept_cancel)).replace(
        "FORGET_TO_SUCCEED", repr(forget_to_succeed)
    )
    client = CLIENT.replace("CANCEL_AFTER", repr(cancel_after)).replace("ORDER", repr(order))
    return run_nodes(
        launcher,
        out_dir,
        {"fibonacci_server": server, "fibonacci_client": client},
        duration_s=5.0,
        clock=clock,
    )


def feedback_lines(log: str) -> list[str]:
    return re.findall(r"feedback (\[[0-9, ]*\])", log)


@pytest.mark.slow
@pytest.mark.parametrize("clock", [Clock.LOCKSTEP, Clock.REALTIME])
def test_the_tutorial_goal_gets_its_feedback_in_order_and_its_result(
    launcher, tmp_path: Path, clock: Clock
) -> None:
    outcome = run_fibonacci(launcher, tmp_path, clock=clock)
    client = outcome.log("fibonacci_client")
    assert "server ready=True" in client and "accepted=True" in client, outcome.describe()
    sequence = [0, 1, 1, 2, 3, 5, 8]
    assert feedback_lines(client) == [str(sequence[:n]) for n in range(3, 8)]
    assert "result status=4 sequence=[0, 1, 1, 2, 3, 5, 8] handle status=4" in client
    assert "goal request order=6" in outcome.log("fibonacci_server")
    assert "actions [('/fibonacci', ['example_interfaces/action/Fibonacci'])]" in client


def test_a_cancel_the_server_accepts_ends_the_goal_canceled(launcher, tmp_path: Path) -> None:
    outcome = run_fibonacci(launcher, tmp_path, order=15, cancel_after=2, stepping=True)
    client = outcome.log("fibonacci_client")
    assert "cancel code=0 canceling=1" in client, outcome.describe()
    assert re.search(r"result status=5 sequence=\[0, 1, 1, 2(, 3)?\]", client), client
    assert "canceled" in outcome.log("fibonacci_server")
    assert len(feedback_lines(client)) <= 3


@pytest.mark.slow
def test_a_sleeping_execute_callback_takes_a_cancel_under_a_multi_threaded_executor(
    launcher, tmp_path: Path
) -> None:
    outcome = run_fibonacci(launcher, tmp_path, order=15, cancel_after=2, multi_threaded=True)
    client = outcome.log("fibonacci_client")
    assert "accepted=True" in client, outcome.describe()
    assert "cancel code=0 canceling=1" in client and "result status=5" in client


@pytest.mark.slow
def test_the_default_cancel_callback_refuses_and_the_goal_finishes(
    launcher, tmp_path: Path
) -> None:
    outcome = run_fibonacci(
        launcher, tmp_path, order=6, cancel_after=1, accept_cancel=False, stepping=True
    )
    client = outcome.log("fibonacci_client")
    assert "cancel code=1 canceling=0" in client, outcome.describe()
    assert "result status=4 sequence=[0, 1, 1, 2, 3, 5, 8]" in client


@pytest.mark.slow
def test_a_goal_the_server_rejects(launcher, tmp_path: Path) -> None:
    outcome = run_fibonacci(launcher, tmp_path, order=25)
    client = outcome.log("fibonacci_client")
    assert "accepted=False" in client and "result status" not in client, outcome.describe()


@pytest.mark.slow
def test_an_execute_callback_that_sets_no_state_aborts_with_rclpys_warning(
    launcher, tmp_path: Path
) -> None:
    outcome = run_fibonacci(launcher, tmp_path, order=3, forget_to_succeed=True)
    assert "Goal state not set, assuming aborted" in outcome.log("fibonacci_server")
    assert "result status=6 sequence=[0, 1, 1, 2]" in outcome.log("fibonacci_client")


def test_the_wire_is_rcl_actions(launcher, tmp_path: Path) -> None:
    outcome = run_fibonacci(launcher, tmp_path, order=3)
    for topic in ("fibonacci/_action/feedback", "fibonacci/_action/status"):
        assert topic in outcome.graph, sorted(outcome.graph)
        assert outcome.graph[topic]["publishers"] and outcome.graph[topic]["subscribers"]
    services = ("send_goal", "get_result", "cancel_goal")
    for name in services:
        assert f"__srv__/fibonacci/_action/{name}" in outcome.graph, sorted(outcome.graph)
    # One result request, sent when the goal was accepted and answered when it ended (as
    # rcl_action holds it), not asked again.
    requests = outcome.messages("__srv__/fibonacci/_action/get_result")
    replies = outcome.messages("__srv__reply/fibonacci_client")
    assert len(requests) == 1, requests
    feedbacks = outcome.messages("fibonacci/_action/feedback")
    assert replies[-1][0] >= feedbacks[-1][0] > requests[0][0]
