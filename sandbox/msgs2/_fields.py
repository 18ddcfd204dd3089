"""Field properties, defaults and checks of ROS 2 message classes, as rosidl_generator_py has them.

ros2/rosidl_python, ``rosidl_generator_py/resource/_msg.py.em``: every field is a property over
a slot named ``_<field>``; the setter checks the value's type and range with ``assert`` when the
instance's ``_check_fields`` is true, then stores it, converting numeric sequences to
``array.array`` and numeric fixed arrays to numpy arrays of the field's dtype. Defaults: 0, 0.0,
False, '', a new nested message, ``array.array(code)``, ``numpy.zeros(n, dtype)``, an empty list,
or the definition's default value.

``_check_fields``: rosidl (Jazzy) turns the checks on only when the environment variable
``ROS_PYTHON_CHECK_FIELDS`` is ``1`` (before Jazzy they were always on). RoboDojo follows Jazzy,
the distribution it models (``CHECK_FIELDS`` off): a script Jazzy's rclpy accepts, such as one
writing ``twist.linear.x = 1``, must run here too. A wrong value is still caught, at publish,
by the serializer, with the same sentence naming the field. ``check_fields=True`` in a
constructor turns the checks on for that message, as in rosidl.
"""

from __future__ import annotations

import math
from array import array
from collections import UserList, UserString
from collections.abc import Callable, Sequence, Set
from typing import Any

from ._spec import FLOAT_BOUNDS, INT_RANGES, NUMPY_DTYPES, FieldSpec

CHECK_FIELDS = False  # Jazzy's default (ROS_PYTHON_CHECK_FIELDS unset), see the docstring


def _element_check(field: FieldSpec) -> tuple[Callable[[Any], bool], str]:
    """A test of one value of the field's element type, and the sentence when it fails."""
    primitive = field.primitive
    if primitive is None:
        cls = field.message_class
        return (lambda v: isinstance(v, cls)), f"a sub message of type '{cls.__name__}'"
    python = primitive.python
    if field.base == "string":
        bound = field.string_bound
        if bound is None:
            return (lambda v: isinstance(v, str)), "of type 'str'"
        return (
            lambda v: isinstance(v, str | UserString) and len(v) <= bound
        ), f"a string not longer than {bound}"
    if python == "bool":
        return (lambda v: isinstance(v, bool)), "of type 'bool'"
    if python == "bytes":
        return (lambda v: isinstance(v, bytes) and len(v) == 1), "of type 'bytes' with length 1"
    if python == "int":
        low, high = INT_RANGES[primitive.code]
        kind = "an unsigned integer" if low == 0 else "an integer"
        return (
            lambda v: isinstance(v, int) and low <= v <= high
        ), f"{kind} (int) in [{low}, {high}]"
    bound = FLOAT_BOUNDS[primitive.code]
    name = "float" if primitive.code == "f" else "double"
    return (
        lambda v: isinstance(v, float) and (not (v < -bound or v > bound) or math.isinf(v))
    ), f"a {name} (float) in [{-bound}, {bound}]"


def _describe(value: Any) -> str:
    text = repr(value)
    return f"{text[:57]}... ({type(value).__name__})" if len(text) > 60 else text


