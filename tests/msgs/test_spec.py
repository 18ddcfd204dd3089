"""Tests for sandbox.msgs._spec: parsing, genmsg md5sums and full text."""

import pytest

from sandbox.msgs import MESSAGE_TYPES, Message, geometry_msgs, nav_msgs, sensor_msgs, std_msgs
from sandbox.msgs._core import _REGISTRY
from sandbox.msgs._spec import parse_definition

# Real ROS1 md5sums, from a ROS Noetic installation (rosmsg md5).
KNOWN_MD5 = {
    "std_msgs/Int32": "da5909fbe378aeaf85e547e830cc1bb7",
    "std_msgs/Bool": "8b94c1b53db61fb6aed406028ad6332a",
    "geometry_msgs/Twist": "9f195f881246fdfa2798d1d3eebca84a",
    "std_msgs/Int32MultiArray": "1d99f79f8b325b44fee908053e9c945b",
    "std_msgs/Header": "2176decaecbce78abc3b96ef049fabed",
    "sensor_msgs/LaserScan": "90c7ef2dc6895d81024acba2ac42f369",
    "nav_msgs/Odometry": "cd5e73d190d741a2f92e81eda573aca7",
    "geometry_msgs/Pose": "e45d45a5a1ce597b249e23fb30fc871f",
    "std_msgs/String": "992ce8a1687cec8c8bd883ec73ca41d1",
    "std_msgs/Float32": "73fcbf46b49191e672908e50842a83d4",
    "std_msgs/Int16": "8524586e34fbd7cb1c08c5f5f1ca0e57",
    "sensor_msgs/Range": "c005c34273dc426c67a020a87bc24148",
    "sensor_msgs/Imu": "6a62c6daae103f4ff57a132d6f95cec2",
    "nav_msgs/OccupancyGrid": "3381f2d731d4076ec5c71b0759edbe4e",
    "nav_msgs/Path": "6227e2b7e9cce15051f669a5e197bbf7",
    "geometry_msgs/Vector3": "4a842b65f413084dc2b10fb484ea7f17",
    "std_msgs/Empty": "d41d8cd98f00b204e9800998ecf8427e",
    "geometry_msgs/Pose2D": "938fa65709584ad8e77d238529be13b8",
    "std_msgs/Time": "cd7166c74c552c311fbcc2fe5a7bc289",
}


@pytest.mark.parametrize(("msg_type", "md5"), sorted(KNOWN_MD5.items()))
def test_md5_matches_ros(msg_type: str, md5: str) -> None:
    assert MESSAGE_TYPES[msg_type]._md5sum == md5


def test_md5_ignores_comments_and_spacing() -> None:
    class Spaced(Message, register=False):
        _type = "test_msgs/Spaced"
        _definition = "  int32    data   # the value\n\n# trailing comment\n"

    assert Spaced._md5sum == std_msgs.Int32._md5sum


def test_constants_are_class_attributes_and_hashed_first() -> None:
    assert (sensor_msgs.Range.ULTRASOUND, sensor_msgs.Range.INFRARED) == (0, 1)
    assert "ULTRASOUND" not in sensor_msgs.Range.__slots__

    class Reordered(Message, register=False):
        _type = "sensor_msgs/Reordered"
        _definition = (
            sensor_msgs.Range._definition.replace("uint8 ULTRASOUND=0\nuint8 INFRARED=1\n", "")
            + "\nuint8 ULTRASOUND=0\nuint8 INFRARED=1"
        )

    assert Reordered._md5sum == sensor_msgs.Range._md5sum


def test_string_constant_keeps_hash_sign() -> None:
    class WithText(Message, register=False):
        _type = "test_msgs/WithText"
        _definition = "string GREETING=hi # there\nint32 x"

    assert WithText.GREETING == "hi # there"


def test_slots_follow_definition_order() -> None:
    assert sensor_msgs.LaserScan.__slots__ == (
        "header",
        "angle_min",
        "angle_max",
        "angle_increment",
        "time_increment",
        "scan_time",
        "range_min",
        "range_max",
        "ranges",
        "intensities",
    )
    assert sensor_msgs.Imu._slot_types[:3] == [
        "std_msgs/Header",
        "geometry_msgs/Quaternion",
        "float64[9]",
    ]
    assert nav_msgs.Path._slot_types == ["std_msgs/Header", "geometry_msgs/PoseStamped[]"]
    assert sensor_msgs.LaserScan._has_header and not geometry_msgs.Twist._has_header


def test_full_text_of_twist_lists_vector3_once() -> None:
    text = geometry_msgs.Twist._full_text
    assert text.startswith(geometry_msgs.Twist._definition + "\n" + "=" * 80 + "\n")
    assert text.count("MSG: geometry_msgs/Vector3\n") == 1
    assert text.endswith("float64 z")


def test_full_text_of_odometry_is_depth_first() -> None:
    names = [line[5:] for line in nav_msgs.Odometry._full_text.splitlines() if line[:5] == "MSG: "]
    assert names == [
        "std_msgs/Header",
        "geometry_msgs/PoseWithCovariance",
        "geometry_msgs/Pose",
        "geometry_msgs/Point",
        "geometry_msgs/Quaternion",
        "geometry_msgs/TwistWithCovariance",
        "geometry_msgs/Twist",
        "geometry_msgs/Vector3",
    ]


def _no_lookup(name: str) -> type:
    raise AssertionError(f"unexpected lookup of {name}")


def test_parser_reads_arrays_and_resolves_names() -> None:
    seen: list[str] = []

    def lookup(name: str) -> type:
        seen.append(name)
        return std_msgs.Header

    constants, fields = parse_definition(
        "pkg/Msg", "Header h\nThing t\nother/Kind[] k\nuint8[16] raw\nfloat32[] v", lookup
    )
    assert constants == []
    assert seen == ["std_msgs/Header", "pkg/Thing", "other/Kind"]
    assert [(f.is_array, f.array_len) for f in fields] == [
        (False, None),
        (False, None),
        (True, None),
        (True, 16),
        (True, None),
    ]


@pytest.mark.parametrize(
    ("definition", "complaint"),
    [
        ("int32", "want 'type name'"),
        ("int32 a b", "want 'type name'"),
        ("int32[x] a", "invalid field"),
        ("int32 9a", "invalid field"),
        ("int32 a\nint32 a", "declared twice"),
        ("uint8 BAD=x", "not a valid uint8"),
    ],
)
def test_parser_rejects_bad_definitions(definition: str, complaint: str) -> None:
    with pytest.raises(ValueError, match=complaint):
        parse_definition("pkg/Msg", definition, _no_lookup)


def test_unknown_nested_type_says_to_define_it_first() -> None:
    with pytest.raises(ValueError, match=r"define .* before"):

        class UsesMissing(Message, register=False):
            _type = "test_msgs/UsesMissing"
            _definition = "NotDefined thing"


def test_duplicate_type_is_rejected() -> None:
    class Once(Message):
        _type = "test_msgs/Once"
        _definition = "int32 data"

    try:
        with pytest.raises(TypeError, match=r"test_msgs/Once is already defined by tests\.msgs"):

            class Twice(Message):
                _type = "test_msgs/Once"
                _definition = "int32 data"

    finally:
        _REGISTRY.pop("test_msgs/Once")
