"""The ROS 2 ``Message`` base class and the registry of message types.

A class is built from its type name and ``.msg`` text (``_definitions.py`` holds the table):
the metaclass parses the text (``_spec.py``), makes rosidl_generator_py's Python shape
(``_fields.py``: slots, properties with checks, defaults, constants as class attributes,
``get_fields_and_field_types()``, ``SLOT_TYPES``, repr ``std_msgs.msg.Int32(data=3)``), and
attaches generated CDR code (``_cdr.py``) and the rosbag2 schema text (``_fulltext.py``).

Beyond rosidl's shape every class carries what the server asks of a message class, ROS 1 or 2:
``_type`` ("pkg/msg/Name"), ``serialize()`` (CDR with the 4-byte encapsulation header, as
``rclpy.serialization.serialize_message`` returns it), ``deserialize(bytes)``, ``_full_text``,
``_schema_encoding = "ros2msg"`` and ``_message_encoding = "cdr"``.
"""

from __future__ import annotations

import re
import threading
import warnings
from typing import Any, ClassVar, Self

from sandbox.msgs._core import DeserializationError, SerializationError

from . import _slot_types
from ._cdr import BadValue, ShortBuffer
from ._cdr_read import build_deserializer
from ._cdr_write import build_serializer
from ._fields import CHECK_FIELDS, make_default, make_property
from ._fulltext import full_text
from ._spec import FieldSpec, min_wire_size, parse_definition

_REGISTRY: dict[str, type[Message]] = {}
# Several callback threads may ask for one type at once; building Odometry builds its nested
# types first, hence re-entrant.
BUILD_LOCK = threading.RLock()

# Our class attributes; a field whose rosidl slot (``_<name>``) would shadow one is stored in
# ``_<name>_`` instead (Marker.type would otherwise hide Marker._type).
_RESERVED = frozenset(
    {
        "_type",
        "_definition",
        "_full_text",
        "_schema_encoding",
        "_message_encoding",
        "_field_specs",
        "_constant_specs",
        "_slot_of",
        "_min_size",
        "_defaults",
        "_fields_and_field_types",
        "_serialize_fast",
        "_deserialize_from",
        "_check_fields",
        "_accepted",
    }
)


def snake_case(name: str) -> str:
    """rosidl_pycommon's convert_camel_case_to_lower_case_underscore: the module file name."""
    name = re.sub(r"(.)([A-Z][a-z]+)", r"\1_\2", name)
    return re.sub(r"([a-z0-9])([A-Z])", r"\1_\2", name).lower()


def rosidl_module(msg_type: str) -> str:
    """rosidl's module of the class: ``std_msgs.msg._int32``, ``pkg.srv._add_two_ints``."""
    package, kind, name = msg_type.split("/")
    stem = name.split("_")[0] if kind in ("srv", "action") else name
    return f"{package}.{kind}._{snake_case(stem)}"


