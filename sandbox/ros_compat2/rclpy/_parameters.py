"""A node's parameters, declared, typed and set as rclpy/node.py does it.

- declare_parameter(name, value, descriptor): the override for `name` (from the command line,
  a params file, the launch file, or parameter_overrides) wins over `value`; the type is the
  value's (statically typed) unless the descriptor says dynamic_typing; a second declaration
  raises ParameterAlreadyDeclaredException; an override of another type raises
  InvalidParameterTypeException ("Trying to set parameter 'speed' to '1' of type 'INTEGER',
  expecting type 'DOUBLE'", the message every ROS 2 course meets once).
- get_parameter of an undeclared name raises ParameterNotDeclaredException unless the node
  allows undeclared parameters; a statically typed parameter declared without a value raises
  ParameterUninitializedException.
- set_parameters runs the pre-set, on-set (which may refuse with SetParametersResult) and
  post-set callbacks and applies descriptors (read_only, integer and floating point ranges).

Left out: the /parameter_events topic and the parameter services (nothing in a run calls them).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from .exceptions import (
    InvalidParameterException,
    InvalidParameterTypeException,
    InvalidParameterValueException,
    ParameterAlreadyDeclaredException,
    ParameterImmutableException,
    ParameterNotDeclaredException,
    ParameterUninitializedException,
)
from .parameter import PARAMETER_SEPARATOR_STRING, Parameter

if TYPE_CHECKING:
    from .node import Node

PARAM_REL_TOL = 1e-6  # rclpy's Node.PARAM_REL_TOL for floating point ranges


@dataclass
class _Result:
    """SetParametersResult's fields (the message class is made at the API's edge)."""

    successful: bool
    reason: str = ""


@dataclass
class _Descriptor:
    """rcl_interfaces/msg/ParameterDescriptor's fields."""

    name: str = ""
    type: int = 0
    description: str = ""
    additional_constraints: str = ""
    read_only: bool = False
    dynamic_typing: bool = False
    floating_point_range: list[Any] = field(default_factory=list)
    integer_range: list[Any] = field(default_factory=list)

    @classmethod
    def from_msg(cls, msg: Any) -> _Descriptor:
        if isinstance(msg, _Descriptor):
            return msg
        if not hasattr(msg, "dynamic_typing"):
            raise TypeError(
                f"a parameter descriptor is an rcl_interfaces.msg.ParameterDescriptor, got "
                f"{type(msg).__name__}"
            )
        return cls(
            name=msg.name,
            type=msg.type,
            description=msg.description,
            additional_constraints=msg.additional_constraints,
            read_only=msg.read_only,
            dynamic_typing=msg.dynamic_typing,
            floating_point_range=list(msg.floating_point_range),
            integer_range=list(msg.integer_range),
        )

    def to_msg(self) -> Any:
        from rcl_interfaces.msg import ParameterDescriptor

        return ParameterDescriptor(
            name=self.name,
            type=self.type,
            description=self.description,
            additional_constraints=self.additional_constraints,
            read_only=self.read_only,
            dynamic_typing=self.dynamic_typing,
            floating_point_range=list(self.floating_point_range),
            integer_range=list(self.integer_range),
        )


def set_parameters_result(result: Any) -> Any:
    from rcl_interfaces.msg import SetParametersResult

    return SetParametersResult(successful=result.successful, reason=result.reason)


def validate_parameter_name(name: str) -> None:
    """rclpy.validate_parameter_name: any non-empty string will do."""
    if not isinstance(name, str):
        raise TypeError("parameter name must be a string")
    if not name:
        raise InvalidParameterException(name)


