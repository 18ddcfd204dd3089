"""Service classes: genpy's shape, and md5sums as real ROS 1 computes them."""

from __future__ import annotations

import pytest

from sandbox.msgs import (
    SERVICE_TYPES,
    Service,
    UnknownMessageTypeError,
    UnknownServiceTypeError,
    get_message_class,
    get_service_class,
    nav_msgs,
    std_srvs,
)

# md5sums of the services (and of their request and response) in a ROS 1 noetic installation,
# as published in generated code of public repositories (genpy, roslisp, rosserial, ROS#).
KNOWN_SERVICE_MD5 = {
    "std_srvs/Empty": "d41d8cd98f00b204e9800998ecf8427e",
    "std_srvs/Trigger": "937c9679a518e3a18d831e57125ea522",
    "std_srvs/SetBool": "09fb03525b03e7ea1fd3992bafd87e16",
    "nav_msgs/GetMap": "6cdd0a18e0aff5b0a3ca2326a89b54ff",
    "nav_msgs/GetPlan": "421c8ea4d21c6c9db7054b4bbdf1e024",
    "nav_msgs/SetMap": "c36922319011e63ed7784112ad4fdd32",
    "nav_msgs/LoadMap": "22e647fdfbe3b23c8c9f419908afaebd",
    "sensor_msgs/SetCameraInfo": "bef1df590ed75ed1f393692395e15482",
    "tf2_msgs/FrameGraph": "437ea58e9463815a0d511c7326b686b0",
}
KNOWN_PART_MD5 = {
    "std_srvs/SetBoolRequest": "8b94c1b53db61fb6aed406028ad6332a",
    "std_srvs/SetBoolResponse": "937c9679a518e3a18d831e57125ea522",
    "std_srvs/TriggerRequest": "d41d8cd98f00b204e9800998ecf8427e",
    "nav_msgs/GetPlanRequest": "e25a43e0752bcca599a8c2eef8282df8",
    "nav_msgs/GetPlanResponse": "0002bc113c0259d71f6cf8cbc9430e18",
}


def test_every_service_has_a_known_md5() -> None:
    assert sorted(KNOWN_SERVICE_MD5) == sorted(SERVICE_TYPES)


@pytest.mark.parametrize(("srv_type", "md5"), sorted(KNOWN_SERVICE_MD5.items()))
def test_service_md5_matches_ros(srv_type: str, md5: str) -> None:
    assert get_service_class(srv_type)._md5sum == md5


@pytest.mark.parametrize(("msg_type", "md5"), sorted(KNOWN_PART_MD5.items()))
def test_request_and_response_md5_match_ros(msg_type: str, md5: str) -> None:
    assert get_message_class(msg_type)._md5sum == md5


@pytest.mark.parametrize("srv_type", sorted(SERVICE_TYPES))
def test_service_class_has_genpys_shape(srv_type: str) -> None:
    package, name = srv_type.split("/")
    cls = get_service_class(srv_type)
    assert issubclass(cls, Service)
    assert (cls.__name__, cls._type, cls.__module__) == (name, srv_type, f"sandbox.msgs.{package}")
    assert cls._request_class is get_message_class(f"{srv_type}Request")
    assert cls._response_class is get_message_class(f"{srv_type}Response")
    assert cls._request_class._type == f"{srv_type}Request"
    # Reached by name in the package module too, the same objects.
    module = __import__(f"sandbox.msgs.{package}", fromlist=[name])
    assert getattr(module, name) is cls
    assert getattr(module, f"{name}Request") is cls._request_class


def test_request_and_response_are_ordinary_messages() -> None:
    request = std_srvs.SetBoolRequest(data=True)
    assert std_srvs.SetBoolRequest.deserialize(request.serialize()) == request
    response = std_srvs.SetBoolResponse(True, "motors on")
    assert response.serialize() == b"\x01\x09\x00\x00\x00motors on"
    assert nav_msgs.LoadMapResponse.RESULT_UNDEFINED_FAILURE == 255


def test_the_service_md5_is_not_either_parts_md5() -> None:
    # SetBool's md5 hashes both parts; a mix-up with a part's md5 would pass rosserial's check
    # for the wrong type.
    cls = std_srvs.SetBool
    assert cls._md5sum not in (cls._request_class._md5sum, cls._response_class._md5sum)


def test_unknown_service_is_a_sentence() -> None:
    with pytest.raises(UnknownServiceTypeError) as caught:
        get_service_class("std_srvs/SetBol")
    assert str(caught.value).startswith(
        "unknown service type 'std_srvs/SetBol' (did you mean std_srvs/SetBool?); known types "
        "are: std_srvs/Empty, std_srvs/SetBool, std_srvs/Trigger"
    )
    assert isinstance(caught.value, UnknownMessageTypeError)  # one except clause catches both


def test_a_message_is_not_a_service() -> None:
    with pytest.raises(UnknownServiceTypeError, match="is a message, not a service"):
        get_service_class("std_msgs/String")
