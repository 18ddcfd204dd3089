"""`roslib.message`: message and service classes by type name, as in ROS 1 noetic.

Follows roslib/genpy ``get_message_class``: ``'pkg/Name'`` gives the class, ``'Header'`` alone
means std_msgs/Header, ``'time'``/``'duration'`` the time types, a name without a package raises
ValueError, and a type that does not exist gives None (scripts test ``if cls is None``).
"""

from __future__ import annotations

from typing import Any

from sandbox.msgs import (
    DeserializationError,
    Duration,
    Message,
    SerializationError,
    Service,
    Time,
    UnknownMessageTypeError,
)
from sandbox.msgs import get_message_class as _get_message_class
from sandbox.msgs import get_service_class as _get_service_class


def _full_name(type_name: str) -> str:
    package, _, name = type_name.rpartition("/")
    if package:
        return type_name
    if name == "Header":
        return "std_msgs/Header"
    raise ValueError(f"message type is missing package name: {type_name}")


def get_message_class(message_type: str, reload_on_error: bool = False) -> Any:
    """The class of ``'pkg/Name'`` (or Time/Duration for 'time'/'duration'), None if unknown."""
    del reload_on_error  # all classes exist from the start; there is nothing to reload
    if message_type == "time":
        return Time
    if message_type == "duration":
        return Duration
    try:
        return _get_message_class(_full_name(message_type))
    except UnknownMessageTypeError:
        return None


def get_service_class(service_type: str, reload_on_error: bool = False) -> type[Service] | None:
    """The service class of ``'pkg/Name'``, None if there is no such service."""
    del reload_on_error
    try:
        return _get_service_class(_full_name(service_type))
    except UnknownMessageTypeError:
        return None


__all__ = [
    "DeserializationError",
    "Duration",
    "Message",
    "SerializationError",
    "Time",
    "get_message_class",
    "get_service_class",
]
