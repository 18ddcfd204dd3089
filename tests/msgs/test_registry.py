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


def test_unknown_name_suggests_close_matches_and_lists_the_package() -> None:
    with pytest.raises(UnknownMessageTypeError) as caught:
        get_message_class("std_msgs/Int33")
    text = str(caught.value)
    assert text.startswith("unknown message type 'std_msgs/Int33' (did you mean std_msgs/Int32")
    assert "known types are: std_msgs/Bool, std_msgs/Byte," in text
    assert "geometry_msgs" not in text  # only the package asked for: a short sentence
    assert isinstance(caught.value, KeyError)


def test_a_type_in_another_package_is_named() -> None:
    with pytest.raises(UnknownMessageTypeError, match=r"did you mean geometry_msgs/Twist\?"):
        get_message_class("std_msgs/Twist")


def test_unknown_package_lists_the_packages() -> None:
    with pytest.raises(UnknownMessageTypeError) as caught:
        get_message_class("move_base_msgs/MoveBaseGoal")
    assert str(caught.value) == (
        "unknown message type 'move_base_msgs/MoveBaseGoal': RoboDojo has no package "
        "'move_base_msgs'; known types are those of actionlib_msgs, geometry_msgs, nav_msgs, "
        "sensor_msgs, std_msgs, std_srvs, tf2_msgs, visualization_msgs"
    )


@pytest.mark.parametrize("name", ["Int32", "std_msgs/Int32/x", "", "std_msgs.Int32"])
def test_a_name_without_one_slash_says_how_to_write_it(name: str) -> None:
    with pytest.raises(UnknownMessageTypeError, match="must be written 'package/Name'"):
        get_message_class(name)


def test_a_service_is_not_a_message_type() -> None:
    with pytest.raises(UnknownMessageTypeError) as caught:
        get_message_class("std_srvs/SetBool")
    assert str(caught.value) == (
        "std_srvs/SetBool is a service, not a message: its messages are std_srvs/SetBoolRequest "
        "and std_srvs/SetBoolResponse, and get_service_class('std_srvs/SetBool') gives the service"
    )
    # ... but its request and response are (genpy gives them their own md5sums)
    assert get_message_class("std_srvs/SetBoolRequest")._type == "std_srvs/SetBoolRequest"


def test_registry_cannot_be_modified_from_outside() -> None:
    with pytest.raises(TypeError):
        MESSAGE_TYPES["x/Y"] = std_msgs.Int32  # type: ignore[index]


@pytest.mark.parametrize("built_first", [False, True])
def test_a_provided_type_cannot_be_defined_again(built_first: bool) -> None:
    if built_first:
        get_message_class("std_msgs/Int64")
    with pytest.raises(TypeError, match="a ROS type RoboDojo provides: use get_message_class"):

        class Int64(Message):
            _type = "std_msgs/Int64"
            _definition = "int32 data"  # a different definition would shadow the real one

    assert get_message_class("std_msgs/Int64")._md5sum == "34add168574510e6e17f5d23ecc077ef"


def test_registry_lists_every_type_and_knows_membership() -> None:
    assert len(MESSAGE_TYPES) == len(list(MESSAGE_TYPES)) >= 140
    assert "visualization_msgs/Marker" in MESSAGE_TYPES
    assert "std_msgs/Int33" not in MESSAGE_TYPES
    assert MESSAGE_TYPES.get("std_msgs/Int33") is None


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
