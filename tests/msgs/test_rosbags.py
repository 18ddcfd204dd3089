"""Our definitions, md5sums and wire bytes against rosbags' ROS 1 noetic type store.

rosbags is an independent implementation (its own parser, hashing and serializer), so agreeing
with it on every type checks both the generated table and our codegen. Types rosbags lacks
(tf2_msgs, the services) are registered into a private store from our definitions: that still
checks our hashing and wire format against rosbags' code; their md5sums against real ROS are in
test_services.py and test_spec.py.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from sandbox.msgs import MESSAGE_TYPES, Duration, Message, Time, get_message_class
from sandbox.msgs._definitions import MESSAGES
from sandbox.msgs._generate import (
    EXTRA_ACTIONS,
    EXTRA_MESSAGES,
    SERVICES,
    TARGET,
    expand_action,
    generated_source,
    rosbags_definitions,
)

from .samples import sample

_NUMPY_DTYPES = {
    "bool": np.bool_,
    "int8": np.int8,
    "byte": np.int8,
    "uint8": np.uint8,
    "char": np.uint8,
    "int16": np.int16,
    "uint16": np.uint16,
    "int32": np.int32,
    "uint32": np.uint32,
    "int64": np.int64,
    "uint64": np.uint64,
    "float32": np.float32,
    "float64": np.float64,
}


def _rosbags_name(msg_type: str) -> str:
    package, name = msg_type.split("/")
    return f"{package}/msg/{name}"


@pytest.fixture(scope="module")
def store():
    """The noetic store plus our definitions of the types it lacks."""
    typestore = get_typestore(Stores.ROS1_NOETIC)
    missing = {
        _rosbags_name(name): text
        for name, text in MESSAGES.items()
        if _rosbags_name(name) not in typestore.fielddefs
    }
    types: dict[str, Any] = {}
    for name, text in missing.items():
        types.update(get_types_from_msg(text, name))
    typestore.register(types)
    return typestore


def test_committed_table_is_what_the_generator_writes() -> None:
    assert TARGET.read_text() == generated_source(), (
        "sandbox/msgs/_definitions.py is stale: run python3 -m sandbox.msgs._generate"
    )


def test_table_holds_every_rosbags_type_and_every_extra() -> None:
    from_rosbags = rosbags_definitions()
    assert len(from_rosbags) > 100
    assert from_rosbags.items() <= MESSAGES.items()
    expected_extras = set(EXTRA_MESSAGES)
    for name, parts in EXTRA_ACTIONS.items():
        expected_extras |= set(expand_action(name, *parts))
    for name in SERVICES:
        expected_extras |= {f"{name}Request", f"{name}Response"}
    assert set(MESSAGES) == set(from_rosbags) | expected_extras


def test_time_types_are_ros1_primitives_not_builtin_interfaces() -> None:
    assert "builtin_interfaces" not in "".join(MESSAGES.values())
    assert MESSAGES["std_msgs/Header"].splitlines()[1] == "time stamp"
    assert "duration lifetime" in MESSAGES["visualization_msgs/Marker"].splitlines()


def test_definitions_carry_no_comments() -> None:
    assert not [name for name, text in MESSAGES.items() if "#" in text]


def test_action_expansion_reproduces_rosbags_get_map_messages(store) -> None:
    # rosbags holds the seven messages of nav_msgs/GetMap.action: expanding the .action text
    # ourselves (as tf2_msgs' LookupTransform is) must give the same md5sums.
    expanded = expand_action("nav_msgs/GetMap", "", "nav_msgs/OccupancyGrid map", "")
    assert len(expanded) == 7
    for name, text in expanded.items():

        class Expanded(Message, register=False):
            _type = name
            _definition = text

        _, md5 = store.generate_msgdef(_rosbags_name(name), ros_version=1)
        assert Expanded._md5sum == md5, name


@pytest.mark.parametrize("msg_type", sorted(MESSAGES))
def test_md5sum_matches_rosbags(store, msg_type: str) -> None:
    _, md5 = store.generate_msgdef(_rosbags_name(msg_type), ros_version=1)
    assert get_message_class(msg_type)._md5sum == md5


def to_rosbags(store, message: Message) -> Any:
    """The rosbags object equal to ``message`` (time -> builtin_interfaces, arrays -> numpy)."""
    cls = store.types[_rosbags_name(message._type)]
    values = {}
    for field in type(message)._field_specs:  # type: ignore[attr-defined]
        values[field.name] = _convert(store, field, getattr(message, field.name))
    return cls(**values)


def _convert(store, field: Any, value: Any) -> Any:
    if field.is_array:
        if field.kind in ("int", "float", "bool"):
            return np.array(list(value), dtype=_NUMPY_DTYPES[field.base_type])
        element = field.__class__(field.name, field.base_type, field.base_type, False, None,
                                  field.message_class)  # fmt: skip
        return [_convert(store, element, item) for item in value]
    if field.kind == "message":
        return to_rosbags(store, value)
    if isinstance(value, Time | Duration):
        name = "Time" if isinstance(value, Time) else "Duration"
        return store.types[f"builtin_interfaces/msg/{name}"](sec=value.secs, nanosec=value.nsecs)
    return value


@pytest.mark.parametrize("msg_type", sorted(MESSAGES))
def test_serialized_bytes_match_rosbags(store, msg_type: str) -> None:
    message = sample(msg_type)  # differs from the default (checked in test_serialization.py)
    ours = message.serialize()
    theirs = bytes(store.serialize_ros1(to_rosbags(store, message), _rosbags_name(msg_type)))
    assert ours == theirs
    assert MESSAGE_TYPES[msg_type].deserialize(theirs) == message
