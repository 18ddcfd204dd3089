"""The generator's pure parts: action expansion, type spelling, and the table's source text."""

from __future__ import annotations

import pytest
from rosbags.typesys.base import Nodetype

from sandbox.msgs._generate import _constant_text, _type_text, expand_action, render


def test_an_action_expands_into_genactions_seven_messages() -> None:
    expanded = expand_action("tf2_msgs/LookupTransform", "string target_frame", "bool ok", "")
    assert expanded == {
        "tf2_msgs/LookupTransformAction": (
            "LookupTransformActionGoal action_goal\n"
            "LookupTransformActionResult action_result\n"
            "LookupTransformActionFeedback action_feedback"
        ),
        "tf2_msgs/LookupTransformActionGoal": (
            "Header header\nactionlib_msgs/GoalID goal_id\nLookupTransformGoal goal"
        ),
        "tf2_msgs/LookupTransformActionResult": (
            "Header header\nactionlib_msgs/GoalStatus status\nLookupTransformResult result"
        ),
        "tf2_msgs/LookupTransformActionFeedback": (
            "Header header\nactionlib_msgs/GoalStatus status\nLookupTransformFeedback feedback"
        ),
        "tf2_msgs/LookupTransformGoal": "string target_frame",
        "tf2_msgs/LookupTransformResult": "bool ok",
        "tf2_msgs/LookupTransformFeedback": "",
    }


def test_rosbags_types_are_spelt_as_ros1_writes_them() -> None:
    base = (Nodetype.BASE, ("float64", 0))
    assert _type_text(base) == "float64"
    assert _type_text((Nodetype.ARRAY, (base, 9))) == "float64[9]"
    assert _type_text((Nodetype.SEQUENCE, (base, 0))) == "float64[]"
    assert _type_text((Nodetype.NAME, "builtin_interfaces/msg/Time")) == "time"
    assert _type_text((Nodetype.NAME, "builtin_interfaces/msg/Duration")) == "duration"
    point = (Nodetype.NAME, "geometry_msgs/msg/Point")
    assert _type_text((Nodetype.SEQUENCE, (point, 0))) == "geometry_msgs/Point[]"


def test_what_ros1_cannot_spell_or_hash_exactly_is_refused() -> None:
    with pytest.raises(ValueError, match="bounded string"):
        _type_text((Nodetype.BASE, ("string", 10)))  # ROS 2's string<=10
    with pytest.raises(ValueError, match="add its text by hand"):
        _constant_text("float64", 0.1)  # md5 hashes the text as written: "0.1" or "1e-1"?
    assert _constant_text("int8", -1) == "-1"


def test_the_rendered_table_reads_back_as_the_same_texts() -> None:
    messages = {
        "a_msgs/Empty": "",
        "a_msgs/One": "int32 data",
        "a_msgs/Many": "uint8 A=1\nstring s\nfloat64[3] v",
        "a_msgs/Quoted": 'string Q="""\nint8 x',
        "a_msgs/Slash": "string S=a\\nb\nint8 y",
    }
    namespace: dict[str, object] = {}
    exec(render(messages, ("a_msgs/Srv",)), namespace)
    assert namespace["MESSAGES"] == messages
    assert namespace["SERVICES"] == ("a_msgs/Srv",)