class _MessageMeta(type):
    """Builds a message class from ``_type`` and ``_definition`` (see the module docstring)."""

    def __new__(
        mcls,
        name: str,
        bases: tuple[type, ...],
        namespace: dict[str, Any],
        lookup: Any = None,
        text_of: Any = None,
    ) -> _MessageMeta:
        if "_definition" not in namespace:  # the abstract base
            return super().__new__(mcls, name, bases, namespace)
        msg_type = namespace["_type"]
        constants, fields = parse_definition(msg_type, namespace["_definition"], lookup)
        slot_of = {
            f.name: f"_{f.name}_" if f"_{f.name}" in _RESERVED else f"_{f.name}" for f in fields
        }
        clashes = {c.name for c in constants} & set(slot_of)
        if clashes:
            raise ValueError(f"{msg_type}: {sorted(clashes)} used as both field and constant")
        namespace.update({c.name: c.value for c in constants})
        for field in fields:
            if field.default is not None:  # rosidl's <FIELD>__DEFAULT class attribute
                namespace[f"{field.name.upper()}__DEFAULT"] = field.default
        namespace.update(
            __slots__=(*slot_of.values(), "_check_fields"),
            _field_specs=tuple(fields),
            _constant_specs=tuple(constants),
            _slot_of=slot_of,
            _fields_and_field_types={f.name: f.field_type for f in fields},
            SLOT_TYPES=tuple(_slot_types.slot_type(f) for f in fields),
            _min_size=min_wire_size(fields),
            _accepted=frozenset((*slot_of, "check_fields")),
        )
        cls = super().__new__(mcls, name, bases, namespace)
        for field in fields:
            descriptor = cls.__dict__[slot_of[field.name]]
            setattr(cls, field.name, make_property(field, slot_of[field.name], descriptor))
        cls._defaults = tuple(  # type: ignore[attr-defined]
            (field.name, cls.__dict__[slot_of[field.name]].__set__, make_default(field))
            for field in fields
        )

        def slots(owner: Any, field: FieldSpec) -> str:
            return owner._slot_of[field.name]

        cls._serialize_fast = build_serializer(cls, slots)  # type: ignore[attr-defined]
        cls._deserialize_from = staticmethod(build_deserializer(cls, slots, CHECK_FIELDS))  # type: ignore[attr-defined]
        if text_of is not None:
            cls._full_text = full_text(msg_type, text_of)  # type: ignore[attr-defined]
        return cls


