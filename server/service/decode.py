"""ROS messages as plain JSON data for a browser's live view.

A viewer gets every telemetry frame as JSON, so a message has to become dicts, lists, numbers,
strings and None: nested messages become dicts keyed by field, ``Time``/``Duration`` float
seconds, byte strings and numpy arrays lists. JSON has no NaN or infinity (``JSON.parse`` rejects
Python's ``NaN``), so non-finite floats become None - a LaserScan's "no return" reads as a gap.

Conversion follows each class's parsed field specs, planned once per class, rather than
inspecting every value: a 429-beam LaserScan converts in tens of microseconds. ROS 2 messages
(a ROS 2 run's "pkg/msg/Name" types, CDR bytes) convert the same way with their own field names:
a stamp is ``{"sec": ..., "nanosec": ...}`` there, as `ros2 topic echo` shows it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from sandbox.msgs import Duration, Message, Time, get_message_class
from server.runs.message_fields import byte_value, field_shapes

# An array longer than this is sent as {"omitted_items": n} instead of its items: a 200 x 200
# OccupancyGrid (40 000 cells) is ~150 kB of JSON per frame, too much to push to every browser at
# up to 60 Hz; the recording keeps it whole for a map view or Foxglove.
MAX_ARRAY_ITEMS = 20_000

_Convert = Callable[[Any], Any]
_PLANS: dict[type, tuple[tuple[str, _Convert], ...]] = {}
# type name -> class; get_message_class raises for unknown names, this only remembers hits.
_CLASSES: dict[str, type[Message]] = {}


def to_jsonable(message: Message) -> dict[str, Any]:
    """The message's fields as nested plain data that ``json.dumps`` accepts with
    ``allow_nan=False``."""
    plan = _PLANS.get(message.__class__)
    if plan is None:
        plan = _plan(message.__class__)
    return {name: convert(getattr(message, name)) for name, convert in plan}


def decode(type_name: str, data: bytes) -> dict[str, Any]:
    """Deserialize the bytes of ``type_name`` (ROS 1 "pkg/Name", or ROS 2 "pkg/msg/Name" with
    CDR bytes) and convert them for JSON."""
    cls = _CLASSES.get(type_name)
    if cls is None:
        cls = _CLASSES[type_name] = get_message_class(type_name)
    return to_jsonable(cls.deserialize(data))


# ------------------------------------------------------------------------------------ planning
def _plan(cls: type) -> tuple[tuple[str, _Convert], ...]:
    plan = tuple((spec.name, _converter(spec)) for spec in field_shapes(cls))
    _PLANS[cls] = plan
    return plan


def _converter(spec: Any) -> _Convert:
    kind = spec.kind
    if kind == "message":
        one = to_jsonable
    elif kind == "float":
        one = _float
    elif kind in ("time", "duration"):
        one = _seconds
    elif kind == "byte":
        one = byte_value
    else:  # int, bool, string: already plain (numpy scalars and the like are coerced)
        one = _plain
    if not spec.is_array:
        return one
    if kind == "float":
        return _float_array
    if kind in ("int", "bool"):
        return _number_array
    return lambda values: _array(values, one)


def _float(value: Any) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def _seconds(value: Any) -> float | None:
    if isinstance(value, Time | Duration):
        return value.to_sec()
    return _float(value)  # a user-built message may hold plain seconds


def _plain(value: Any) -> Any:
    if value is None or value.__class__ in (int, bool, str):
        return value
    if isinstance(value, bytes | bytearray):  # a char or uint8 array of fixed size 1
        return list(value)
    item = getattr(value, "item", None)  # numpy scalar -> Python number
    return item() if item is not None else value


def _omitted(values: Any) -> dict[str, int] | None:
    count = len(values)
    return {"omitted_items": count} if count > MAX_ARRAY_ITEMS else None


def _as_list(values: Any) -> list[Any]:
    if values.__class__ is list:
        return values
    tolist = getattr(values, "tolist", None)  # numpy and array.array, in one C call
    return tolist() if tolist is not None else list(values)  # tuple, bytes (-> ints)


def _float_array(values: Any) -> Any:
    omitted = _omitted(values)
    if omitted is not None:
        return omitted
    items = _as_list(values)
    # One C-level sum tells whether any item is NaN or infinite (or the sum overflowed, which
    # the per-item pass below then handles correctly); most arrays need no per-item check.
    if math.isfinite(sum(items)):
        return items if items is not values else list(items)
    return [item if math.isfinite(item) else None for item in items]


def _number_array(values: Any) -> Any:
    omitted = _omitted(values)
    if omitted is not None:
        return omitted
    items = _as_list(values)
    return items if items is not values else list(items)


def _array(values: Any, convert: _Convert) -> Any:
    omitted = _omitted(values)
    if omitted is not None:
        return omitted
    return [convert(item) for item in values]
