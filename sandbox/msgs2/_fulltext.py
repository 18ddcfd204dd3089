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
_PRIMITIVES = frozenset(
    {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32"}
    | {"uint32", "int64", "uint64", "string"}
)


def dependencies(text: str, package: str) -> list[str]:
    """Sorted ``pkg/Name`` (or ``pkg/kind/Name``) types that ``text``'s fields name."""
    found = set()
    for match in _FIELD_TYPE.finditer(text):
        name = match[1]
        if name in _PRIMITIVES:
            continue
        found.add(name if "/" in name else f"{package}/{name}")
    return sorted(found)


def full_text(msg_type: str, text_of: Callable[[str], str]) -> str:
    """The schema of ``msg_type``; ``text_of("pkg/msg/Name")`` gives a type's own text."""
    seen: set[str] = set()

    def expand(type_name: str, depth: int) -> str:
        if depth > 50:  # rosbag2 stops at its max recursion depth as well
            raise ValueError(f"definition of {msg_type} nests too deeply")
        text = text_of(type_name) + "\n"  # interface files end with a newline
        package = type_name.split("/", 1)[0]
        for dependency in dependencies(text, package):
            if dependency in seen:
                continue
            seen.add(dependency)
            text += "\n" + _DELIMITER + f"MSG: {dependency}\n"
            text += expand(_full_name(dependency), depth + 1)
        return text

    return expand(msg_type, 0)


def _full_name(name: str) -> str:
    package, _, rest = name.partition("/")
    return name if "/" in rest else f"{package}/msg/{rest}"