class Message(metaclass=_MessageMeta):
    """Base of every ROS 2 message class (rosidl_generator_py's shape, plus CDR)."""

    __slots__ = ()
    __hash__ = None  # type: ignore[assignment]  # mutable; rosidl classes are unhashable too

    _type: ClassVar[str]
    _definition: ClassVar[str]
    _full_text: ClassVar[str]
    _schema_encoding: ClassVar[str] = "ros2msg"
    _message_encoding: ClassVar[str] = "cdr"
    _field_specs: ClassVar[tuple[FieldSpec, ...]]
    _fields_and_field_types: ClassVar[dict[str, str]]
    SLOT_TYPES: ClassVar[tuple[Any, ...]]

    def __init__(self, **kwargs: Any) -> None:
        check = kwargs.get("check_fields", CHECK_FIELDS)
        self._check_fields = check
        if not self._accepted.issuperset(kwargs):  # type: ignore[attr-defined]
            unknown = sorted(set(kwargs) - self._accepted)  # type: ignore[attr-defined]
            sentence = (
                f"{', '.join(unknown)} ({self._type} has the fields "
                f"{', '.join(self._slot_of) or 'none'})"  # type: ignore[attr-defined]
            )
            if check:
                raise AssertionError(f"Invalid arguments passed to constructor: {sentence}")
            # Jazzy's rosidl ignores them silently; the script runs, but a typo is worth a line.
            warnings.warn(f"ignored unknown constructor arguments: {sentence}", stacklevel=2)
        for name, store, default in self._defaults:  # type: ignore[attr-defined]
            if name in kwargs:
                setattr(self, name, kwargs[name])
            else:
                store(self, default())

    @classmethod
    def get_fields_and_field_types(cls) -> dict[str, str]:
        """Field name -> rosidl type spelling (``'sequence<float>'``, ``'double[36]'``)."""
        return dict(cls._fields_and_field_types)

    def serialize(self) -> bytes:
        """CDR bytes, encapsulation header first (as rclpy's serialize_message returns them)."""
        try:
            return self._serialize_fast()  # type: ignore[attr-defined]
        except Exception as error:
            from ._explain import explain_failure

            raise SerializationError(explain_failure(self, error)) from None

    @classmethod
    def deserialize(cls, data: bytes | bytearray | memoryview) -> Self:
        """Decode one message from CDR bytes (with header); anything malformed is an error."""
        if not isinstance(data, bytes):
            if not isinstance(data, bytearray | memoryview):
                raise TypeError(f"{cls._type}.deserialize() needs bytes, got {type(data).__name__}")
            data = bytes(data)
        if len(data) < 4 or data[0] != 0 or data[1] not in (0, 1):
            raise DeserializationError(
                f"{cls._type}: the data does not start with a CDR encapsulation header "
                f"(00 01 00 00 for little-endian), got {data[:4].hex(' ') or 'nothing'}"
            )
        if data[1] == 0:
            raise DeserializationError(
                f"{cls._type}: big-endian CDR (header 00 00) is not supported; ROS 2 on "
                "common machines sends little-endian (00 01)"
            )
        try:
            message, end = cls._deserialize_from(data)  # type: ignore[attr-defined]
        except ShortBuffer as short:
            raise DeserializationError(
                f"{cls._type}: the data ends too early (got {len(data)} bytes, need at least "
                f"{short.need}) while reading field {short.path!r}"
            ) from None
        except BadValue as bad:
            raise DeserializationError(f"{cls._type}: {bad}") from None
        except UnicodeDecodeError as error:
            raise DeserializationError(
                f"{cls._type}: a string field is not valid UTF-8 ({error.reason})"
            ) from None
        if len(data) - end > 3:  # up to 3 bytes of padding may end a CDR buffer
            raise DeserializationError(
                f"{cls._type}: {len(data) - end} unexpected trailing bytes (the message ends "
                f"at byte {end} of {len(data)}); is the data really a {cls._type}?"
            )
        return message

    def __repr__(self) -> str:
        module = type(self).__module__.split(".")
        module.pop()
        args = []
        for field in self._field_specs:
            value = getattr(self, field.name)
            text = repr(value)
            if field.container == "sequence" and field.is_numeric_container:
                text = "[]" if not len(value) else text[len("array('x', ") : -1]
            args.append(f"{field.name}={text}")
        return f"{'.'.join([*module, type(self).__name__])}({', '.join(args)})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, self.__class__):
            return False
        for field in self._field_specs:
            mine, theirs = getattr(self, field.name), getattr(other, field.name)
            if field.container == "array" and field.is_numeric_container:
                import numpy

                if not numpy.array_equal(mine, theirs):
                    return False
            elif mine != theirs:
                return False
        return True

    def __reduce__(self) -> tuple[Any, ...]:
        # Rebuilt through the registry: our classes live in no importable module of their
        # rosidl name, so pickle (and copy) must not look them up by module path.
        state = tuple(getattr(self, slot) for slot in self.__slots__)
        return (_restore, (self._type, state))

    def __copy__(self) -> Self:
        new = self.__class__.__new__(self.__class__)
        for slot in self.__slots__:
            object.__setattr__(new, slot, getattr(self, slot))
        return new


def _restore(msg_type: str, state: tuple[Any, ...]) -> Message:
    from . import get_message_class

    cls = get_message_class(msg_type)
    message = cls.__new__(cls)
    for slot, value in zip(cls.__slots__, state, strict=True):
        object.__setattr__(message, slot, value)
    return message


def registered(msg_type: str) -> type[Message] | None:
    return _REGISTRY.get(msg_type)


def build(msg_type: str, definition: str, lookup: Any, text_of: Any) -> type[Message]:
    """Create and register the class of ``msg_type`` (the caller holds BUILD_LOCK)."""
    cls = _REGISTRY.get(msg_type)
    if cls is not None:
        return cls
    name = msg_type.rsplit("/", 1)[1]
    namespace = {
        "__module__": rosidl_module(msg_type),
        "__qualname__": name,
        "__doc__": f"Message class '{name}' ({msg_type}).",
        "_type": msg_type,
        "_definition": definition,
    }
    cls = _MessageMeta(name, (Message,), namespace, lookup=lookup, text_of=text_of)
    _REGISTRY[msg_type] = cls  # type: ignore[assignment]
    return cls  # type: ignore[return-value]
