"""What the editor knows about message types: fields, their ROS types and units, by dialect.

One view over both definitions (`sandbox.msgs` for ROS 1, `sandbox.msgs2` for ROS 2), read from
the classes those packages build, so the editor never holds a second copy of a message's
fields. Type names are kept in the ROS 1 spelling `pkg/Name` for both dialects (ROS 2's
`pkg/msg/Name` loses its `msg/`): a student's `Twist` is `geometry_msgs/Twist` either way.
"""

from __future__ import annotations

import keyword
from dataclasses import dataclass
from functools import cache

ROS1, ROS2 = 1, 2

# Units of fields a student meets in the lab's robots' topics, from the comments of the .msg
# files (ros/common_msgs and ros2/common_interfaces) and REP 103 (SI units, radians).
FIELD_UNITS: dict[tuple[str, str], str] = {
    ("geometry_msgs/Twist", "linear"): "m/s",
    ("geometry_msgs/Twist", "angular"): "rad/s",
    ("geometry_msgs/Accel", "linear"): "m/s^2",
    ("geometry_msgs/Accel", "angular"): "rad/s^2",
    ("geometry_msgs/Pose", "position"): "m",
    ("geometry_msgs/Pose", "orientation"): "unit quaternion",
    ("geometry_msgs/Pose2D", "x"): "m",
    ("geometry_msgs/Pose2D", "y"): "m",
    ("geometry_msgs/Pose2D", "theta"): "rad",
    ("geometry_msgs/Transform", "translation"): "m",
    ("geometry_msgs/Transform", "rotation"): "unit quaternion",
    ("sensor_msgs/LaserScan", "angle_min"): "rad",
    ("sensor_msgs/LaserScan", "angle_max"): "rad",
    ("sensor_msgs/LaserScan", "angle_increment"): "rad",
    ("sensor_msgs/LaserScan", "time_increment"): "s",
    ("sensor_msgs/LaserScan", "scan_time"): "s",
    ("sensor_msgs/LaserScan", "range_min"): "m",
    ("sensor_msgs/LaserScan", "range_max"): "m",
    ("sensor_msgs/LaserScan", "ranges"): "m; values outside [range_min, range_max] are no return",
    ("sensor_msgs/Range", "field_of_view"): "rad",
    ("sensor_msgs/Range", "min_range"): "m",
    ("sensor_msgs/Range", "max_range"): "m",
    ("sensor_msgs/Range", "range"): "m; inf when nothing is in range",
    ("sensor_msgs/Imu", "orientation"): "unit quaternion",
    ("sensor_msgs/Imu", "angular_velocity"): "rad/s",
    ("sensor_msgs/Imu", "linear_acceleration"): "m/s^2",
    ("sensor_msgs/BatteryState", "voltage"): "V",
    ("sensor_msgs/BatteryState", "current"): "A",
    ("sensor_msgs/BatteryState", "charge"): "Ah",
    ("sensor_msgs/BatteryState", "percentage"): "0..1",
    ("sensor_msgs/Temperature", "temperature"): "degrees Celsius",
    ("sensor_msgs/Illuminance", "illuminance"): "lux",
    ("nav_msgs/Odometry", "pose"): "position in m, orientation a unit quaternion",
    ("nav_msgs/Odometry", "twist"): "m/s and rad/s, in child_frame_id",
    ("nav_msgs/MapMetaData", "resolution"): "m/cell",
    ("std_msgs/Header", "stamp"): "time the data was measured",
}

_PYTHON_TYPES = {
    "bool": "bool",
    "boolean": "bool",
    "string": "str",
    "wstring": "str",
    "float32": "float",
    "float64": "float",
    "float": "float",
    "double": "float",
    "byte": "int",
    "char": "int",
    "octet": "bytes",
}


