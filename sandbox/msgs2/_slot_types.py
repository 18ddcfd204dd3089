"""The type objects of a message class's ``SLOT_TYPES``, shaped like ``rosidl_parser.definition``.

ros2/rosidl, ``rosidl_parser/rosidl_parser/definition.py``: rosidl_generator_py lists one of
these per field, and rosidl_runtime_py (``set_message_fields``, ``message_to_ordereddict``) and
course code walk them with ``isinstance`` checks (``AbstractNestedType``, ``BasicType``,
``NamespacedType``) and read ``typename``, ``value_type``, ``size``, ``maximum_size``.
"""

from __future__ import annotations

from typing import Any


class AbstractType:
    def __eq__(self, other: object) -> bool:
        return type(self) is type(other) and vars(self) == vars(other)

    def __hash__(self) -> int:
        return hash((type(self).__name__, *sorted(vars(self).items())))

    def __repr__(self) -> str:
        args = ", ".join(f"{key}={value!r}" for key, value in vars(self).items())
        return f"{type(self).__name__}({args})"


class BasicType(AbstractType):
    def __init__(self, typename: str) -> None:
        self.typename = typename


class NamedType(AbstractType):
    def __init__(self, name: str) -> None:
        self.name = name


class NamespacedType(AbstractType):
    def __init__(self, namespaces: list[str], name: str) -> None:
        self.namespaces = list(namespaces)
        self.name = name

    def namespaced_name(self) -> tuple[str, ...]:
        return (*self.namespaces, self.name)


class AbstractGenericString(AbstractType):
    def has_maximum_size(self) -> bool:
        return getattr(self, "maximum_size", None) is not None


class AbstractString(AbstractGenericString):
    pass


class UnboundedString(AbstractString):
    pass


class BoundedString(AbstractString):
    def __init__(self, maximum_size: int) -> None:
        self.maximum_size = maximum_size


class AbstractNestedType(AbstractType):
    def __init__(self, value_type: AbstractType) -> None:
        self.value_type = value_type


class Array(AbstractNestedType):
    def __init__(self, value_type: AbstractType, size: int) -> None:
        super().__init__(value_type)
        self.size = size


class AbstractSequence(AbstractNestedType):
    pass


class UnboundedSequence(AbstractSequence):
    pass


class BoundedSequence(AbstractSequence):
    def __init__(self, value_type: AbstractType, maximum_size: int) -> None:
        super().__init__(value_type)
        self.maximum_size = maximum_size


def _element(field: Any) -> AbstractType:
    if field.message_class is not None:
        package, kind, name = field.base.split("/")
        return NamespacedType([package, kind], name)
    if field.base == "string":
        if field.string_bound is not None:
            return BoundedString(field.string_bound)
        return UnboundedString()
    return BasicType(field.primitive.idl)


def slot_type(field: Any) -> AbstractType:
    """The SLOT_TYPES entry of one field (a ``_spec.FieldSpec``)."""
    element = _element(field)
    if field.container == "array":
        return Array(element, field.size)
    if field.container == "sequence":
        if field.size is None:
            return UnboundedSequence(element)
        return BoundedSequence(element, field.size)
    return element