class ParameterStore:
    """The parameters of one node."""

    def __init__(self, node: Node, overrides: dict[str, Any], allow_undeclared: bool) -> None:
        self._node = node
        self._parameters: dict[str, Parameter] = {}
        self._descriptors: dict[str, _Descriptor] = {}
        self._allow_undeclared = allow_undeclared
        self.overrides: dict[str, Parameter] = {}
        for name, value in overrides.items():
            try:
                self.overrides[name] = Parameter(name, value=value)
            except TypeError as error:
                raise ValueError(f"the value given for parameter '{name}': {error}") from None
        self.pre_set: list[Any] = []
        self.on_set: list[Any] = []
        self.post_set: list[Any] = []

    def add_overrides(self, parameters: list[Parameter]) -> None:
        for parameter in parameters:
            if not isinstance(parameter, Parameter):
                raise TypeError(
                    "parameter_overrides is a list of rclpy.parameter.Parameter, got "
                    f"{type(parameter).__name__}"
                )
            self.overrides[parameter.name] = parameter

    def declare_overrides(self) -> None:
        self.declare_parameters(
            "",
            [(name, parameter.value, _Descriptor()) for name, parameter in self.overrides.items()],
            ignore_override=True,
        )

    def declare_builtin(self, name: str, value: Any) -> None:
        self.declare_parameters("", [(name, value, _Descriptor())])

    # ------------------------------------------------------------------ declaring
    def declare_parameter(
        self, name: str, value: Any, descriptor: Any, ignore_override: bool
    ) -> Parameter:
        if value is None and descriptor is None:
            args: tuple[Any, ...] = (name,)
        else:
            args = (name, value, _Descriptor() if descriptor is None else descriptor)
        return self.declare_parameters("", [args], ignore_override)[0]

    def declare_parameters(
        self, namespace: str, parameters: list[tuple[Any, ...]], ignore_override: bool = False
    ) -> list[Parameter]:
        parameter_list: list[Parameter] = []
        descriptors: dict[str, _Descriptor] = {}
        for index, parameter_tuple in enumerate(parameters):
            if not isinstance(parameter_tuple, tuple) or not 1 <= len(parameter_tuple) <= 3:
                raise TypeError(
                    f"Invalid parameter tuple length at index {index} in parameters list: "
                    f"{parameter_tuple}; expecting length between 1 and 3"
                )
            name = parameter_tuple[0]
            if not isinstance(name, str):
                raise TypeError(
                    f"First element {name} at index {index} in parameters list is not a str."
                )
            if namespace:
                name = f"{namespace}.{name}"
            validate_parameter_name(name)
            second = parameter_tuple[1] if len(parameter_tuple) > 1 else None
            raw_descriptor = parameter_tuple[2] if len(parameter_tuple) > 2 else _Descriptor()
            try:
                descriptor = _Descriptor.from_msg(raw_descriptor)
            except TypeError:
                raise TypeError(
                    f"Third element {raw_descriptor} at index {index} in parameters list is not "
                    "a ParameterDescriptor."
                ) from None
            descriptor = _Descriptor(**vars(descriptor))  # the caller's object stays theirs
            if len(parameter_tuple) == 1:
                warnings.warn(
                    f"when declaring parameter named '{name}', declaring a parameter only "
                    "providing its name is deprecated. You have to either:\n\t- Pass a name and "
                    'a default value different to "PARAMETER NOT SET" (and optionally a '
                    "descriptor).\n\t- Pass a name and a parameter type.\n\t- Pass a name and a "
                    "descriptor with `dynamic_typing=True`",
                    stacklevel=4,
                )
                descriptor.dynamic_typing = True
            value = None
            if isinstance(second, Parameter.Type):
                if second == Parameter.Type.NOT_SET:
                    raise ValueError(
                        f"Cannot declare parameter {{{name}}} as statically typed of type NOT_SET"
                    )
                if descriptor.dynamic_typing:
                    raise ValueError(
                        f"When declaring parameter {{{name}}} passing a descriptor with"
                        "`dynamic_typing=True` is not allowed when the parameter type is provided"
                    )
                descriptor.type = second.value
            else:
                value = second
                if not descriptor.dynamic_typing:
                    descriptor.type = Parameter.Type.from_parameter_value(value).value
                    if descriptor.type == Parameter.Type.NOT_SET:
                        raise ValueError(
                            "Cannot declare a statically typed parameter with default value of "
                            "type PARAMETER_NOT_SET"
                        )
            if not ignore_override and name in self.overrides:
                value = self.overrides[name].value
            parameter_list.append(Parameter(name, value=value))
            descriptors[name] = descriptor
        already = [p.name for p in parameter_list if p.name in self._parameters]
        if already:
            raise ParameterAlreadyDeclaredException(already)
        for parameter in parameter_list:
            result = self._set_atomically_common([parameter], descriptors, allow_not_set_type=True)
            if not result.successful:
                if result.reason.startswith("Wrong parameter type"):
                    raise InvalidParameterTypeException(
                        parameter, Parameter.Type(descriptors[parameter.name].type).name
                    )
                raise InvalidParameterValueException(parameter.name, parameter.value, result.reason)
        return [self._parameters[p.name] for p in parameter_list]

    def undeclare(self, name: str) -> None:
        if not self.has(name):
            raise ParameterNotDeclaredException(name)
        if self._descriptors[name].read_only:
            raise ParameterImmutableException(name)
        del self._parameters[name]
        del self._descriptors[name]

    # ------------------------------------------------------------------ reading
    def has(self, name: str) -> bool:
        return name in self._parameters

    def get(self, name: str) -> Parameter:
        if self.has(name):
            parameter = self._parameters[name]
            if parameter.type_ != Parameter.Type.NOT_SET or self._descriptors[name].dynamic_typing:
                return parameter
            raise ParameterUninitializedException(name)
        if self._allow_undeclared:
            return Parameter(name, Parameter.Type.NOT_SET, None)
        raise ParameterNotDeclaredException(name)

    def get_or(self, name: str, alternative: Parameter | None) -> Parameter:
        if alternative is None:
            alternative = Parameter(name, Parameter.Type.NOT_SET)
        if not self.has(name) or self._parameters[name].type_ == Parameter.Type.NOT_SET:
            return alternative
        return self._parameters[name]

    def by_prefix(self, prefix: str) -> dict[str, Parameter]:
        if prefix:
            prefix = prefix + PARAMETER_SEPARATOR_STRING
        return {
            name[len(prefix) :]: value
            for name, value in self._parameters.items()
            if name.startswith(prefix)
        }

    def type_of(self, name: str) -> Parameter.Type:
        if not isinstance(name, str):
            raise TypeError("All names must be instances of type str")
        if self.has(name):
            return self._parameters[name].type_
        if self._allow_undeclared:
            return Parameter.Type.NOT_SET
        raise ParameterNotDeclaredException(name)

    def describe(self, name: str) -> Any:
        if name in self._descriptors:
            return self._descriptors[name].to_msg()
        if self._allow_undeclared:
            return _Descriptor(name=name).to_msg()
        raise ParameterNotDeclaredException(name)

    def set_descriptor(self, name: str, descriptor: Any, alternative_value: Any = None) -> Any:
        if not self.has(name):
            if not self._allow_undeclared:
                raise ParameterNotDeclaredException(name)
            return self.get(name).get_parameter_value()
        if self._descriptors[name].read_only:
            raise ParameterImmutableException(name)
        current = self._parameters[name]
        new = _Descriptor(**vars(_Descriptor.from_msg(descriptor)))
        new.name = name
        if alternative_value is None:
            alternative = current
        else:
            alternative = Parameter(name, value=alternative_value)
        if new.dynamic_typing:
            new.type = alternative.type_.value
        elif alternative.type_.value != new.type:
            raise InvalidParameterValueException(
                name,
                alternative.value,
                "Wrong parameter type, expected "
                f"'{Parameter.Type(new.type)}' got '{alternative.type_}'",
            )
        if alternative.value != current.value:
            result = self._apply_descriptor(alternative, new, check_read_only=False)
            if not result.successful:
                raise InvalidParameterValueException(name, alternative.value, result.reason)
            self._parameters[name] = alternative
        self._descriptors[name] = new
        return self._parameters[name].get_parameter_value()

    def list_parameters(self, prefixes: list[str], depth: int) -> Any:
        from rcl_interfaces.msg import ListParametersResult

        if not isinstance(prefixes, list):
            raise TypeError("The prefixes argument must be a list")
        if not all(isinstance(prefix, str) for prefix in prefixes):
            raise TypeError("All prefixes must be instances of type str")
        if not isinstance(depth, int):
            raise TypeError("The depth must be instance of type int")
        if depth < 0:
            raise ValueError("The depth must be greater than or equal to zero")
        result = ListParametersResult()
        recursive = not prefixes and depth == 0  # ListParameters DEPTH_RECURSIVE

        def shallow(name: str) -> bool:
            return name.count(PARAMETER_SEPARATOR_STRING) < depth

        names: list[str] = []
        found_prefixes: list[str] = []
        for name in self._parameters:
            if (
                not recursive
                and not (not prefixes and shallow(name))
                and not any(
                    name == prefix
                    or (
                        name.startswith(prefix + PARAMETER_SEPARATOR_STRING)
                        and (depth == 0 or shallow(name[len(prefix) + 1 :]))
                    )
                    for prefix in prefixes
                )
            ):
                continue
            names.append(name)
            if PARAMETER_SEPARATOR_STRING in name:
                found = name.rsplit(PARAMETER_SEPARATOR_STRING, 1)[0]
                if found not in found_prefixes:
                    found_prefixes.append(found)
        result.names = names
        result.prefixes = found_prefixes
        return result

    # ------------------------------------------------------------------ setting
    def set_parameters(self, parameter_list: list[Parameter]) -> list[Any]:
        return [self.set_atomically([parameter]) for parameter in parameter_list]

    def set_atomically(self, parameter_list: list[Parameter]) -> Any:
        if self.pre_set:
            modified: list[Parameter] = []
            for callback in self.pre_set:
                modified.extend(callback(parameter_list))
            parameter_list = modified
            if not parameter_list:
                return set_parameters_result(
                    _Result(
                        False,
                        "parameter list cannot be empty, this might be due to "
                        "pre_set_parameters_callback modifying the original parameters list.",
                    )
                )
        if not all(isinstance(parameter, Parameter) for parameter in parameter_list):
            raise TypeError(f"parameter must be instance of type '{Parameter!r}'")
        undeclared = [p.name for p in parameter_list if p.name not in self._parameters]
        if not self._allow_undeclared and undeclared:
            raise ParameterNotDeclaredException(undeclared)
        return set_parameters_result(self._set_atomically_common(parameter_list))

    def _set_atomically_common(
        self,
        parameter_list: list[Parameter],
        descriptors: dict[str, _Descriptor] | None = None,
        allow_not_set_type: bool = False,
    ) -> _Result:
        if descriptors is not None:
            result = self._apply_descriptors(parameter_list, descriptors, False)
        else:
            result = self._apply_descriptors(parameter_list, self._descriptors, True)
        if not result.successful:
            return result
        for callback in self.on_set:
            answer = callback(parameter_list)
            if not hasattr(answer, "successful"):
                raise TypeError(
                    "a parameters callback returns rcl_interfaces.msg.SetParametersResult("
                    f"successful=..., reason=...), got {answer!r}"
                )
            if not answer.successful:
                return _Result(False, answer.reason)
        for parameter in parameter_list:
            if not allow_not_set_type and parameter.type_ == Parameter.Type.NOT_SET:
                self._parameters.pop(parameter.name, None)
                self._descriptors.pop(parameter.name, None)
                continue
            if descriptors is not None:
                self._descriptors[parameter.name] = descriptors[parameter.name]
            elif parameter.name not in self._descriptors:
                self._descriptors[parameter.name] = _Descriptor(dynamic_typing=True)
            self._parameters[parameter.name] = parameter
            if parameter.name == "use_sim_time" and parameter.type_ == Parameter.Type.BOOL:
                self._node._clock._set_ros_time_is_active(parameter.value)
        for callback in self.post_set:
            callback(parameter_list)
        return _Result(True)

    def _apply_descriptors(
        self,
        parameter_list: list[Parameter],
        descriptors: dict[str, _Descriptor],
        check_read_only: bool,
    ) -> _Result:
        for parameter in parameter_list:
            if parameter.name in descriptors:
                result = self._apply_descriptor(
                    parameter, descriptors[parameter.name], check_read_only
                )
                if not result.successful:
                    return result
        return _Result(True)

    def _apply_descriptor(
        self, parameter: Parameter, descriptor: _Descriptor, check_read_only: bool
    ) -> _Result:
        descriptor.name = parameter.name
        if check_read_only and descriptor.read_only:
            return _Result(False, f"Trying to set a read-only parameter: {parameter.name}.")
        if descriptor.dynamic_typing:
            descriptor.type = parameter.type_.value
        elif self.has(parameter.name) and parameter.type_ == Parameter.Type.NOT_SET:
            return _Result(False, "Static parameter cannot be undeclared")
        elif parameter.type_ != Parameter.Type.NOT_SET and parameter.type_.value != descriptor.type:
            return _Result(
                False,
                f"Wrong parameter type, expected '{Parameter.Type(descriptor.type)}' got "
                f"'{parameter.type_}'",
            )
        if parameter.type_ == Parameter.Type.INTEGER and descriptor.integer_range:
            return _integer_range(parameter, descriptor.integer_range[0])
        if parameter.type_ == Parameter.Type.DOUBLE and descriptor.floating_point_range:
            return _floating_point_range(parameter, descriptor.floating_point_range[0])
        return _Result(True)


