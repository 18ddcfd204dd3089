"""The rcl_action wire of one action served by a built-in node, over the run's service topics.

An rcl_action server is three services and two topics under `<action>/_action/`: `send_goal`,
`get_result`, `cancel_goal` (action_msgs/srv/CancelGoal), `feedback` (the action's
FeedbackMessage: goal id + feedback) and `status` (action_msgs/msg/GoalStatusArray). A service
between the nodes of a run is a pair of internal topics (sandbox/services.py): requests on
`__srv__/<service>`, each a robodojo_msgs/msg/ServiceCall carrying the request's CDR bytes and
the topic to answer on, answers as robodojo_msgs/msg/ServiceReply. This module turns those
envelopes into requests and answers back, and builds the feedback and status messages; what the
goals do is nav2_server.py's business, their states sandbox/action_goals.py's.

Sources (facts): rcl_action's names (`_action/send_goal` ...), action_msgs' interfaces,
rosidl's generated action types (`<Action>.Impl.SendGoalService` ...).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from sandbox.action_goals import ActionGoals, GoalStatus
from sandbox.msgs import get_message_class
from sandbox.services import REPLY_PREFIX, request_topic
from sandbox.units import NS_PER_S

SERVICE_CALL = "robodojo_msgs/msg/ServiceCall"
SERVICE_REPLY = "robodojo_msgs/msg/ServiceReply"
STATUS_TYPE = "action_msgs/msg/GoalStatusArray"


# Result error codes as Nav2 Jazzy's servers give them (bt_navigator passes on the code of the
# server that failed: the planner's 2xx, the controller's 1xx, its own 9xxx).
ERROR_CODES = {
    "NONE": 0,
    "PREEMPTED": 0,  # Nav2 aborts a preempted goal with an empty result
    "INVALID_CONTROLLER": 101,  # FollowPath
    "FAILED_TO_MAKE_PROGRESS": 105,
    "NO_VALID_CONTROL": 106,
    "PLANNER_TF_ERROR": 202,  # ComputePathToPose
    "GOAL_OUTSIDE_MAP": 204,
    "GOAL_OCCUPIED": 206,
    "NO_VALID_PATH": 208,
    "NO_VALID_WAYPOINTS": 602,  # FollowWaypoints
    "UNKNOWN": 9000,  # NavigateToPose
    "FAILED_TO_LOAD_BEHAVIOR_TREE": 9001,
    "TF_ERROR": 9002,
}


def with_error(result: Any, code_name: str, message: str) -> Any:
    """Fill a Jazzy result's error_code and error_msg (results before Jazzy have neither)."""
    fields = result.get_fields_and_field_types()
    if "error_msg" in fields:
        result.error_msg = message
    if "error_code" in fields:
        result.error_code = ERROR_CODES[code_name or "NONE"]
    return result


def time_msg(time_ns: int) -> Any:
    return get_message_class("builtin_interfaces/msg/Time")(
        sec=time_ns // NS_PER_S, nanosec=time_ns % NS_PER_S
    )


def duration_msg(seconds: float) -> Any:
    time_ns = max(round(seconds * NS_PER_S), 0)
    return get_message_class("builtin_interfaces/msg/Duration")(
        sec=time_ns // NS_PER_S, nanosec=time_ns % NS_PER_S
    )


def stamp_ns(stamp: Any) -> int:
    return int(stamp.sec) * NS_PER_S + int(stamp.nanosec)


def uuid_msg(uuid: bytes) -> Any:
    return get_message_class("unique_identifier_msgs/msg/UUID")(uuid=list(uuid))


def reply(call: Any, response: Any = None, error: str = "") -> tuple[str, Any]:
    """(topic, ServiceReply) answering `call` with `response`, or with an error sentence."""
    reply_class = get_message_class(SERVICE_REPLY)
    message = reply_class(id=call.id, ok=response is not None, error=error)
    if response is not None:
        message.response = response.serialize()
    return call.reply_to, message


@dataclass
class ServiceClient:
    """The calling end of one service, for a built-in node (the Stanley controller's)."""

    service: str
    service_class: Any
    node_name: str
    next_id: int = 1

    @property
    def reply_topic(self) -> str:
        return REPLY_PREFIX + self.node_name

    @property
    def topic(self) -> str:
        return request_topic(self.service)

    def call(self, request: Any) -> tuple[int, tuple[str, Any]]:
        call_id, self.next_id = self.next_id, self.next_id + 1
        message = get_message_class(SERVICE_CALL)(
            service=self.service,
            reply_to=self.reply_topic,
            id=call_id,
            request=request.serialize(),
        )
        return call_id, (self.topic, message)

    def response(self, reply_message: Any) -> Any:
        """The response a ServiceReply carries; ValueError with the server's sentence if none."""
        if not reply_message.ok:
            raise ValueError(reply_message.error)
        return self.service_class.Response.deserialize(bytes(reply_message.response))


class ActionWire:
    """Names, types and messages of one action server (`name` without a leading slash)."""

    def __init__(self, name: str, action_class: Any) -> None:
        self.name = name.strip("/")
        self.action = action_class
        impl = action_class.Impl
        self.send_goal = request_topic(f"{self.name}/_action/send_goal")
        self.get_result = request_topic(f"{self.name}/_action/get_result")
        self.cancel_goal = request_topic(f"{self.name}/_action/cancel_goal")
        self.feedback_topic = f"{self.name}/_action/feedback"
        self.status_topic = f"{self.name}/_action/status"
        self._services = {
            self.send_goal: impl.SendGoalService,
            self.get_result: impl.GetResultService,
            self.cancel_goal: impl.CancelGoalService,
        }
        self.goals = ActionGoals()

    @property
    def request_topics(self) -> tuple[str, ...]:
        return tuple(self._services)

    @property
    def published(self) -> tuple[tuple[str, str], ...]:
        return (
            (self.feedback_topic, self.action.Impl.FeedbackMessage._type),
            (self.status_topic, STATUS_TYPE),
        )

    def request(self, topic: str, call: Any) -> Any:
        """The request a ServiceCall on one of this action's request topics carries."""
        return self._services[topic].Request.deserialize(bytes(call.request))

    def goal_response(self, accepted: bool, time_ns: int) -> Any:
        return self.action.Impl.SendGoalService.Response(accepted=accepted, stamp=time_msg(time_ns))

    def result_response(self, status: GoalStatus, result: Any) -> Any:
        response = self.action.Impl.GetResultService.Response(status=int(status))
        if result is not None:
            response.result = result
        return response

    def cancel_response(self, code: int, canceling: list) -> Any:
        info = get_message_class("action_msgs/msg/GoalInfo")
        response = self.action.Impl.CancelGoalService.Response(return_code=int(code))
        response.goals_canceling = [
            info(goal_id=uuid_msg(g.uuid), stamp=time_msg(g.stamp_ns)) for g in canceling
        ]
        return response

    def feedback(self, uuid: bytes, feedback: Any) -> tuple[str, Any]:
        message = self.action.Impl.FeedbackMessage(goal_id=uuid_msg(uuid), feedback=feedback)
        return self.feedback_topic, message

    def status(self) -> tuple[str, Any]:
        info = get_message_class("action_msgs/msg/GoalInfo")
        status = get_message_class("action_msgs/msg/GoalStatus")
        array = get_message_class(STATUS_TYPE)()
        array.status_list = [
            status(goal_info=info(goal_id=uuid_msg(uuid), stamp=time_msg(ns)), status=int(state))
            for uuid, ns, state in self.goals.status_list()
        ]
        return self.status_topic, array
