"""The ``Message`` base class and the registry of message types.

A message class declares only its ROS type name and its ``.msg`` definition text::

    class Int32(Message):
        _type = "std_msgs/Int32"
        _definition = "int32 data"

The metaclass parses the definition (``_spec.py``), derives ``__slots__``, constants, md5sum and
full text from it, and attaches a generated ``__init__``, serializer and deserializer
(``_codegen.py``). Nothing about a type's wire format is written anywhere else.
"""

from __future__ import annotations

import keyword
import textwrap
import types
from collections.abc import Mapping
from typing import Any, ClassVar, Self

from ._check import explain_failure
from ._codegen import ShortBuffer, build_deserializer, build_init, build_serializer
from ._spec import (
    compute_full_text,
    compute_md5,
    min_wire_size,
    parse_definition,
)

_REGISTRY: dict[str, type[Message]] = {}
# Read-only view of every registered type, keyed by "pkg/Name".
MESSAGE_TYPES: Mapping[str, type[Message]] = types.MappingProxyType(_REGISTRY)


class SerializationError(ValueError, TypeError):
    """A field holds a value ROS1 cannot encode; the message names the field path.

    Subclasses both ValueError (out-of-range numbers) and TypeError (wrong types) so that code
    catching either of the built-in exceptions for the case it expects still works.
    """


class DeserializationError(ValueError):
    """Bytes that are not a valid encoding of the requested message type."""


class UnknownMessageTypeError(KeyError):
    """``get_message_class`` was given a type name that is not registered."""

    def __str__(self) -> str:  # KeyError would show the sentence in quotes
        return str(self.args[0])


def _lookup_registered(msg_type: str) -> type[Message]:
    try:
        return _REGISTRY[msg_type]
    except KeyError:
        raise ValueError(
            f"nested type {msg_type} is not defined yet; define (or import) it before the "
            "message that uses it"
        ) from None


def get_message_class(msg_type: str) -> type[Message]:
    """The class registered for ``"pkg/Name"``, e.g. ``get_message_class("std_msgs/Int32")``."""
    try:
        return _REGISTRY[msg_type]
    except KeyError:
        known = ", ".join(sorted(_REGISTRY))
        raise UnknownMessageTypeError(
            f"unknown message type {msg_type!r}; known types are: {known}"
        ) from None


class _MessageMeta(type):
    """Builds a message class from its ``_type`` and ``_definition``."""

    def __new__(
        mcls,
        name: str,
        bases: tuple[type, ...],
        namespace: dict[str, Any],
        register: bool = True,
    ) -> _MessageMeta:
        if "_definition" not in namespace:  # the abstract Message base itself
            return super().__new__(mcls, name, bases, namespace)
        msg_type = namespace.get("_type")
        if not isinstance(msg_type, str) or msg_type.count("/") != 1:
            raise TypeError(f"message class {name} needs _type = 'pkg/Name', got {msg_type!r}")
        if register and msg_type in _REGISTRY:
            raise TypeError(f"{msg_type} is already defined by {_REGISTRY[msg_type].__module__}")
        definition = textwrap.dedent(namespace["_definition"]).strip("\n").rstrip()
        constants, fields = parse_definition(msg_type, definition, _lookup_registered)
        for field in fields:
            if keyword.iskeyword(field.name):
                raise ValueError(f"{msg_type}: field name {field.name!r} is a Python keyword")
        clashes = {c.name for c in constants} & {f.name for f in fields}
        if clashes:
            raise ValueError(f"{msg_type}: {sorted(clashes)} used as both field and constant")
        namespace.update({c.name: c.value for c in constants})
        namespace.update(
            __slots__=tuple(field.name for field in fields),
            _definition=definition,
            _field_specs=tuple(fields),
            _constant_specs=tuple(constants),
            _slot_types=[field.full_type for field in fields],
            _md5sum=compute_md5(constants, fields),
            _full_text=compute_full_text(definition, fields),
            _has_header=bool(fields)
            and fields[0].name == "header"
            and fields[0].base_type == "std_msgs/Header",
            _min_size=min_wire_size(fields),
            _array_fields=frozenset(field.name for field in fields if field.is_array),
        )
        cls = super().__new__(mcls, name, bases, namespace)
        cls.__init__ = build_init(cls)  # type: ignore[misc]
        cls._serialize_fast = build_serializer(cls)  # type: ignore[attr-defined]
        cls._deserialize_from = staticmethod(build_deserializer(cls))  # type: ignore[attr-defined]
        if register:
            _REGISTRY[msg_type] = cls  # type: ignore[assignment]
        return cls


class Message(metaclass=_MessageMeta):
    """Base of every ROS1 message class; subclasses declare ``_type`` and ``_definition``.

    Instances take field values positionally (definition order) or by keyword; missing fields
    get ROS defaults. Assignment is unchecked, as in rospy; ``serialize()`` checks.
    """

    __slots__ = ()
    __hash__ = None  # type: ignore[assignment]  # mutable, like rospy messages

    _type: ClassVar[str]
    _definition: ClassVar[str]
    _md5sum: ClassVar[str]
    _full_text: ClassVar[str]
    _slot_types: ClassVar[list[str]]
    _has_header: ClassVar[bool]

    def serialize(self) -> bytes:
        """ROS1 wire bytes (little-endian, no length prefix for the message itself)."""
        try:
            return self._serialize_fast()  # type: ignore[attr-defined]
        except Exception as error:
            raise SerializationError(explain_failure(type(self), self, error)) from error

    @classmethod
    def deserialize(cls, data: bytes | bytearray | memoryview) -> Self:
        """Decode exactly one message from ``data``; extra or missing bytes are an error."""
        if not isinstance(data, bytes):
            if not isinstance(data, bytearray | memoryview):
                raise TypeError(f"{cls._type}.deserialize() needs bytes, got {type(data).__name__}")
            data = bytes(data)
        try:
            message, end = cls._deserialize_from(data)  # type: ignore[attr-defined]
        except ShortBuffer as short:
            raise DeserializationError(
                f"{cls._type}: buffer too short (got {len(data)} bytes, need {short.need}) "
                f"while reading field {short.path!r}"
            ) from None
        except UnicodeDecodeError as error:
            raise DeserializationError(
                f"{cls._type}: a string field is not valid UTF-8 ({error.reason} at byte "
                f"{error.start} of the string)"
            ) from None
        if end != len(data):
            raise DeserializationError(
                f"{cls._type}: {len(data) - end} unexpected trailing bytes (the message ends "
                f"at byte {end} of {len(data)}); is the data really a {cls._type}?"
            )
        return message

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        arrays = self._array_fields  # type: ignore[attr-defined]
        for name in self.__slots__:
            mine, theirs = getattr(self, name), getattr(other, name)
            if mine is theirs:
                continue
            if name in arrays:
                # Arrays may be lists, tuples, bytes or numpy arrays; compare the items.
                mine, theirs = _as_list(mine), _as_list(theirs)
            if mine != theirs:
                return False
        return True

    def __repr__(self) -> str:
        values = ", ".join(f"{name}={getattr(self, name, None)!r}" for name in self.__slots__)
        return f"{type(self).__name__}({values})"


def _as_list(values: Any) -> list[Any]:
    tolist = getattr(values, "tolist", None)
    return tolist() if tolist is not None else list(values)
