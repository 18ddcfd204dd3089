"""ROS 2 service and action classes in rosidl's shape (_srv.py.em, _action.py.em)."""

from __future__ import annotations

import random
from typing import Any

import pytest

from sandbox.msgs2 import (
    UnknownServiceTypeError,
    get_action_class,
    get_message_class,
    get_service_class,
)
from sandbox.msgs2._definitions import ACTIONS, SERVICES
from tests.msgs2.samples import random_message, to_rosbags, typestore_with


def test_a_service_holds_its_request_response_and_event() -> None:
    AddTwoInts = get_service_class("example_interfaces/srv/AddTwoInts")
    assert AddTwoInts.Request._type == "example_interfaces/srv/AddTwoInts_Request"
    assert AddTwoInts.Response._type == "example_interfaces/srv/AddTwoInts_Response"
    assert repr(AddTwoInts.Request(a=2, b=3)) == (
        "example_interfaces.srv.AddTwoInts_Request(a=2, b=3)"
    )
    assert AddTwoInts.Response(sum=5).serialize() == b"\x00\x01\x00\x00" + (5).to_bytes(8, "little")
    assert AddTwoInts.Event.get_fields_and_field_types() == {
        "info": "service_msgs/ServiceEventInfo",
        "request": "sequence<example_interfaces/AddTwoInts_Request, 1>",
        "response": "sequence<example_interfaces/AddTwoInts_Response, 1>",
    }
    with pytest.raises(NotImplementedError):
        AddTwoInts()
    assert get_service_class("example_interfaces/srv/AddTwoInts") is AddTwoInts


def test_an_empty_request_is_one_filler_byte() -> None:
    Empty = get_service_class("std_srvs/srv/Empty")
    assert Empty.Request().serialize() == b"\x00\x01\x00\x00\x00"
    assert Empty.Request.get_fields_and_field_types() == {}
    Trigger = get_service_class("std_srvs/srv/Trigger")
    response = Trigger.Response.deserialize(
        Trigger.Response(success=True, message="ok").serialize()
    )
    assert (response.success, response.message) == (True, "ok")


def test_an_action_holds_goal_result_feedback_and_the_rcl_action_types() -> None:
    Fibonacci = get_action_class("example_interfaces/action/Fibonacci")
    assert Fibonacci.Goal(order=10).order == 10
    assert Fibonacci.Result._type == "example_interfaces/action/Fibonacci_Result"
    assert list(Fibonacci.Feedback(sequence=[0, 1, 1]).sequence) == [0, 1, 1]
    impl = Fibonacci.Impl
    send = impl.SendGoalService
    assert send._type == "example_interfaces/action/Fibonacci_SendGoal"
    request = send.Request(goal=Fibonacci.Goal(order=3))
    assert request.goal_id.uuid.shape == (16,)
    assert set(send.Response.get_fields_and_field_types()) == {"accepted", "stamp"}
    assert set(impl.GetResultService.Response.get_fields_and_field_types()) == {"status", "result"}
    assert set(impl.FeedbackMessage.get_fields_and_field_types()) == {"goal_id", "feedback"}
    assert impl.CancelGoalService._type == "action_msgs/srv/CancelGoal"
    assert impl.CancelGoalService.Response.ERROR_UNKNOWN_GOAL_ID == 2
    assert impl.GoalStatusMessage._type == "action_msgs/msg/GoalStatusArray"
    tutorial = get_action_class("action_tutorials_interfaces/action/Fibonacci")
    assert "partial_sequence" in tutorial.Feedback.get_fields_and_field_types()
    with pytest.raises(NotImplementedError):
        Fibonacci()


def test_nav2_actions() -> None:
    NavigateToPose = get_action_class("nav2_msgs/action/NavigateToPose")
    goal = NavigateToPose.Goal()
    goal.pose.header.frame_id = "map"
    goal.pose.pose.position.x = 1.5
    back = NavigateToPose.Goal.deserialize(goal.serialize())
    assert back.pose.pose.position.x == 1.5 and back.pose.pose.orientation.w == 1.0
    assert NavigateToPose.Feedback().distance_remaining == 0.0
    FollowWaypoints = get_action_class("nav2_msgs/action/FollowWaypoints")
    assert FollowWaypoints.Result.TASK_EXECUTOR_FAILED == 601
    assert FollowWaypoints.Goal.GOAL_INDEX__DEFAULT == 0
    ComputePath = get_action_class("nav2_msgs/action/ComputePathToPose")
    assert ComputePath.Feedback.get_fields_and_field_types() == {}


ALL_SERVICE_MESSAGES = sorted(
    [f"{name}_{part}" for name in SERVICES for part in ("Request", "Response", "Event")]
    + [f"{name}_{part}" for name in ACTIONS for part in ("Goal", "Result", "Feedback")]
    + [f"{name}_{part}" for name in ACTIONS for part in ("SendGoal_Request", "FeedbackMessage")]
    + [f"{name}_GetResult_Response" for name in ACTIONS]
    + ["robodojo_msgs/msg/ServiceCall", "robodojo_msgs/msg/ServiceReply"]
    + ["nav2_msgs/msg/MissedWaypoint", "example_interfaces/msg/ByteMultiArray"]
)


@pytest.fixture(scope="module")
def typestore() -> Any:
    return typestore_with([get_message_class(name) for name in ALL_SERVICE_MESSAGES])


@pytest.mark.parametrize("msg_type", ALL_SERVICE_MESSAGES)
def test_service_and_action_messages_match_rosbags_cdr(msg_type: str, typestore: Any) -> None:
    cls = get_message_class(msg_type)
    for seed in range(5):
        message = random_message(cls, random.Random(seed))
        ours = message.serialize()
        assert ours == bytes(typestore.serialize_cdr(to_rosbags(message, typestore), msg_type))
        assert cls.deserialize(ours) == message


def test_unknown_names_get_sentences() -> None:
    with pytest.raises(UnknownServiceTypeError, match="did you mean std_srvs/srv/SetBool"):
        get_service_class("std_srvs/srv/SetBol")
    with pytest.raises(UnknownServiceTypeError, match="is a service, not an action"):
        get_action_class("example_interfaces/srv/AddTwoInts")
    with pytest.raises(KeyError, match=r"is a service, not a message.*SetBool_Request"):
        get_message_class("std_srvs/srv/SetBool")
