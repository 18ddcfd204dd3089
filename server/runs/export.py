"""CSV export of a recording: one file per topic, for spreadsheets and pandas.

Each file starts with a header line: ``time_s`` (the message's log time, run time [s]) then the
message's fields flattened with dotted names in definition order (``linear.x``,
``header.stamp``). Values:

- ``time`` / ``duration`` fields: seconds, exact to the nanosecond ("12.050000000");
- ``float32`` fields: the shortest decimal that reads back as the same float32 ("0.1", not
  "0.10000000149011612"); float64 fields: Python's shortest round-trip repr;
- ``bool``: "true"/"false";
- arrays (``ranges``, ``covariance``, ``transforms``): one column holding a JSON list; arrays of
  messages become lists of objects. Non-finite floats are written as JSON's de facto
  ``Infinity``/``-Infinity``/``NaN`` (Python's json and pandas read them; a LaserScan's "no
  return" is often inf).

File names come from topic names: ``/ultrasonic/range_0`` -> ``ultrasonic__range_0.csv``.
Messages are decoded with ``sandbox.msgs`` by schema name; a topic with no messages still gets a
file with its header line. A ROS 2 recording (``ros2msg`` schemas, CDR) exports the same way with
ROS 2 field names: a stamp is two columns, ``header.stamp.sec`` and ``header.stamp.nanosec``.
"""

from __future__ import annotations

import csv
import json
import math
import re
import struct
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

import numpy as np
from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader, make_reader

from sandbox.msgs import Message, get_message_class
from sandbox.units import NS_PER_S
from server.runs.message_fields import FieldShape, byte_value, field_shapes

_UNSAFE_CHARS = re.compile(r"[^\w.\-]+")

Formatter = Callable[[Any], str]


def csv_file_name(topic: str) -> str:
    """``/ultrasonic/range_0`` -> ``ultrasonic__range_0.csv``."""
    parts = [
        _UNSAFE_CHARS.sub("_", part) for part in topic.split("/") if part not in ("", ".", "..")
    ]
    stem = "__".join(parts).strip(".")
    return f"{stem or 'topic'}.csv"


def _seconds(value: Any) -> str:
    total = value.secs * NS_PER_S + value.nsecs
    sign = "-" if total < 0 else ""
    secs, nsecs = divmod(abs(total), NS_PER_S)
    return f"{sign}{secs}.{nsecs:09d}"


def _float32_number(value: float) -> float | str:
    """The shortest decimal of a float32 as a JSON-ready number (or Python's inf/nan)."""
    if not math.isfinite(value):
        return value
    return float(str(np.float32(value)))


def _float32(value: float) -> str:
    return repr(_float32_number(float(value)))


def _plain(field: FieldShape) -> Callable[[Any], Any]:
    """Converter of one element of `field` to a JSON-ready value."""
    kind = field.kind if field.message_class is None else "message"
    if kind == "message":
        return lambda message: _as_dict(message)
    if kind in ("time", "duration"):
        return lambda value: float(_seconds(value))
    if kind == "float" and field.code == "f":
        return lambda value: _float32_number(float(value))
    if kind == "bool":
        return bool
    if kind == "byte":
        return byte_value
    if kind == "string":
        return lambda value: value.decode("utf-8", "replace") if isinstance(value, bytes) else value
    return lambda value: value


def _as_dict(message: Message) -> dict[str, Any]:
    values = {}
    for field in field_shapes(type(message)):
        convert = _plain(field)
        value = getattr(message, field.name)
        if field.is_array:
            values[field.name] = [convert(item) for item in _items(value)]
        else:
            values[field.name] = convert(value)
    return values


def _items(value: Any) -> list[Any]:
    if isinstance(value, bytes | bytearray):
        return list(value)
    tolist = getattr(value, "tolist", None)
    return tolist() if tolist is not None else list(value)


def _columns(cls: type[Message], prefix: str = "") -> list[tuple[str, list[str], Formatter]]:
    """(column name, attribute path, formatter) for every leaf of `cls`, definition order."""
    columns: list[tuple[str, list[str], Formatter]] = []
    for field in field_shapes(cls):
        name = f"{prefix}{field.name}"
        nested = field.message_class
        if nested is not None and not field.is_array:
            for column, path, formatter in _columns(nested, f"{name}."):
                columns.append((column, [field.name, *path], formatter))
            continue
        columns.append((name, [field.name], _formatter(field)))
    return columns


_JSON_NON_FINITE = {"inf": "Infinity", "-inf": "-Infinity", "nan": "NaN"}


