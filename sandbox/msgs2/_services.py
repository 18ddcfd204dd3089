"""ROS 2 service and action classes, shaped as rosidl_generator_py generates them.

ros2/rosidl_python, ``rosidl_generator_py/resource/_srv.py.em`` and ``_action.py.em``:

- a service class (``AddTwoInts``) holds its messages as ``Request``, ``Response`` and ``Event``
  (types ``example_interfaces/srv/AddTwoInts_Request`` ...) and cannot be instantiated;
- an action class (``Fibonacci``) holds ``Goal``, ``Result``, ``Feedback`` and an ``Impl`` class
  with the types rcl_action talks over: ``SendGoalService`` and ``GetResultService`` (services
  ``Fibonacci_SendGoal``, ``Fibonacci_GetResult``), ``FeedbackMessage``, and the generic
  ``CancelGoalService`` (action_msgs/srv/CancelGoal) and ``GoalStatusMessage``
  (action_msgs/msg/GoalStatusArray).
"""

from __future__ import annotations

from typing import Any, ClassVar

from sandbox.msgs._core import UnknownMessageTypeError

from ._catalog import ACTION, SRV, unknown_type_sentence
from ._core import BUILD_LOCK, rosidl_module
from ._definitions import ACTIONS, SERVICES


class UnknownServiceTypeError(UnknownMessageTypeError):
    """``get_service_class``/``get_action_class`` was given a name RoboDojo does not provide."""


class Service:
    """Base of every ROS 2 service class: ``Request``, ``Response``, ``Event``."""

    _type: ClassVar[str]
    Request: ClassVar[type]
    Response: ClassVar[type]
    Event: ClassVar[type]

    def __init__(self) -> None:
        raise NotImplementedError("Service classes can not be instantiated")


class Action:
    """Base of every ROS 2 action class: ``Goal``, ``Result``, ``Feedback`` and ``Impl``."""

    _type: ClassVar[str]
    Goal: ClassVar[type]
    Result: ClassVar[type]
    Feedback: ClassVar[type]
    Impl: ClassVar[type]

    def __init__(self) -> None:
        raise NotImplementedError("Action classes can not be instantiated")


_SERVICES: dict[str, type[Service]] = {}
_ACTIONS: dict[str, type[Action]] = {}


def _action_service(srv_type: str) -> bool:
    """``pkg/action/X_SendGoal`` or ``pkg/action/X_GetResult`` of a known action."""
    for suffix in ("_SendGoal", "_GetResult"):
        if srv_type.endswith(suffix) and srv_type[: -len(suffix)] in ACTIONS:
            return True
    return False


def get_service_class(srv_type: str) -> type[Service]:
    """The class of ``"pkg/srv/Name"``, e.g. ``get_service_class("std_srvs/srv/SetBool")``."""
    cls = _SERVICES.get(srv_type)
    if cls is not None:
        return cls
    if srv_type not in SERVICES and not _action_service(srv_type):
        raise UnknownServiceTypeError(unknown_type_sentence(srv_type, SRV))
    from . import get_message_class

    with BUILD_LOCK:
        cls = _SERVICES.get(srv_type)
        if cls is None:
            name = srv_type.rsplit("/", 1)[1]
            namespace: dict[str, Any] = {
                "__module__": rosidl_module(srv_type),
                "__qualname__": name,
                "__doc__": f"Service class '{name}' ({srv_type}).",
                "__slots__": (),
                "_type": srv_type,
                "Request": get_message_class(f"{srv_type}_Request"),
                "Response": get_message_class(f"{srv_type}_Response"),
                "Event": get_message_class(f"{srv_type}_Event"),
            }
            cls = _SERVICES[srv_type] = type(name, (Service,), namespace)
        return cls


def get_action_class(action_type: str) -> type[Action]:
    """The class of ``"pkg/action/Name"``, e.g. ``"example_interfaces/action/Fibonacci"``."""
    cls = _ACTIONS.get(action_type)
    if cls is not None:
        return cls
    if action_type not in ACTIONS:
        raise UnknownServiceTypeError(unknown_type_sentence(action_type, ACTION))
    from . import get_message_class

    with BUILD_LOCK:
        cls = _ACTIONS.get(action_type)
        if cls is None:
            name = action_type.rsplit("/", 1)[1]
            module = rosidl_module(action_type)
            impl = type(
                "Impl",
                (),
                {
                    "__module__": module,
                    "__qualname__": f"{name}.Impl",
                    "SendGoalService": get_service_class(f"{action_type}_SendGoal"),
                    "GetResultService": get_service_class(f"{action_type}_GetResult"),
                    "FeedbackMessage": get_message_class(f"{action_type}_FeedbackMessage"),
                    "CancelGoalService": get_service_class("action_msgs/srv/CancelGoal"),
                    "GoalStatusMessage": get_message_class("action_msgs/msg/GoalStatusArray"),
                },
            )
            namespace: dict[str, Any] = {
                "__module__": module,
                "__qualname__": name,
                "__doc__": f"Action class '{name}' ({action_type}).",
                "__slots__": (),
                "_type": action_type,
                "Goal": get_message_class(f"{action_type}_Goal"),
                "Result": get_message_class(f"{action_type}_Result"),
                "Feedback": get_message_class(f"{action_type}_Feedback"),
                "Impl": impl,
            }
            cls = _ACTIONS[action_type] = type(name, (Action,), namespace)
        return cls
