"""Tests for the registry: lookup by name and a validator run over every registered type."""

import pytest

from sandbox.msgs import (
    MESSAGE_TYPES,
    Message,
    UnknownMessageTypeError,
    get_message_class,
    std_msgs,
)
from sandbox.msgs._spec import parse_definition


def test_get_message_class_by_name() -> None:
    assert get_message_class("std_msgs/Int32") is std_msgs.Int32


def test_unknown_name_lists_valid_names() -> None:
    with pytest.raises(UnknownMessageTypeError) as caught:
        get_message_class("std_msgs/Int33")
    text = str(caught.value)
    assert text.startswith("unknown message type 'std_msgs/Int33'; known types are:")
    assert "std_msgs/Int32" in text and "geometry_msgs/Twist" in text
    assert isinstance(caught.value, KeyError)


def test_registry_cannot_be_modified_from_outside() -> None:
    with pytest.raises(TypeError):
        MESSAGE_TYPES["x/Y"] = std_msgs.Int32  # type: ignore[index]


def test_classes_without_register_stay_out_of_the_registry() -> None:
    class Private(Message, register=False):
        _type = "test_msgs/Private"
        _definition = "int8 x"

    assert "test_msgs/Private" not in MESSAGE_TYPES


@pytest.mark.parametrize("msg_type", sorted(MESSAGE_TYPES))
def test_every_registered_type_is_valid(msg_type: str) -> None:
    cls = MESSAGE_TYPES[msg_type]
    assert cls._type == msg_type
    assert cls.__name__ == msg_type.split("/")[1]
    assert len(cls._md5sum) == 32
    _, fields = parse_definition(msg_type, cls._definition, get_message_class)
    assert tuple(f.name for f in fields) == cls.__slots__
    assert cls._full_text.startswith(cls._definition)
    default = cls()
    data = default.serialize()
    assert len(data) == cls._min_size  # defaults have empty arrays and strings
    assert cls.deserialize(data) == default
