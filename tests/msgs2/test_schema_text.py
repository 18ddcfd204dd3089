"""``_full_text`` is rosbag2's ros2msg schema, and mcap_ros2 (an independent reader) decodes
our CDR with it."""

from __future__ import annotations

import io

import pytest
from mcap.reader import make_reader
from mcap.writer import Writer
from mcap_ros2.decoder import DecoderFactory

from sandbox.msgs2 import get_message_class

DELIMITER = "=" * 80


def test_the_format_is_rosbag2s() -> None:
    text = get_message_class("geometry_msgs/msg/TwistStamped")._full_text
    assert text == (
        "std_msgs/Header header\nTwist twist\n"
        f"\n{DELIMITER}\nMSG: geometry_msgs/Twist\nVector3 linear\nVector3 angular\n"
        f"\n{DELIMITER}\nMSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
        f"\n{DELIMITER}\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
        f"\n{DELIMITER}\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
    )


def test_each_dependency_is_written_once() -> None:
    text = get_message_class("visualization_msgs/msg/MarkerArray")._full_text
    names = [line for line in text.splitlines() if line.startswith("MSG: ")]
    assert len(names) == len(set(names))
    assert "MSG: std_msgs/Header" in names and "MSG: visualization_msgs/Marker" in names


def _decode_with_mcap_ros2(message: object) -> object:
    cls = type(message)
    buffer = io.BytesIO()
    writer = Writer(buffer)
    writer.start(profile="ros2", library="test")
    schema = writer.register_schema(cls._type, cls._schema_encoding, cls._full_text.encode())
    channel = writer.register_channel("/topic", cls._message_encoding, schema)
    writer.add_message(channel, log_time=1, publish_time=1, data=message.serialize())
    writer.finish()
    buffer.seek(0)
    reader = make_reader(buffer, decoder_factories=[DecoderFactory()])
    (_, _, _, decoded), *_ = reader.iter_decoded_messages()
    return decoded


@pytest.mark.parametrize(
    "msg_type",
    ["sensor_msgs/msg/LaserScan", "nav_msgs/msg/Odometry", "tf2_msgs/msg/TFMessage",
     "visualization_msgs/msg/MarkerArray", "std_msgs/msg/Empty", "nav_msgs/msg/OccupancyGrid",
     "rcl_interfaces/msg/ParameterDescriptor"],
)  # fmt: skip
def test_mcap_ros2_decodes_our_bytes_with_our_schema(msg_type: str) -> None:
    import random

    from tests.msgs2.samples import random_message

    message = random_message(get_message_class(msg_type), random.Random(3))
    decoded = _decode_with_mcap_ros2(message)
    for field in message._field_specs:
        if field.message_class is None and field.container is None:
            assert getattr(decoded, field.name) == getattr(message, field.name)


def test_mcap_ros2_reads_a_scan() -> None:
    LaserScan = get_message_class("sensor_msgs/msg/LaserScan")
    scan = LaserScan(ranges=[0.5, 1.0, 3.5], angle_increment=0.017453292)
    scan.header.frame_id = "base_scan"
    scan.header.stamp.sec = 12
    decoded = _decode_with_mcap_ros2(scan)
    assert decoded.header.frame_id == "base_scan" and decoded.header.stamp.sec == 12
    assert list(decoded.ranges) == [0.5, 1.0, 3.5]


def test_service_and_action_types_are_named_in_msg_syntax() -> None:
    from sandbox.msgs2 import get_action_class

    feedback = get_action_class("nav2_msgs/action/NavigateToPose").Impl.FeedbackMessage
    text = feedback._full_text
    assert text.startswith(
        "unique_identifier_msgs/UUID goal_id\nnav2_msgs/NavigateToPose_Feedback feedback\n"
    )
    assert f"\n{DELIMITER}\nMSG: nav2_msgs/NavigateToPose_Feedback\n" in text
    assert "/action/" not in text and "/msg/" not in text
