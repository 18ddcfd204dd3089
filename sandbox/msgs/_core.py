"""The ``Message`` base class and the registry of message types.

A message class declares only its ROS type name and its ``.msg`` definition text::

    class Int32(Message):
        _type = "std_msgs/Int32"
        _definition = "int32 data"

The metaclass parses the definition (``_spec.py``), derives ``__slots__``, constants, md5sum and
full text from it, and attaches a generated ``__init__``, serializer and deserializer
(``_codegen.py``). Nothing about a type's wire format is written anywhere else.

The ROS types RoboDojo provides are not written as classes: their definitions are a table
(``_definitions.py``) and ``get_message_class`` builds a class the first time it is asked for,
so a node pays only for the types it uses (building all ~140 takes tens of milliseconds).
"""

from __future__ import annotations

import keyword
import textwrap
import threading
from collections.abc import Iterator, Mapping
from typing import Any, ClassVar, Self

from ._catalog import unknown_type_sentence
from ._check import explain_failure
from ._codegen import ShortBuffer, build_deserializer, build_init, build_serializer
from ._definitions import MESSAGES
from ._spec import (
    compute_full_text,
    compute_md5,
    min_wire_size,
    parse_definition,
)

_REGISTRY: dict[str, type[Message]] = {}
# Building a class runs the metaclass, which registers it; a node's callback threads may ask for
# the same type at once. Re-entrant: building Odometry builds its nested types first.
_BUILD_LOCK = threading.RLock()


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


def _lookup_nested(msg_type: str) -> type[Message]:
    cls = _REGISTRY.get(msg_type)
    if cls is not None:
        return cls
    if msg_type in MESSAGES:
        return _build(msg_type)
    raise ValueError(
        f"nested type {msg_type} is not defined yet; define (or import) it before the "
        "message that uses it"
    )


def _build(msg_type: str) -> type[Message]:
    """Create (and so register) the class of a type in the definition table."""
    with _BUILD_LOCK:
        cls = _REGISTRY.get(msg_type)
        if cls is None:
            package, name = msg_type.split("/")
            namespace = {
                "__module__": f"sandbox.msgs.{package}",  # where pickle and repr find it
                "__qualname__": name,
                "_type": msg_type,
                "_definition": MESSAGES[msg_type],
            }
            cls = _MessageMeta(name, (Message,), namespace, from_table=True)
        return cls


def get_message_class(msg_type: str) -> type[Message]:
    """The class of ``"pkg/Name"``, e.g. ``get_message_class("std_msgs/Int32")``.

    A ROS 2 name (``"std_msgs/msg/Int32"``) gives the ROS 2 class from ``sandbox.msgs2``.
    Built on first use for the ROS types RoboDojo provides; raises UnknownMessageTypeError
    (a KeyError) with a sentence naming close matches for anything else.
    """
    cls = _REGISTRY.get(msg_type)
    if cls is not None:
        return cls
    if msg_type in MESSAGES:
        return _build(msg_type)
    if msg_type.count("/") == 2 and msg_type.split("/")[1] in ("msg", "srv", "action"):
        from sandbox.msgs2 import get_message_class as get_ros2_message_class

        return get_ros2_message_class(msg_type)  # type: ignore[return-value]
    raise UnknownMessageTypeError(unknown_type_sentence(msg_type))


class _MessageTypes(Mapping[str, "type[Message]"]):
    """Read-only view of every type, keyed by "pkg/Name"; a class is built when looked up."""

    def __getitem__(self, msg_type: str) -> type[Message]:
        return get_message_class(msg_type)

    def __contains__(self, msg_type: object) -> bool:
        return msg_type in MESSAGES or msg_type in _REGISTRY

    def __iter__(self) -> Iterator[str]:
        return iter(sorted(MESSAGES.keys() | _REGISTRY.keys()))

    def __len__(self) -> int:
        return len(MESSAGES.keys() | _REGISTRY.keys())


MESSAGE_TYPES: Mapping[str, type[Message]] = _MessageTypes()


class _MessageMeta(type):
    """Builds a message class from its ``_type`` and ``_definition``."""

    def __new__(
        mcls,
        name: str,
        bases: tuple[type, ...],
        namespace: dict[str, Any],
        register: bool = True,
        from_table: bool = False,
    ) -> _MessageMeta:
        if "_definition" not in namespace:  # the abstract Message base itself
            return super().__new__(mcls, name, bases, namespace)
        msg_type = namespace.get("_type")
        if not isinstance(msg_type, str) or msg_type.count("/") != 1:
            raise TypeError(f"message class {name} needs _type = 'pkg/Name', got {msg_type!r}")
        if register and msg_type in MESSAGES and not from_table:
            raise TypeError(
                f"{msg_type} is a ROS type RoboDojo provides: use get_message_class"
                f"({msg_type!r}) instead of defining it again"
            )
        if register and msg_type in _REGISTRY:
            raise TypeError(f"{msg_type} is already defined by {_REGISTRY[msg_type].__module__}")
        definition = textwrap.dedent(namespace["_definition"]).strip("\n").rstrip()
        constants, fields = parse_definition(msg_type, definition, _lookup_nested)
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
    # What a recorder writes for this class (MCAP's well-known encodings); ROS 2 classes say
    # "ros2msg" and "cdr".
    _schema_encoding: ClassVar[str] = "ros1msg"
    _message_encoding: ClassVar[str] = "ros1"
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