@dataclass(frozen=True, slots=True)
class FieldInfo:
    name: str
    ros_type: str  # as the .msg file writes it: "float32[]", "geometry_msgs/Vector3"
    message_type: str | None  # the element's message type, None for numbers, text, time
    is_array: bool
    python_type: str  # what the field holds in Python, for stubs and hover: "list[float]"

    def describe(self, owner: str) -> str:
        """`ranges: float32[] [m; ...]`: the field's ROS type and, where known, its unit."""
        unit = FIELD_UNITS.get((owner, self.name))
        return f"{self.name}: {self.ros_type}" + (f" [{unit}]" if unit else "")


@dataclass(frozen=True, slots=True)
class MessageInfo:
    type_name: str  # pkg/Name
    fields: tuple[FieldInfo, ...]
    constants: tuple[tuple[str, str, str], ...]  # (name, ros type, value text)
    attributes: frozenset[str]  # every public name an instance has: fields, methods, constants

    @property
    def short_name(self) -> str:
        return self.type_name.rsplit("/", 1)[1]

    def field(self, name: str) -> FieldInfo | None:
        return next((f for f in self.fields if f.name == name), None)

    def field_names(self) -> str:
        return ", ".join(f.name for f in self.fields) or "none"


def plain_type_name(type_name: str) -> str:
    """`pkg/Name` from `pkg/Name` or `pkg/msg/Name`."""
    parts = type_name.split("/")
    return f"{parts[0]}/{parts[-1]}" if len(parts) >= 2 else type_name


def _python_type(base: str, message_type: str | None, is_array: bool, dialect: int) -> str:
    if message_type is not None:
        package, name = message_type.split("/")
        element = f"{package}.msg.{name}"
    elif base in ("time", "duration"):
        element = base.capitalize()  # sandbox.msgs' Time / Duration, imported by the stub
    elif base in ("uint8", "char") and is_array and dialect == ROS1:
        return "bytes"  # genpy reads uint8[] as bytes
    else:
        element = _PYTHON_TYPES.get(base, "int")
    return f"list[{element}]" if is_array else element


def _from_class(cls: type, dialect: int) -> MessageInfo:
    fields = []
    for spec in cls._field_specs:
        if keyword.iskeyword(spec.name):
            continue
        nested = getattr(spec, "message_class", None)
        message_type = plain_type_name(nested._type) if nested is not None else None
        if dialect == ROS1:
            base, is_array = spec.base_type, spec.is_array
        else:
            base, is_array = spec.base, spec.container is not None
        python_type = _python_type(base, message_type, is_array, dialect)
        fields.append(FieldInfo(spec.name, spec.written_type, message_type, is_array, python_type))
    constants = tuple(
        (c.name, c.type, getattr(c, "value_text", None) or repr(c.value))
        for c in cls._constant_specs
    )
    attributes = frozenset(name for name in dir(cls) if not name.startswith("_"))
    names = {f.name for f in fields}
    return MessageInfo(
        plain_type_name(cls._type),
        tuple(fields),
        constants,
        attributes | names | {c[0] for c in constants},
    )


@cache
def message_info(dialect: int, type_name: str) -> MessageInfo | None:
    """The fields of `pkg/Name` (or `pkg/msg/Name`) in that dialect; None for an unknown type."""
    package, _, name = plain_type_name(type_name).partition("/")
    try:
        if dialect == ROS1:
            from sandbox.msgs import get_message_class

            cls = get_message_class(f"{package}/{name}")
        else:
            from sandbox.msgs2 import get_message_class as get_message_class2

            cls = get_message_class2(f"{package}/msg/{name}")
    except (KeyError, LookupError, ValueError, TypeError):
        return None
    return _from_class(cls, dialect)


def message_names(dialect: int, package: str) -> tuple[str, ...]:
    """Short names of the messages in `package`'s msg module in that dialect."""
    if dialect == ROS1:
        from sandbox.msgs import _catalog
    else:
        from sandbox.msgs2 import _catalog
    return tuple(_catalog.names(package, "msg"))


def packages(dialect: int) -> tuple[str, ...]:
    if dialect == ROS1:
        from sandbox.msgs import _catalog
    else:
        from sandbox.msgs2 import _catalog
    return tuple(_catalog.packages())
