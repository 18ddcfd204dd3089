"""ROS 1 message objects <-> ROS 2 message objects, at the robot's edge of a ROS 2 run.

The simulator, sensors and built-in nodes keep their ROS 1 classes; a ROS 2 run converts what
leaves them and what comes back. Fields map by name, as ros1_bridge's automatic mapping does
(ros2/ros1_bridge, ``doc/index.rst``, "How are ROS 1 and 2 messages associated with each
other?"; a ROS 1 field differing from its ROS 2 twin only in case, like CameraInfo's ``D`` and
``d``, maps too), with ROS 2's changes made explicit:

- ``std_msgs/Header``: ROS 2 has no ``seq`` (REP 2000's "Changes between ROS 1 and ROS 2"
  message notes); it is dropped going to ROS 2 and 0 coming back.
- ROS 1 ``time``/``duration`` primitives <-> ``builtin_interfaces/Time``/``Duration``
  (``sec`` int32 and ``nanosec`` uint32 in [0, 1e9)).
- A ROS 2 field ROS 1 lacks (``Marker.texture``, ``Range.variance``) gets its default going to
  ROS 2 and is left out coming back.
- ``to_ros1(TwistStamped, "geometry_msgs/Twist")`` takes the twist: ROS 2 Jazzy's TurtleBot3
  sends TwistStamped where the ROS 1 robot reads Twist.

Anything else that does not map (a type with no twin, a ROS 1 field ROS 2 lacks) raises
``BridgeError`` with a sentence. Converters are planned once per pair of classes; the objects
are built without the setters' checks (the values come from typed messages).
"""

from __future__ import annotations

import threading
from array import array
from collections.abc import Callable, Iterable
from typing import Any

from sandbox.msgs import Duration as Ros1Duration
from sandbox.msgs import Time as Ros1Time
from sandbox.msgs import get_message_class as get_ros1_message_class
from sandbox.msgs._definitions import SERVICES as ROS1_SERVICES
from sandbox.units import NS_PER_S

from . import get_message_class
from ._fields import CHECK_FIELDS
from ._spec import NUMPY_DTYPES, FieldSpec

_TIME = "builtin_interfaces/msg/Time"
_DURATION = "builtin_interfaces/msg/Duration"
_DROPPED_GOING_TO_ROS2 = {("std_msgs/Header", "seq")}  # ROS 1 fields ROS 2 removed on purpose


class BridgeError(TypeError):
    """A ROS 1 type or field has no ROS 2 counterpart (or the other way round)."""


def ros2_name(ros1_type: str) -> str:
    """``"std_msgs/Int32"`` -> ``"std_msgs/msg/Int32"``; service parts go to ``srv``."""
    package, _, name = ros1_type.partition("/")
    if not name or "/" in name:
        raise BridgeError(f"{ros1_type!r} is not a ROS 1 type name ('package/Name')")
    for suffix in ("Request", "Response"):
        service = f"{package}/{name[: -len(suffix)]}"
        if name.endswith(suffix) and service in ROS1_SERVICES:
            return f"{package}/srv/{name[: -len(suffix)]}_{suffix}"
    if ros1_type in ROS1_SERVICES:
        return f"{package}/srv/{name}"
    return f"{package}/msg/{name}"


def build_both_dialects(ros1_types: Iterable[str]) -> None:
    """Build the class of each ROS 1 type and of its ROS 2 twin now (a class is generated at
    its first use: 0.3 ms for std_msgs/Int32, 13 ms for sensor_msgs/LaserScan); an unknown
    name raises the message types' own sentence."""
    for name in ros1_types:
        get_ros1_message_class(name)
        get_message_class(ros2_name(name))


def ros1_name(ros2_type: str) -> str:
    """``"std_msgs/msg/Int32"`` -> ``"std_msgs/Int32"``; ``p/srv/X_Request`` -> ``p/XRequest``."""
    parts = ros2_type.split("/")
    if len(parts) != 3:
        raise BridgeError(f"{ros2_type!r} is not a ROS 2 type name ('package/msg/Name')")
    package, kind, name = parts
    if kind == "srv":
        for suffix in ("Request", "Response"):
            if name.endswith("_" + suffix):
                return f"{package}/{name[: -len(suffix) - 1]}{suffix}"
    return f"{package}/{name}"


