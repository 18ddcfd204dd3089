"""rclpy.action's ActionServer and ServerGoalHandle, built as rclpy/action/server.py builds
them over rcl_action: three services (`<action>/_action/send_goal`, `get_result`,
`cancel_goal`) and two publishers (`feedback`, `status`) on the node, so an ActionClient in
another node of the run (or the run's built-in Nav2 server's clients) speaks to it unchanged.
The goals' state machine and cancel policy are rcl_action's (sandbox/action_goals.py).

Behaviour as rclpy: a goal request goes to goal_callback (default: accept); an accepted goal
goes to handle_accepted_callback (default: goal_handle.execute()), which schedules the execute
callback as a task of the node's executor, so the client hears "accepted" first. The execute
callback returns the action's Result after calling goal_handle.succeed(), abort() or canceled()
(none of them: the goal is aborted, with rclpy's warning). It may sleep (time.sleep) and
publish feedback; while it runs, the node's other callbacks wait, as in a single-threaded
executor. A cancel request goes to cancel_callback (default: reject) for each goal it names.
Finished goals are kept result_timeout seconds (rclpy's default 10 s) for late result requests.
A get_result request for a goal still running is answered when the goal ends, as rcl_action
holds it: the service callback is a coroutine awaiting the goal's result (rclpy runs an async
service callback as a task and sends what it returns).
"""

from __future__ import annotations

import inspect
import traceback
from enum import Enum
from typing import Any

from rclpy.task import Future
from sandbox.action_goals import ActionGoals, CancelCode, Goal, GoalEvent, GoalStatus
from sandbox.msgs import get_message_class

from . import wire

RESULT_TIMEOUT_S = 10  # [s] rclpy's ActionServer(result_timeout=10): how long results are kept


def _qos(profile: Any) -> dict[str, Any]:
    """A service's qos_profile keyword, when one was given."""
    return {} if profile is None else {"qos_profile": profile}


class GoalResponse(Enum):
    """What a goal_callback returns."""

    REJECT = 1
    ACCEPT = 2


class CancelResponse(Enum):
    """What a cancel_callback returns."""

    REJECT = 1
    ACCEPT = 2


def default_handle_accepted_callback(goal_handle: ServerGoalHandle) -> None:
    """Execute the goal."""
    goal_handle.execute()


def default_goal_callback(goal_request: Any) -> GoalResponse:
    """Accept all goals."""
    return GoalResponse.ACCEPT


def default_cancel_callback(cancel_request: Any) -> CancelResponse:
    """No cancellations."""
    return CancelResponse.REJECT


class ServerGoalHandle:
    """One accepted goal, as the server's callbacks see it."""

    def __init__(self, action_server: ActionServer, goal: Goal, goal_id: Any, stamp: Any) -> None:
        self._action_server = action_server
        self._goal = goal
        self._goal_id = goal_id
        self._stamp = stamp
        self._destroyed = False
        self.ended_ns: int | None = None  # when it reached a terminal state (for expiry)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ServerGoalHandle) and self._goal.uuid == other._goal.uuid

    def __hash__(self) -> int:
        return hash(self._goal.uuid)

    @property
    def request(self) -> Any:
        """The goal the client sent (the action's Goal message)."""
        return self._goal.request

    @property
    def goal_id(self) -> Any:
        """The goal's unique_identifier_msgs/msg/UUID."""
        return self._goal_id

    @property
    def is_active(self) -> bool:
        return not self._destroyed and self._goal.status not in wire.TERMINAL

    @property
    def is_cancel_requested(self) -> bool:
        return self.status == GoalStatus.CANCELING

    @property
    def status(self) -> int:
        """action_msgs/msg/GoalStatus.STATUS_* of the goal."""
        return int(GoalStatus.UNKNOWN if self._destroyed else self._goal.status)

    def _update_state(self, event: GoalEvent) -> None:
        if self._destroyed:
            return
        self._goal.update(event)  # GoalTransitionError (a ValueError) names an illegal one
        self._action_server._publish_status()
        if self._goal.status in wire.TERMINAL:
            self.ended_ns = self._action_server._now_ns()

    def execute(self, execute_callback: Any = None) -> None:
        """Start executing the goal (what the default handle_accepted_callback does)."""
        if not self.is_cancel_requested:
            self._update_state(GoalEvent.EXECUTE)
        self._action_server._notify_execute(self, execute_callback)

    def publish_feedback(self, feedback: Any) -> None:
        """Send `feedback` (the action's Feedback message) to the client."""
        action_type = self._action_server.action_type
        if not isinstance(feedback, action_type.Feedback):
            raise TypeError(
                f"publish_feedback() takes a {action_type.__name__}.Feedback message, got "
                f"{type(feedback).__name__}"
            )
        if self._destroyed:
            return
        message = action_type.Impl.FeedbackMessage()
        message.goal_id = self._goal_id
        message.feedback = feedback
        self._action_server._feedback_publisher.publish(message)

    def succeed(self) -> None:
        self._update_state(GoalEvent.SUCCEED)

    def abort(self) -> None:
        self._update_state(GoalEvent.ABORT)

    def canceled(self) -> None:
        self._update_state(GoalEvent.CANCELED)

    def destroy(self) -> None:
        self._destroyed = True


