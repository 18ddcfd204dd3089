"""rclpy.parameter: Parameter, Parameter.Type and the value conversions (rclpy/parameter.py).

Types are inferred from Python values as rclpy infers them: bool before int (a bool is an
int in Python), int is INTEGER and float is DOUBLE (so 1 is not a valid DOUBLE), lists by
their items. The type numbers are rcl_interfaces/msg/ParameterType's.
"""

from __future__ import annotations

import array
from enum import IntEnum
from typing import Any

import yaml

PARAMETER_SEPARATOR_STRING = "."


class Parameter:
    """A named, typed value of a node."""

    class Type(IntEnum):
        NOT_SET = 0
        BOOL = 1
        INTEGER = 2
        DOUBLE = 3
        STRING = 4
        BYTE_ARRAY = 5
        BOOL_ARRAY = 6
        INTEGER_ARRAY = 7
        DOUBLE_ARRAY = 8
        STRING_ARRAY = 9

        @classmethod
        def from_parameter_value(cls, parameter_value: Any) -> Parameter.Type:
            if parameter_value is None:
                return cls.NOT_SET
            if isinstance(parameter_value, bool):
                return cls.BOOL
            if isinstance(parameter_value, int):
                return cls.INTEGER
            if isinstance(parameter_value, float):
                return cls.DOUBLE
            if isinstance(parameter_value, str):
                return cls.STRING
            if isinstance(parameter_value, list | tuple | array.array):
                if all(isinstance(v, bytes) for v in parameter_value):
                    return cls.BYTE_ARRAY
                if all(isinstance(v, bool) for v in parameter_value):
                    return cls.BOOL_ARRAY
                if all(isinstance(v, int) for v in parameter_value):
                    return cls.INTEGER_ARRAY
                if all(isinstance(v, float) for v in parameter_value):
                    return cls.DOUBLE_ARRAY
                if all(isinstance(v, str) for v in parameter_value):
                    return cls.STRING_ARRAY
                raise TypeError(
                    "The given value is not a list of one of the allowed types "
                    f"'{parameter_value}'."
                )
            raise TypeError(f"The given value is not one of the allowed types '{parameter_value}'.")

        def check(self, parameter_value: Any) -> bool:
            kind = Parameter.Type
            if self == kind.NOT_SET:
                return parameter_value is None
            if self == kind.BOOL:
                return isinstance(parameter_value, bool)
            if self == kind.INTEGER:
                return isinstance(parameter_value, int)
            if self == kind.DOUBLE:
                return isinstance(parameter_value, float)
            if self == kind.STRING:
                return isinstance(parameter_value, str)
            if self == kind.BYTE_ARRAY:
                return isinstance(parameter_value, list | tuple) and all(
                    isinstance(v, bytes) and len(v) == 1 for v in parameter_value
                )
            if self == kind.BOOL_ARRAY:
                return isinstance(parameter_value, list | tuple) and all(
                    isinstance(v, bool) for v in parameter_value
                )
            if self == kind.INTEGER_ARRAY:
                return isinstance(parameter_value, list | tuple | array.array) and all(
                    isinstance(v, int) for v in parameter_value
                )
            if self == kind.DOUBLE_ARRAY:
                return isinstance(parameter_value, list | tuple | array.array) and all(
                    isinstance(v, float) for v in parameter_value
                )
            if self == kind.STRING_ARRAY:
                return isinstance(parameter_value, list | tuple) and all(
                    isinstance(v, str) for v in parameter_value
                )
            return False

    def __init__(self, name: str, type_: Parameter.Type | None = None, value: Any = None) -> None:
        if type_ is None:
            type_ = Parameter.Type.from_parameter_value(value)
        if not isinstance(type_, Parameter.Type):
            raise TypeError(f"type must be an instance of '{Parameter.Type!r}'")
        if not type_.check(value):
            raise ValueError(f"Type '{type_}' and value '{value}' do not agree")
        self._type_ = type_
        self._name = name
        self._value = value

    @classmethod
    def from_parameter_msg(cls, param_msg: Any) -> Parameter:
        type_ = Parameter.Type(param_msg.value.type)
        return cls(param_msg.name, type_, parameter_value_to_python(param_msg.value))

    @property
    def name(self) -> str:
        return self._name

    @property
    def type_(self) -> Parameter.Type:
        return self._type_

    @property
    def value(self) -> Any:
        return self._value

    def __repr__(self) -> str:
        return f"Parameter(name={self._name!r}, type_={self._type_.name}, value={self._value!r})"

    def get_parameter_value(self) -> Any:
        """As an rcl_interfaces/msg/ParameterValue."""
        from rcl_interfaces.msg import ParameterValue

        parameter_value = ParameterValue(type=self._type_.value)
        field = _VALUE_FIELDS.get(self._type_)
        if field is not None:
            value = self._value
            if self._type_ in _ARRAY_TYPES:
                value = list(value)
            setattr(parameter_value, field, value)
        return parameter_value

    def to_parameter_msg(self) -> Any:
        from rcl_interfaces.msg import Parameter as ParameterMsg

        return ParameterMsg(name=self.name, value=self.get_parameter_value())


_VALUE_FIELDS = {
    Parameter.Type.BOOL: "bool_value",
    Parameter.Type.INTEGER: "integer_value",
    Parameter.Type.DOUBLE: "double_value",
    Parameter.Type.STRING: "string_value",
    Parameter.Type.BYTE_ARRAY: "byte_array_value",
    Parameter.Type.BOOL_ARRAY: "bool_array_value",
    Parameter.Type.INTEGER_ARRAY: "integer_array_value",
    Parameter.Type.DOUBLE_ARRAY: "double_array_value",
    Parameter.Type.STRING_ARRAY: "string_array_value",
}
_ARRAY_TYPES = {
    Parameter.Type.BYTE_ARRAY,
    Parameter.Type.BOOL_ARRAY,
    Parameter.Type.INTEGER_ARRAY,
    Parameter.Type.DOUBLE_ARRAY,
    Parameter.Type.STRING_ARRAY,
}


def parameter_value_to_python(parameter_value: Any) -> Any:
    """The Python value of an rcl_interfaces/msg/ParameterValue (None when NOT_SET)."""
    kind = Parameter.Type(parameter_value.type) if parameter_value.type in range(10) else None
    if kind is None:
        raise RuntimeError(f"unexpected parameter type {parameter_value.type}")
    if kind == Parameter.Type.NOT_SET:
        return None
    value = getattr(parameter_value, _VALUE_FIELDS[kind])
    return list(value) if kind in _ARRAY_TYPES else value


def get_parameter_value(string_value: str) -> Any:
    """A ParameterValue guessed from text, as `ros2 param set` types it (YAML)."""
    try:
        value = yaml.safe_load(string_value)
    except yaml.YAMLError:
        value = string_value
    try:
        kind = Parameter.Type.from_parameter_value(value)
    except TypeError:
        kind, value = Parameter.Type.STRING, string_value
    if kind == Parameter.Type.NOT_SET:
        kind, value = Parameter.Type.STRING, string_value
    return Parameter("", kind, value).get_parameter_value()