def to_ros2(ros1_message: Any) -> Any:
    """The ROS 2 twin of a ROS 1 message object (``sandbox.msgs`` class)."""
    return _converter(type(ros1_message), None, to_ros2=True)(ros1_message)


def to_ros1(ros2_message: Any, ros1_type: str | None = None) -> Any:
    """The ROS 1 message of ``ros1_type`` (default: the twin of the ROS 2 type)."""
    return _converter(type(ros2_message), ros1_type, to_ros2=False)(ros2_message)


_CONVERTERS: dict[tuple[type, str | None, bool], Callable[[Any], Any]] = {}
_LOCK = threading.RLock()


def _converter(source: type, target_name: str | None, to_ros2: bool) -> Callable[[Any], Any]:
    key = (source, target_name, to_ros2)
    converter = _CONVERTERS.get(key)
    if converter is None:
        with _LOCK:
            converter = _CONVERTERS.get(key) or _plan(source, target_name, to_ros2)
            _CONVERTERS[key] = converter
    return converter


def _lookup(name: str, to_ros2: bool, source_type: str) -> type:
    try:
        return get_message_class(name) if to_ros2 else get_ros1_message_class(name)
    except KeyError:
        side = "ROS 2" if to_ros2 else "ROS 1"
        raise BridgeError(
            f"{source_type} has no {side} counterpart ({name} does not exist), so it cannot "
            "cross between a ROS 1 robot and ROS 2 nodes"
        ) from None


def _plan(source: type, target_name: str | None, to_ros2: bool) -> Callable[[Any], Any]:
    source_type = source._type  # type: ignore[attr-defined]
    if not hasattr(source, "_field_specs"):
        raise BridgeError(f"{source!r} is not a message class")
    if to_ros2:
        target = _lookup(ros2_name(source_type), True, source_type)
        return _plan_to_ros2(source, target)
    wanted = target_name or ros1_name(source_type)
    if wanted != ros1_name(source_type):
        if source_type == "geometry_msgs/msg/TwistStamped" and wanted == "geometry_msgs/Twist":
            inner = _converter(get_message_class("geometry_msgs/msg/Twist"), None, False)
            return lambda message: inner(message.twist)
        raise BridgeError(
            f"a {source_type} cannot become a ROS 1 {wanted}: only its twin "
            f"{ros1_name(source_type)} (or geometry_msgs/Twist from a TwistStamped)"
        )
    return _plan_to_ros1(source, _lookup(wanted, False, source_type))


def _match(name: str, names: dict[str, Any]) -> Any:
    if name in names:
        return names[name]
    lowered = {other.lower(): spec for other, spec in names.items()}
    return lowered.get(name.lower())


def _plan_to_ros2(source: type, target: type) -> Callable[[Any], Any]:
    ros1_fields = {f.name: f for f in source._field_specs}  # type: ignore[attr-defined]
    ros2_fields = {f.name: f for f in target._field_specs}  # type: ignore[attr-defined]
    for name in ros1_fields:
        if _match(name, ros2_fields) is None and (source._type, name) not in _DROPPED_GOING_TO_ROS2:  # type: ignore[attr-defined]
            raise BridgeError(
                f"{source._type}.{name} has no field in {target._type}: the types differ "  # type: ignore[attr-defined]
                "between ROS 1 and ROS 2"
            )
    steps = []
    defaults = []
    slot_setters = {name: target.__dict__[slot].__set__ for name, slot in target._slot_of.items()}  # type: ignore[attr-defined]
    for name, field in ros2_fields.items():
        ros1_field = _match(name, ros1_fields)
        store = slot_setters[name]
        if ros1_field is None:
            defaults.append((store, _default_of(target, name)))
        else:
            steps.append((store, ros1_field.name, _value_to_ros2(field, ros1_field)))

    def convert(message: Any) -> Any:
        result = target.__new__(target)
        result._check_fields = CHECK_FIELDS
        for store, attribute, value_of in steps:
            store(result, value_of(getattr(message, attribute)))
        for store, factory in defaults:
            store(result, factory())
        return result

    return convert


