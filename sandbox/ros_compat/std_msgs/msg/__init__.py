"""The std_msgs message classes (defined once, in sandbox.msgs.std_msgs)."""

from sandbox.msgs import Message as _Message
from sandbox.msgs import std_msgs as _definitions

__all__ = sorted(
    name
    for name, value in vars(_definitions).items()
    if isinstance(value, type)
    and issubclass(value, _Message)
    and getattr(value, "_type", "").startswith("std_msgs/")
)
globals().update({name: getattr(_definitions, name) for name in __all__})