class ActionServer:
    """ActionServer(node, action_type, action_name, execute_callback, *, goal_callback=...,
    handle_accepted_callback=..., cancel_callback=..., result_timeout=10)."""

    def __init__(
        self,
        node: Any,
        action_type: Any,
        action_name: str,
        execute_callback: Any,
        *,
        callback_group: Any = None,
        goal_callback: Any = default_goal_callback,
        handle_accepted_callback: Any = default_handle_accepted_callback,
        cancel_callback: Any = default_cancel_callback,
        goal_service_qos_profile: Any = None,
        result_service_qos_profile: Any = None,
        cancel_service_qos_profile: Any = None,
        feedback_pub_qos_profile: Any = None,
        status_pub_qos_profile: Any = None,
        result_timeout: float = RESULT_TIMEOUT_S,
    ) -> None:
        wire.check_action_type(action_type, "ActionServer(node, action_type, name, callback)")
        self.register_handle_accepted_callback(handle_accepted_callback)
        self.register_goal_callback(goal_callback)
        self.register_cancel_callback(cancel_callback)
        self.register_execute_callback(execute_callback)
        self._node = node
        self._action_type = action_type
        self._action_name = action_name
        self._result_timeout_ns = round(float(result_timeout) * 1e9)
        self._goals = ActionGoals()
        self._handles: dict[bytes, ServerGoalHandle] = {}
        self._results: dict[bytes, Any] = {}  # uuid -> GetResultService.Response, once ended
        self._waiting: dict[bytes, Future] = {}  # uuid -> the result a get_result awaits
        self._logger = wire.child_logger(node, "action_server")
        names = wire.names(action_name)
        impl = action_type.Impl
        group = callback_group  # rclpy puts the whole action server in one group
        self._services = [
            node.create_service(
                impl.SendGoalService,
                names["send_goal"],
                self._on_send_goal,
                callback_group=group,
                **_qos(goal_service_qos_profile),
            ),
            node.create_service(
                impl.GetResultService,
                names["get_result"],
                self._on_get_result,
                callback_group=group,
                **_qos(result_service_qos_profile),
            ),
            node.create_service(
                impl.CancelGoalService,
                names["cancel_goal"],
                self._on_cancel,
                callback_group=group,
                **_qos(cancel_service_qos_profile),
            ),
        ]
        self._feedback_publisher = node.create_publisher(
            impl.FeedbackMessage, names["feedback"], feedback_pub_qos_profile or wire.FEEDBACK_DEPTH
        )
        self._status_publisher = node.create_publisher(
            impl.GoalStatusMessage, names["status"], status_pub_qos_profile or wire.status_qos()
        )

    @property
    def action_type(self) -> Any:
        return self._action_type

    # ------------------------------------------------------------------ registration
    def register_handle_accepted_callback(self, handle_accepted_callback: Any) -> None:
        self._handle_accepted_callback = (
            handle_accepted_callback or default_handle_accepted_callback
        )

    def register_goal_callback(self, goal_callback: Any) -> None:
        self._goal_callback = goal_callback or default_goal_callback

    def register_cancel_callback(self, cancel_callback: Any) -> None:
        self._cancel_callback = cancel_callback or default_cancel_callback

    def register_execute_callback(self, execute_callback: Any) -> None:
        if not callable(execute_callback):
            raise TypeError(
                "Failed to register goal execution callback: not callable (ActionServer's "
                "fourth argument is the function that executes a goal: def execute_callback("
                "self, goal_handle): ... return result)"
            )
        self._execute_callback = execute_callback

    # ------------------------------------------------------------------ bookkeeping
    def _now_ns(self) -> int:
        return int(self._node.get_clock().now().nanoseconds)

    def _expire(self) -> None:
        """Forget goals that ended more than result_timeout ago (rcl_action's expiry)."""
        now = self._now_ns()
        for key, handle in list(self._handles.items()):
            if handle.ended_ns is not None and now - handle.ended_ns > self._result_timeout_ns:
                handle.destroy()
                del self._handles[key]
                self._goals.goals.pop(key, None)
                self._results.pop(key, None)

    def _publish_status(self) -> None:
        status_class = get_message_class("action_msgs/msg/GoalStatus")
        status_list = [
            status_class(
                goal_info=get_message_class("action_msgs/msg/GoalInfo")(
                    goal_id=handle.goal_id, stamp=handle._stamp
                ),
                status=handle.status,
            )
            for handle in self._handles.values()
        ]
        self._status_publisher.publish(
            self._action_type.Impl.GoalStatusMessage(status_list=status_list)
        )

    # ------------------------------------------------------------------ services
    def _on_send_goal(self, request: Any, response: Any) -> Any:
        self._expire()
        key = wire.uuid_bytes(request.goal_id)
        accepted = False
        if key not in self._handles:
            decision = wire.run_callback(self._goal_callback, request.goal)
            if not isinstance(decision, GoalResponse):
                self._logger.warning(
                    "Goal request callback did not return a GoalResponse type. Rejecting goal."
                )
            else:
                accepted = decision == GoalResponse.ACCEPT
        if not accepted:
            response.accepted = False
            return response
        now = self._node.get_clock().now()
        goal = self._goals.accept(key, int(now.nanoseconds), request.goal)
        handle = ServerGoalHandle(self, goal, request.goal_id, now.to_msg())
        self._handles[key] = handle
        response.accepted = True
        response.stamp = now.to_msg()
        self._publish_status()
        wire.run_callback(self._handle_accepted_callback, handle)
        return response

    async def _on_get_result(self, request: Any, response: Any) -> Any:
        self._expire()
        key = wire.uuid_bytes(request.goal_id)
        if key in self._results:
            return self._results[key]
        if key not in self._handles:
            self._logger.warning(
                f"Sending result response for unknown or expired goal ID: {list(bytearray(key))}"
            )
            response.status = int(GoalStatus.UNKNOWN)
            return response
        waiting = self._waiting.get(key)
        if waiting is None:
            waiting = self._waiting[key] = Future()
        return await waiting  # the goal's GetResult response, once its execute callback ends

    def _on_cancel(self, request: Any, response: Any) -> Any:
        self._expire()
        info = request.goal_info
        stamp_ns = int(info.stamp.sec) * 1_000_000_000 + int(info.stamp.nanosec)
        code, goals = self._goals.cancelable(wire.uuid_bytes(info.goal_id), stamp_ns)
        canceling = []
        for goal in goals:
            handle = self._handles[goal.uuid]
            decision = wire.run_callback(self._cancel_callback, handle)
            if decision == CancelResponse.ACCEPT and handle.is_active:
                handle._update_state(GoalEvent.CANCEL_GOAL)
                canceling.append(
                    get_message_class("action_msgs/msg/GoalInfo")(
                        goal_id=handle.goal_id, stamp=handle._stamp
                    )
                )
        if code == CancelCode.NONE and not canceling:
            code = CancelCode.REJECTED  # every goal it named was refused by cancel_callback
        response.return_code = int(code)
        response.goals_canceling = canceling
        return response

    # ------------------------------------------------------------------ execution
    def _notify_execute(self, handle: ServerGoalHandle, execute_callback: Any) -> None:
        callback = execute_callback or self._execute_callback
        executor = getattr(self._node, "executor", None)
        if executor is not None and hasattr(executor, "create_task"):
            executor.create_task(self._execute_goal, callback, handle)
        else:  # not spinning (execute() called outside a callback): run it now
            wire.run_callback(self._execute_goal, callback, handle)

    async def _execute_goal(self, execute_callback: Any, handle: ServerGoalHandle) -> None:
        result_class = self._action_type.Result
        try:
            result = execute_callback(handle)
            if inspect.isawaitable(result):  # an async execute callback
                result = await result
        except KeyboardInterrupt:  # the run ended the node mid-goal (sandbox.ros_errors)
            raise
        except Exception as error:
            result = result_class()
            self._logger.error(f"Error raised in execute callback: {error}")
            traceback.print_exc()
        if handle.is_active:
            self._logger.warning(
                "Goal state not set, assuming aborted. Goal ID: "
                f"{list(bytearray(handle._goal.uuid))}"
            )
            handle.abort()
        if not isinstance(result, result_class):
            name = self._action_type.__name__
            raise TypeError(
                f"the execute callback of action '{self._action_name}' must return a "
                f"{name}.Result message, it returned {result!r}; end it with "
                f"`result = {name}.Result(); ...; return result`"
            )
        response = self._action_type.Impl.GetResultService.Response()
        response.status = handle.status
        response.result = result
        self._results[handle._goal.uuid] = response
        self._goals.goals[handle._goal.uuid].result = result
        waiting = self._waiting.pop(handle._goal.uuid, None)
        if waiting is not None:
            waiting.set_result(response)

    def destroy(self) -> None:
        """Stop serving the action."""
        for handle in self._handles.values():
            handle.destroy()
        for service in self._services:
            self._node.destroy_service(service)
        self._node.destroy_publisher(self._feedback_publisher)
        self._node.destroy_publisher(self._status_publisher)
