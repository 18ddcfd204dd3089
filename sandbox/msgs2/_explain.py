"""Explain why a ROS 2 message failed to serialize, naming the field: ``Twist.linear.x: ...``.

Only called after the fast generated serializer failed (a value set with ``check_fields=False``,
written to a slot directly, or a nested message of the wrong type), so it can afford to walk
every field with the setters' own checks.
"""

from __future__ import annotations

from typing import Any

from ._fields import make_check


def _walk(message: Any, path: str) -> str | None:
    for field in message._field_specs:
        value = getattr(message, message._slot_of[field.name], None)
        where = f"{path}.{field.name}"
        try:
            make_check(field)(value)
        except AssertionError as error:
            return f"{where}: {error}"
        if field.message_class is None:
            continue
        items = value if field.container is not None else [value]
        for index, item in enumerate(items):
            inner = _walk(item, f"{where}[{index}]" if field.container else where)
            if inner:
                return inner
    return None


def explain_failure(message: Any, error: Exception) -> str:
    """A sentence naming the first field that cannot be encoded, or the encoder's error."""
    name = type(message).__name__
    found = _walk(message, name)
    if found:
        return f"cannot serialize {message._type}: {found}"
    return f"cannot serialize {message._type}: {type(error).__name__}: {error}"
