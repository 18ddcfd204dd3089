"""One message with non-default values for every type, shared by the tests.

The types RoboDojo's own code uses have a sample written by hand (SAMPLES); every other type gets
one from ``filled``, which gives each field a value that differs from its default and from its
neighbours'. float32 fields use values exact in single precision so round trips compare equal.
"""

from collections.abc import Callable
from typing import Any

from sandbox.msgs import (
    MESSAGE_TYPES,
    Duration,
    Message,
    Time,
    geometry_msgs,
    nav_msgs,
    sensor_msgs,
    std_msgs,
    tf2_msgs,
)
from sandbox.msgs._spec import INT_RANGES, FieldSpec


def header(seq: int = 7) -> std_msgs.Header:
    return std_msgs.Header(seq=seq, stamp=Time(1_700_000_000, 123_456_789), frame_id="base_link")


def _pose(x: float) -> geometry_msgs.Pose:
    return geometry_msgs.Pose(
        geometry_msgs.Point(x, -2.5, 0.125), geometry_msgs.Quaternion(0.0, 0.0, 0.6, 0.8)
    )


def _twist() -> geometry_msgs.Twist:
    return geometry_msgs.Twist(geometry_msgs.Vector3(0.3, 0, 0), geometry_msgs.Vector3(0, 0, -1.25))


def _transform_stamped(child: str, x: float) -> geometry_msgs.TransformStamped:
    return geometry_msgs.TransformStamped(
        header(),
        child,
        geometry_msgs.Transform(
            geometry_msgs.Vector3(x, 0.5, 0.0), geometry_msgs.Quaternion(0.0, 0.0, 0.6, 0.8)
        ),
    )


def _layout() -> std_msgs.MultiArrayLayout:
    return std_msgs.MultiArrayLayout(
        dim=[
            std_msgs.MultiArrayDimension("rows", 2, 6),
            std_msgs.MultiArrayDimension("cölumns ✓", 3, 3),
        ],
        data_offset=1,
    )