def _float32_array_json(values: Any) -> str:
    """A float32 array as a JSON list of shortest decimals (numpy formats them in one call)."""
    texts = np.asarray(values, dtype=np.float32).astype(str).tolist()
    return "[" + ", ".join([_JSON_NON_FINITE.get(text, text) for text in texts]) + "]"


def _formatter(field: FieldShape) -> Formatter:
    if field.is_array and field.code == "f":
        return _float32_array_json
    if field.is_array:
        convert = _plain(field)
        return lambda value: json.dumps(
            [convert(item) for item in _items(value)], ensure_ascii=False
        )
    kind = field.kind
    if kind in ("time", "duration"):
        return _seconds
    if kind == "float":
        return _float32 if field.code == "f" else lambda value: repr(float(value))
    if kind == "bool":
        return lambda value: "true" if value else "false"
    if kind == "byte":
        return lambda value: str(byte_value(value))
    if kind == "string":
        return lambda value: value.decode("utf-8", "replace") if isinstance(value, bytes) else value
    return str


def _row(message: Message, columns: list[tuple[str, list[str], Formatter]]) -> list[str]:
    row = []
    for _, path, formatter in columns:
        value: Any = message
        for name in path:
            value = getattr(value, name)
        row.append(formatter(value))
    return row


class _TopicCsv:
    def __init__(self, path: Path, cls: type[Message]) -> None:
        self.path = path
        self.cls = cls
        self.columns = _columns(cls)
        self.handle: IO[str] = open(path, "w", newline="", encoding="utf-8")  # noqa: SIM115
        self.writer = csv.writer(self.handle)
        self.writer.writerow(["time_s", *(name for name, _, _ in self.columns)])

    def write(self, log_time_ns: int, data: bytes) -> None:
        message = self.cls.deserialize(data)
        self.writer.writerow([repr(log_time_ns / NS_PER_S), *_row(message, self.columns)])


def export_csv(mcap_path: Path, out_dir: Path) -> list[Path]:
    """Write one CSV per topic of the recording at `mcap_path` into `out_dir`; return the paths
    in topic order. A schema that is neither ``ros1msg`` nor ``ros2msg`` (with CDR messages), or
    names a type ``sandbox.msgs`` does not know, is an error that names the topic."""
    mcap_path, out_dir = Path(mcap_path), Path(out_dir)
    if not mcap_path.is_file():
        raise FileNotFoundError(f"no recording at {mcap_path}")
    out_dir.mkdir(parents=True, exist_ok=True)
    files: dict[int, _TopicCsv] = {}
    try:
        with open(mcap_path, "rb") as stream:
            try:
                summary = make_reader(stream).get_summary()
            except McapError:
                summary = None  # no valid footer: the recording was cut short
            if summary is not None:
                for channel in sorted(summary.channels.values(), key=lambda c: c.topic):
                    _open_topic(files, channel, summary.schemas.get(channel.schema_id), out_dir)
            stream.seek(0)
            # Streaming read, in file (= recorded) order: also works on a file without a
            # summary, up to its last complete record.
            try:
                for schema, channel, message in NonSeekingReader(stream).iter_messages(
                    log_time_order=False
                ):
                    if channel.id not in files:
                        _open_topic(files, channel, schema, out_dir)
                    files[channel.id].write(message.log_time, message.data)
            except (McapError, struct.error, EOFError):
                if summary is not None:
                    raise
    finally:
        for topic_csv in files.values():
            topic_csv.handle.close()
    return [topic_csv.path for topic_csv in files.values()]


def _open_topic(files: dict[int, _TopicCsv], channel: Any, schema: Any, out_dir: Path) -> None:
    encodings = (schema.encoding, channel.message_encoding) if schema is not None else None
    if encodings not in (("ros1msg", "ros1"), ("ros2msg", "cdr")):
        encoding = None if schema is None else schema.encoding
        raise ValueError(
            f"topic '{channel.topic}' is not ROS1-encoded nor ROS 2 CDR (schema encoding "
            f"{encoding!r}); only RoboDojo recordings (ros1msg or ros2msg schemas) can be exported"
        )
    cls = get_message_class(schema.name)
    taken = {topic_csv.path.name for topic_csv in files.values()}
    name = csv_file_name(channel.topic)
    stem, counter = name.removesuffix(".csv"), 2
    while name in taken:
        name, counter = f"{stem}_{counter}.csv", counter + 1
    files[channel.id] = _TopicCsv(out_dir / name, cls)
