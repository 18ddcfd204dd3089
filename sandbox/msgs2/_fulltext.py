"""The ``ros2msg`` schema text of a type, as rosbag2's MCAP storage writes it.

ros2/rosbag2, ``rosbag2_cpp/src/rosbag2_cpp/message_definitions/``
``local_message_definition_source.cpp`` (``get_full_text``), and the MCAP ``ros2msg`` schema
encoding (mcap.dev, "Well-known schema encodings"): the top type's ``.msg`` text, then for each
dependency not yet written, depth first and in sorted name order at each level, a newline, a
line of 80 ``=``, ``MSG: pkg/Name`` and that type's text. Dependencies are the field types the
text names (``std_msgs/Header``, or a bare ``Vector3`` taken as the same package's). Our texts
carry no comments (the type store has none), so the schema is the interface files' text without
them; parsers read both alike.
"""

from __future__ import annotations

import re
from collections.abc import Callable

_DELIMITER = "=" * 80 + "\n"
# Same matching rule as rosbag2's MSG_FIELD_TYPE_REGEX: a line's first word, optionally with
# an array suffix, followed by whitespace.
_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")
_KINDED_NAME = re.compile(r"\b([A-Za-z0-9_]+)/(?:msg|srv|action)/([A-Za-z0-9_]+)")
_PRIMITIVES = frozenset(
    {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32"}
    | {"uint32", "int64", "uint64", "string"}
)


def dependencies(text: str, package: str) -> dict[str, str]:
    """The types ``text``'s fields name: ``pkg/Name`` as the schema writes it -> full name.

    A type of a service or an action (``nav2_msgs/action/NavigateToPose_Goal``) is written
    ``nav2_msgs/NavigateToPose_Goal``: ``.msg`` syntax has no kind, and readers (mcap_ros2,
    rosbags) refuse a three-part name.
    """
    found = {}
    for match in _FIELD_TYPE.finditer(text):
        name = match[1]
        if name in _PRIMITIVES:
            continue
        parts = name.split("/")
        if len(parts) == 1:
            parts = [package, "msg", name]
        elif len(parts) == 2:
            parts = [parts[0], "msg", parts[1]]
        found[f"{parts[0]}/{parts[2]}"] = "/".join(parts)
    return dict(sorted(found.items()))


def _two_part_names(text: str) -> str:
    return _KINDED_NAME.sub(r"\1/\2", text)


def full_text(msg_type: str, text_of: Callable[[str], str]) -> str:
    """The schema of ``msg_type``; ``text_of("pkg/msg/Name")`` gives a type's own text."""
    seen: set[str] = set()

    def expand(type_name: str, depth: int) -> str:
        if depth > 50:  # rosbag2 stops at its max recursion depth as well
            raise ValueError(f"definition of {msg_type} nests too deeply")
        own = text_of(type_name) + "\n"  # interface files end with a newline
        text = _two_part_names(own)
        for written, dependency in dependencies(own, type_name.split("/", 1)[0]).items():
            if written in seen:
                continue
            seen.add(written)
            text += "\n" + _DELIMITER + f"MSG: {written}\n"
            text += expand(dependency, depth + 1)
        return text

    return expand(msg_type, 0)