SAMPLES: dict[str, Callable[[], Message]] = {
    "std_msgs/Header": header,
    "std_msgs/Bool": lambda: std_msgs.Bool(True),
    "std_msgs/Int16": lambda: std_msgs.Int16(-32768),
    "std_msgs/Int32": lambda: std_msgs.Int32(2_147_483_647),
    "std_msgs/Float32": lambda: std_msgs.Float32(0.5),
    "std_msgs/Float64": lambda: std_msgs.Float64(-1e300),
    "std_msgs/String": lambda: std_msgs.String("héllo, 世界 🤖"),
    "std_msgs/Empty": std_msgs.Empty,
    "std_msgs/Time": lambda: std_msgs.Time(Time(5, 6)),
    "std_msgs/Duration": lambda: std_msgs.Duration(Duration(-5, 6)),
    "std_msgs/ColorRGBA": lambda: std_msgs.ColorRGBA(1.0, 0.5, 0.25, 0.125),
    "std_msgs/MultiArrayDimension": lambda: std_msgs.MultiArrayDimension("x", 4, 4),
    "std_msgs/MultiArrayLayout": _layout,
    "std_msgs/Int32MultiArray": lambda: std_msgs.Int32MultiArray(_layout(), [1, -2, 3, 4, 5, 6]),
    "std_msgs/Float32MultiArray": lambda: std_msgs.Float32MultiArray(_layout(), [0.5, -0.25]),
    "geometry_msgs/Vector3": lambda: geometry_msgs.Vector3(1.5, -2.0, 3.25),
    "geometry_msgs/Point": lambda: geometry_msgs.Point(z=9.0),
    "geometry_msgs/Quaternion": lambda: geometry_msgs.Quaternion(w=1.0),
    "geometry_msgs/Pose": lambda: _pose(1.0),
    "geometry_msgs/Pose2D": lambda: geometry_msgs.Pose2D(1.0, 2.0, 3.0),
    "geometry_msgs/PoseStamped": lambda: geometry_msgs.PoseStamped(header(), _pose(2.0)),
    "geometry_msgs/PoseWithCovariance": lambda: geometry_msgs.PoseWithCovariance(
        _pose(3.0), [float(i) for i in range(36)]
    ),
    "geometry_msgs/Twist": _twist,
    "geometry_msgs/TwistWithCovariance": lambda: geometry_msgs.TwistWithCovariance(
        _twist(), [0.01 * i for i in range(36)]
    ),
    "geometry_msgs/Transform": lambda: geometry_msgs.Transform(
        geometry_msgs.Vector3(1.0, -2.0, 0.25), geometry_msgs.Quaternion(0.0, 0.0, 0.6, 0.8)
    ),
    "geometry_msgs/TransformStamped": lambda: _transform_stamped("laser", 0.125),
    "tf2_msgs/TFMessage": lambda: tf2_msgs.TFMessage(
        [_transform_stamped("base_link", 1.5), _transform_stamped("läser ✓", -0.25)]
    ),
    "sensor_msgs/LaserScan": lambda: sensor_msgs.LaserScan(
        header=header(),
        angle_min=-1.5,
        angle_max=1.5,
        angle_increment=0.25,
        time_increment=2.0**-10,
        scan_time=0.125,
        range_min=0.0625,
        range_max=8.0,
        ranges=[0.5, 1.0, float("inf"), 2.0],
        intensities=[10.0, 20.0, 0.0, 5.0],
    ),
    "sensor_msgs/Imu": lambda: sensor_msgs.Imu(
        header(),
        geometry_msgs.Quaternion(0, 0, 0, 1),
        [1.0] * 9,
        geometry_msgs.Vector3(0.1, 0.2, 0.3),
        [2.0] * 9,
        geometry_msgs.Vector3(0, 0, 9.81),
        [-1.0] + [0.0] * 8,
    ),
    "sensor_msgs/Range": lambda: sensor_msgs.Range(
        header(), sensor_msgs.Range.INFRARED, 0.5, 0.03125, 4.0, 1.25
    ),
    "nav_msgs/MapMetaData": lambda: nav_msgs.MapMetaData(Time(3, 4), 0.0625, 4, 2, _pose(-1.0)),
    "nav_msgs/OccupancyGrid": lambda: nav_msgs.OccupancyGrid(
        header(),
        nav_msgs.MapMetaData(Time(3, 4), 0.0625, 4, 2, _pose(-1.0)),
        [-1, 0, 100, 50, -1, 0, 127, -128],
    ),
    "nav_msgs/Odometry": lambda: nav_msgs.Odometry(
        header(),
        "base_footprint",
        geometry_msgs.PoseWithCovariance(_pose(4.0), [0.5] * 36),
        geometry_msgs.TwistWithCovariance(_twist(), [0.25] * 36),
    ),
    "nav_msgs/Path": lambda: nav_msgs.Path(
        header(), [geometry_msgs.PoseStamped(header(i), _pose(float(i))) for i in range(3)]
    ),
}


def _value(field: FieldSpec, seed: int) -> Any:
    """A non-default value of one element of ``field``; ``seed`` makes neighbours differ."""
    kind = field.kind
    if kind == "message":
        return filled(field.message_class, seed)
    if kind == "bool":
        return True
    if kind == "int":
        low, high = INT_RANGES[field.code]
        return low + seed % 7 if low < 0 else min(high, 200 + seed % 50)  # extremes of the range
    if kind == "float":
        return -1.25 - 0.5 * (seed % 64)  # exact in float32
    if kind == "string":
        return f"f{seed} ✓"  # non-ASCII: UTF-8 length differs from the character count
    if kind == "time":
        return Time(1_700_000_000 + seed, 999_999_999 - seed)
    return Duration(-3 - seed, 250_000_000)


def filled(cls: type[Message], seed: int = 1) -> Message:
    """An instance of ``cls`` whose every field (nested ones too) differs from the default;
    variable-length arrays hold two elements (uint8 arrays: bytes, as genpy decodes them)."""
    values = {}
    for index, field in enumerate(cls._field_specs):  # type: ignore[attr-defined]
        field_seed = seed * 31 + index
        if not field.is_array:
            values[field.name] = _value(field, field_seed)
            continue
        count = 2 if field.array_len is None else field.array_len
        items = [_value(field, field_seed + i) for i in range(count)]
        if field.kind == "int" and field.code == "B":
            items = bytes(items)
        values[field.name] = items
    return cls(**values)


def sample(msg_type: str) -> Message:
    """The hand-written sample of ``msg_type`` if there is one, else a filled instance."""
    make = SAMPLES.get(msg_type)
    return make() if make is not None else filled(MESSAGE_TYPES[msg_type])
