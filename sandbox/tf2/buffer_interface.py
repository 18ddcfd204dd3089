"""tf2_ros's BufferInterface: `buffer.transform(stamped_message, target_frame)` for any message
type that registered a do_transform function, and `convert` between registered types.

As in ros/geometry2 (tf2_ros/src/tf2_ros/buffer_interface.py, the same in ROS 1 and ROS 2) the
registries are shared by every buffer and are filled by importing a conversion package:
`import tf2_geometry_msgs` registers PointStamped, PoseStamped, Vector3Stamped, WrenchStamped
(and more here). Types are keyed by their ROS type name ("geometry_msgs/PoseStamped" in ROS 1,
"geometry_msgs/msg/PoseStamped" in ROS 2), so a message class and its re-export are one key.
A timeout of None (the default here) looks once without waiting, as a zero Duration does.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

NO_WAIT = None  # the default timeout: look once, do not wait

# What registers each type when it is missing (the hint in TypeException).
_PROVIDERS = {"geometry_msgs/": "tf2_geometry_msgs"}


def _key(message_type: Any) -> Any:
    return getattr(message_type, "_type", message_type)


class TypeException(Exception):
    """A type with no registered transform or conversion."""

    def __init__(self, errstr: str) -> None:
        super().__init__(errstr)
        self.errstr = errstr


class NotImplementedException(Exception):
    """can_transform or lookup_transform called on the abstract BufferInterface."""

    def __init__(self) -> None:
        self.errstr = "CanTransform or LookupTransform is not implemented"
        super().__init__(self.errstr)


def _unsupported(key: Any) -> TypeException:
    text = f"Type {key} is not loaded or supported"
    for prefix, package in _PROVIDERS.items():
        if isinstance(key, str) and key.startswith(prefix):
            text += f"; add `import {package}` to register the {prefix[:-1]} types"
    return TypeException(text)


class TransformRegistration:
    """Which function transforms each stamped type (shared by all buffers)."""

    _type_map: dict[Any, Callable[..., Any]] = {}  # noqa: RUF012 (shared on purpose)

    def add(self, key: Any, callback: Callable[..., Any]) -> None:
        TransformRegistration._type_map[_key(key)] = callback

    def get(self, key: Any) -> Callable[..., Any]:
        found = TransformRegistration._type_map.get(_key(key))
        if found is None:
            raise _unsupported(_key(key))
        return found

    def print_me(self) -> None:
        print(TransformRegistration._type_map)


class ConvertRegistration:
    """to_msg / from_msg / direct conversions between registered types (shared)."""

    _to_msg_map: dict[Any, Callable[..., Any]] = {}  # noqa: RUF012
    _from_msg_map: dict[Any, Callable[..., Any]] = {}  # noqa: RUF012
    _convert_map: dict[Any, Callable[..., Any]] = {}  # noqa: RUF012

    def add_from_msg(self, key: Any, callback: Callable[..., Any]) -> None:
        ConvertRegistration._from_msg_map[_key(key)] = callback

    def add_to_msg(self, key: Any, callback: Callable[..., Any]) -> None:
        ConvertRegistration._to_msg_map[_key(key)] = callback

    def add_convert(self, key: Any, callback: Callable[..., Any]) -> None:
        if isinstance(key, tuple):
            key = tuple(_key(part) for part in key)
        ConvertRegistration._convert_map[key] = callback

    @staticmethod
    def _get(table: dict[Any, Callable[..., Any]], key: Any) -> Callable[..., Any]:
        found = table.get(key)
        if found is None:
            raise _unsupported(key)
        return found

    def get_from_msg(self, key: Any) -> Callable[..., Any]:
        return self._get(ConvertRegistration._from_msg_map, _key(key))

    def get_to_msg(self, key: Any) -> Callable[..., Any]:
        return self._get(ConvertRegistration._to_msg_map, _key(key))

    def get_convert(self, key: Any) -> Callable[..., Any]:
        if isinstance(key, tuple):
            key = tuple(_key(part) for part in key)
        return self._get(ConvertRegistration._convert_map, key)


def convert(a: Any, b_type: Any) -> Any:
    """`a` as a `b_type`: a direct conversion if registered, a copy for the same type, else
    through the registered to_msg / from_msg pair."""
    registry = ConvertRegistration()
    try:
        return registry.get_convert((type(a), b_type))(a)
    except TypeException:
        if _key(type(a)) == _key(b_type):
            return copy.deepcopy(a)
        return registry.get_from_msg(b_type)(registry.get_to_msg(type(a))(a))


class BufferInterface:
    """transform / transform_full on top of a subclass's lookup_transform(_full)."""

    def __init__(self) -> None:
        self.registration = TransformRegistration()

    def transform(
        self,
        object_stamped: Any,
        target_frame: str,
        timeout: Any = NO_WAIT,
        new_type: Any = None,
    ) -> Any:
        """`object_stamped` (any registered stamped message) expressed in `target_frame`, at
        its own header.stamp; waits up to `timeout` for the transform."""
        do_transform = self.registration.get(type(object_stamped))
        header = _header_of(object_stamped)
        transform = self.lookup_transform(target_frame, header.frame_id, header.stamp, timeout)
        result = do_transform(object_stamped, transform)
        return result if not new_type else convert(result, new_type)

    def transform_full(
        self,
        object_stamped: Any,
        target_frame: str,
        target_time: Any,
        fixed_frame: str,
        timeout: Any = NO_WAIT,
        new_type: Any = None,
    ) -> Any:
        """transform() between two times, through `fixed_frame` (taken to stay still)."""
        do_transform = self.registration.get(type(object_stamped))
        header = _header_of(object_stamped)
        transform = self.lookup_transform_full(
            target_frame, target_time, header.frame_id, header.stamp, fixed_frame, timeout
        )
        result = do_transform(object_stamped, transform)
        return result if not new_type else convert(result, new_type)

    def lookup_transform(
        self, target_frame: str, source_frame: str, time: Any, timeout: Any = NO_WAIT
    ) -> Any:
        raise NotImplementedException()

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = NO_WAIT,
    ) -> Any:
        raise NotImplementedException()

    def can_transform(
        self, target_frame: str, source_frame: str, time: Any, timeout: Any = NO_WAIT
    ) -> bool:
        raise NotImplementedException()

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = NO_WAIT,
    ) -> bool:
        raise NotImplementedException()


def _header_of(object_stamped: Any) -> Any:
    header = getattr(object_stamped, "header", None)
    if header is None:
        raise TypeException(
            f"transform() takes a stamped message (with a header: frame_id and stamp), got "
            f"{type(object_stamped).__name__}"
        )
    return header
