"""ROS 2 (Jazzy) message, service and action types: rosidl's Python shape, CDR on the wire.

The twin of ``sandbox.msgs`` (ROS 1) for ROS 2 runs. A class is built the first time it is
asked for, from the definition table ``_definitions.py``::

    from sandbox.msgs2 import get_message_class
    Twist = get_message_class("geometry_msgs/msg/Twist")
    data = Twist(linear=get_message_class("geometry_msgs/msg/Vector3")(x=0.2)).serialize()
    assert Twist.deserialize(data).linear.x == 0.2

``sandbox.msgs.get_message_class`` hands "pkg/msg/Name" to this package, so server code that
decodes envelopes works for both dialects.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

from sandbox.msgs._core import (
    DeserializationError,
    SerializationError,
    UnknownMessageTypeError,
)

from ._catalog import all_messages, unknown_type_sentence
from ._core import BUILD_LOCK, Message, build, registered
from ._services import (
    Action,
    Service,
    UnknownServiceTypeError,
    get_action_class,
    get_service_class,
)

__all__ = [
    "MESSAGE_TYPES",
    "Action",
    "DeserializationError",
    "Message",
    "SerializationError",
    "Service",
    "UnknownMessageTypeError",
    "UnknownServiceTypeError",
    "get_action_class",
    "get_message_class",
    "get_service_class",
]


def _text_of(msg_type: str) -> str:
    return all_messages()[msg_type]


def _lookup_nested(msg_type: str) -> type[Message]:
    if msg_type not in all_messages():
        raise ValueError(f"nested type {msg_type} is not defined")
    return get_message_class(msg_type)


def get_message_class(msg_type: str) -> type[Message]:
    """The class of ``"pkg/msg/Name"`` (also ``"pkg/srv/X_Request"``, ``"pkg/action/X_Goal"``).

    Raises UnknownMessageTypeError (a KeyError) with a sentence for anything else.
    """
    cls = registered(msg_type)
    if cls is not None:
        return cls
    definition = all_messages().get(msg_type)
    if definition is None:
        raise UnknownMessageTypeError(unknown_type_sentence(msg_type))
    with BUILD_LOCK:
        return build(msg_type, definition, _lookup_nested, _text_of)


class _MessageTypes(Mapping[str, "type[Message]"]):
    """Read-only view of every message type by name; a class is built when looked up."""

    def __getitem__(self, msg_type: str) -> type[Message]:
        return get_message_class(msg_type)

    def __contains__(self, msg_type: object) -> bool:
        return msg_type in all_messages()

    def __iter__(self) -> Iterator[str]:
        return iter(sorted(all_messages()))

    def __len__(self) -> int:
        return len(all_messages())


MESSAGE_TYPES: Mapping[str, type[Message]] = _MessageTypes()