def make_check(field: FieldSpec) -> Callable[[Any], None]:
    """The setter's check: raises AssertionError with a sentence naming the field."""
    accept, wanted = _element_check(field)
    name = field.name
    if field.container is None:

        def check(value: Any) -> None:
            if not accept(value):
                raise AssertionError(f"The '{name}' field must be {wanted}, got {_describe(value)}")

        return check

    size, container = field.size, field.container
    if container == "array":
        length_rule = f" with length {size}"
    elif size is not None:
        length_rule = f" with length <= {size}"
    else:
        length_rule = ""
    typecode = field.primitive.typecode if field.is_numeric_container else ""  # type: ignore[union-attr]
    dtype = NUMPY_DTYPES.get(typecode, "")

    def check_container(value: Any) -> None:
        if typecode:
            if container == "array" and getattr(value, "dtype", None) is not None:
                if value.dtype.name != dtype or value.size != size:
                    raise AssertionError(
                        f"The '{name}' numpy.ndarray() must have dtype '{dtype}' and size "
                        f"{size}, got dtype '{value.dtype.name}' and size {value.size}"
                    )
                return
            if container == "sequence" and isinstance(value, array):
                if value.typecode != typecode:
                    raise AssertionError(
                        f"The '{name}' array.array() must have the type code of '{typecode}', "
                        f"got '{value.typecode}'"
                    )
                if size is not None and len(value) > size:
                    raise AssertionError(f"The '{name}' array.array() must have a size <= {size}")
                return
        is_sequence = isinstance(value, Sequence | Set | UserList) and not isinstance(
            value, str | UserString
        )
        if not is_sequence:
            raise AssertionError(
                f"The '{name}' field must be a set or sequence{length_rule} and each value "
                f"{wanted}, got {_describe(value)}"
            )
        if (container == "array" and len(value) != size) or (
            size is not None and len(value) > size
        ):
            raise AssertionError(
                f"The '{name}' field must be a set or sequence{length_rule}, got {len(value)} "
                "values"
            )
        for index, item in enumerate(value):
            if not accept(item):
                raise AssertionError(
                    f"The '{name}' field must be a set or sequence{length_rule} and each value "
                    f"{wanted}; item {index} is {_describe(item)}"
                )

    return check_container


def make_convert(field: FieldSpec) -> Callable[[Any], Any] | None:
    """How the setter stores a value (always, checked or not), None to store it as given."""
    if not field.is_numeric_container:
        return None
    typecode = field.primitive.typecode  # type: ignore[union-attr]
    if field.container == "sequence":

        def to_array(value: Any) -> array:
            if isinstance(value, array) and value.typecode == typecode:
                return value
            return array(typecode, value)

        return to_array
    import numpy

    dtype = numpy.dtype(NUMPY_DTYPES[typecode])
    size = field.size

    def to_numpy(value: Any) -> Any:
        result = numpy.array(value, dtype=dtype)
        if result.shape != (size,):
            raise AssertionError(
                f"The '{field.name}' field must hold exactly {size} values, got shape "
                f"{result.shape}"
            )
        return result

    return to_numpy


def make_property(field: FieldSpec, slot: str, descriptor: Any) -> property:
    """``field`` as a property over the slot ``descriptor`` (the class's member descriptor)."""
    check = make_check(field)
    convert = make_convert(field)
    store = descriptor.__set__

    if convert is None:

        def setter(self: Any, value: Any) -> None:
            if self._check_fields:
                check(value)
            store(self, value)
    else:

        def setter(self: Any, value: Any) -> None:
            if self._check_fields:
                check(value)
            store(self, convert(value))

    return property(descriptor.__get__, setter, doc=f"Message field '{field.name}'.")


def make_default(field: FieldSpec) -> Callable[[], Any]:
    """A factory of the field's default value (a new object each call where it is mutable)."""
    primitive = field.primitive
    default = field.default
    if field.container is None:
        if field.message_class is not None:
            return field.message_class
        if default is None:
            default = {"int": 0, "float": 0.0, "bool": False, "str": "", "bytes": b"\x00"}[
                primitive.python  # type: ignore[union-attr]
            ]
        return lambda: default
    if field.is_numeric_container:
        typecode = primitive.typecode  # type: ignore[union-attr]
        if field.container == "sequence":
            values = default or []
            return lambda: array(typecode, values)
        import numpy

        dtype = NUMPY_DTYPES[typecode]
        if default is None:
            size = field.size
            return lambda: numpy.zeros(size, dtype=dtype)
        return lambda: numpy.array(default, dtype=dtype)
    if field.container == "sequence":
        values = default or []
        return lambda: list(values)
    if default is not None:
        return lambda: list(default)
    element = make_default(
        FieldSpec(field.name, field.written_type, field.base, None, None, field.string_bound,
                  None, field.message_class)
    )  # fmt: skip
    count = field.size or 0
    return lambda: [element() for _ in range(count)]