def _integer_range(parameter: Parameter, integer_range: Any) -> _Result:
    low = min(integer_range.from_value, integer_range.to_value)
    high = max(integer_range.from_value, integer_range.to_value)
    value = parameter.value
    if value in (low, high):
        return _Result(True)
    if not low < value < high:
        return _Result(
            False,
            f"Parameter {parameter.name} out of range. Min: {low}, Max: {high}, value: {value}",
        )
    if integer_range.step != 0 and (value - low) % integer_range.step != 0:
        return _Result(
            False,
            f"The parameter value for {parameter.name} is not a valid step. Min: {low}, max: "
            f"{high}, value: {value}, step: {integer_range.step}",
        )
    return _Result(True)


def _floating_point_range(parameter: Parameter, floating_range: Any) -> _Result:
    low = min(floating_range.from_value, floating_range.to_value)
    high = max(floating_range.from_value, floating_range.to_value)
    value = parameter.value
    if math.isclose(value, low, rel_tol=PARAM_REL_TOL) or math.isclose(
        value, high, rel_tol=PARAM_REL_TOL
    ):
        return _Result(True)
    if not low < value < high:
        return _Result(
            False,
            f"Parameter {parameter.name} out of range Min: {low}, Max: {high}, value: {value}",
        )
    if floating_range.step != 0.0:
        steps = round((value - low) / floating_range.step)
        if not math.isclose(low + steps * floating_range.step, value, rel_tol=PARAM_REL_TOL):
            return _Result(
                False,
                f"The parameter value for {parameter.name} is not close enough to a valid step. "
                f"Min: {low}, max: {high}, value: {value}, step: {floating_range.step}",
            )
    return _Result(True)