def _default_of(target: type, name: str) -> Callable[[], Any]:
    for field_name, _store, factory in target._defaults:  # type: ignore[attr-defined]
        if field_name == name:
            return factory
    raise AssertionError(name)


def _scalar_to_ros2(field: FieldSpec, ros1_field: Any) -> Callable[[Any], Any]:
    if field.base == _TIME or field.base == _DURATION:
        cls = get_message_class(field.base)

        def stamp(value: Any) -> Any:
            sec, nanosec = divmod(value.secs * NS_PER_S + value.nsecs, NS_PER_S)
            result = cls.__new__(cls)
            result._check_fields = CHECK_FIELDS
            result._sec, result._nanosec = sec, nanosec
            return result

        return stamp
    if field.message_class is not None:
        return lambda value: to_ros2(value)
    python = field.primitive.python  # type: ignore[union-attr]
    if python == "bytes":  # ROS 1 byte is int8; ROS 2 byte is one octet
        return lambda value: bytes([value & 0xFF])
    return {"int": int, "float": float, "bool": bool, "str": str}[python]


def _value_to_ros2(field: FieldSpec, ros1_field: Any) -> Callable[[Any], Any]:
    element = _scalar_to_ros2(field, ros1_field)
    if field.container is None:
        return element
    if field.is_numeric_container:
        typecode = field.primitive.typecode  # type: ignore[union-attr]
        if field.container == "sequence":
            return lambda values: _to_array(typecode, values)
        import numpy

        dtype = NUMPY_DTYPES[typecode]
        return lambda values: numpy.array(values, dtype=dtype)
    return lambda values: [element(value) for value in values]


def _to_array(typecode: str, values: Any) -> array:
    """A numeric sequence as ROS 2 holds it; numpy input (the simulator's) moves as one buffer."""
    if getattr(values, "dtype", None) is None:
        return array(typecode, values)
    result = array(typecode)
    result.frombytes(values.astype(NUMPY_DTYPES[typecode], copy=False).tobytes())
    return result


def _plan_to_ros1(source: type, target: type) -> Callable[[Any], Any]:
    ros2_fields = {f.name: f for f in source._field_specs}  # type: ignore[attr-defined]
    steps = []
    for ros1_field in target._field_specs:  # type: ignore[attr-defined]
        field = _match(ros1_field.name, ros2_fields)
        if field is None:
            if (target._type, ros1_field.name) in _DROPPED_GOING_TO_ROS2:  # type: ignore[attr-defined]
                continue  # Header.seq: the ROS 1 default, 0
            raise BridgeError(f"{target._type}.{ros1_field.name} has no field in {source._type}")  # type: ignore[attr-defined]
        steps.append((ros1_field.name, source._slot_of[field.name], _value_to_ros1(field)))  # type: ignore[attr-defined]

    def convert(message: Any) -> Any:
        result = target()
        for attribute, slot, value_of in steps:
            setattr(result, attribute, value_of(getattr(message, slot)))
        return result

    return convert


def _value_to_ros1(field: FieldSpec) -> Callable[[Any], Any]:
    if field.base == _TIME or field.base == _DURATION:
        cls = Ros1Time if field.base == _TIME else Ros1Duration

        def stamp(value: Any) -> Any:
            if cls is Ros1Time and value.sec < 0:
                raise BridgeError(f"a ROS 1 time cannot be negative (sec={value.sec})")
            return cls(value.sec, value.nanosec)

        element: Callable[[Any], Any] = stamp
    elif field.message_class is not None:
        element = to_ros1
    elif field.base == "byte":
        element = lambda value: value[0] - 256 * (value[0] > 127)  # noqa: E731
    else:
        element = lambda value: value  # noqa: E731
    if field.container is None:
        return element
    if field.is_numeric_container:
        if field.primitive.typecode == "B":  # type: ignore[union-attr]
            return bytes  # ROS 1 uint8[] travels as bytes, as genpy gives it
        return lambda values: values.tolist()
    return lambda values: [element(value) for value in values]
