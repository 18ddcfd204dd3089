"""ROS 2 parameters as a launch file gives them to a node, resolved to the node's own
parameter names (dotted, node-relative: `pid.kp`).

Three sources, in the order launch_ros passes them on the node's command line
(launch_ros/actions/node.py `_perform_substitutions`): SetParameter / SetParametersFromFile
before the node, then the node's `parameters=[...]` in order. A dict is launch_ros's temporary
parameter file: its rule is keyed by the node's full name when the launch gives both name and
namespace, else by the wildcard `/**`; values follow evaluate_parameters.py (a substitution's
text is read as YAML; a plain string stays a string; lists are uniform). A YAML file is rcl's
format (rcl_yaml_param_parser): node names (nested keys are namespaces) down to
`ros__parameters`, nested dictionaries below it become dotted names.

Which rules apply is rcl's and rclpy's (rclpy/src/rclpy/node.cpp
`_populate_node_parameters_from_rcl_params`): all rules are merged by node key as written
(`talker` and `/talker` are two keys), keys kept in the order they first appeared, later values
replacing earlier ones; then every key whose pattern matches the node's fully qualified name
applies, in that order (a key gets a leading `/`; `/*` is one namespace token, `/**` any
number of them)."""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import yaml

from sandbox import bounded_yaml
from sandbox.launch2.context import LaunchContext
from sandbox.launch2.errors import LaunchError, Site, caller_site
from sandbox.launch2.substitutions import Substitution, normalize, perform

MAX_PARAM_FILE_BYTES = 256 * 1024  # [bytes] a parameter file larger than this is not a config
WILDCARD = "/**"
Rule = tuple[str, dict[str, Any]]  # (node key, parameter name -> value)


class ParameterValue:
    """launch_ros.parameter_descriptions.ParameterValue: a value (or substitutions) and the
    type to read it as (None: YAML's rules)."""

    def __init__(self, value: Any, *, value_type: Any = None) -> None:
        self.value, self.value_type = value, value_type
        self.site = caller_site()

    def evaluate(self, context: LaunchContext, name: str) -> Any:
        raw = self.value
        if isinstance(raw, Substitution) or (
            isinstance(raw, list | tuple) and any(isinstance(x, Substitution) for x in raw)
        ):
            raw = perform(context, normalize(raw))
            if self.value_type is str:
                return raw
            raw = _yaml_scalar(raw, name, self.site)
        if self.value_type in (int, float, bool, str) and not isinstance(raw, self.value_type):
            if self.value_type is float and isinstance(raw, int) and not isinstance(raw, bool):
                return float(raw)
            raise LaunchError(
                f"parameter '{name}': {raw!r} is not a {self.value_type.__name__} "
                "(ParameterValue's value_type)",
                self.site,
            )
        return _checked(raw, name, self.site)


class Parameter:
    """launch_ros.parameter_descriptions.Parameter: one name and its value."""

    def __init__(self, name: Any, value: Any, *, value_type: Any = None) -> None:
        self.name = normalize(name, "Parameter's name")
        self.value = ParameterValue(value, value_type=value_type)
        self.site = caller_site()


class ParameterFile:
    """launch_ros.parameter_descriptions.ParameterFile: a YAML file; with allow_substs=True
    its text may hold $(var name) substitutions of launch configurations."""

    def __init__(self, param_file: Any, *, allow_substs: bool = False) -> None:
        self.path = normalize(
            str(param_file) if isinstance(param_file, os.PathLike) else param_file
        )
        self.allow_substs = allow_substs
        self.site = caller_site()


# ------------------------------------------------------------------ dictionaries
def evaluate_dict(
    context: LaunchContext, params: Mapping[Any, Any], site: Site | None, prefix: str = ""
) -> dict[str, Any]:
    """A `parameters=[{...}]` dict -> flat {dotted name: value}."""
    out: dict[str, Any] = {}
    for key, value in params.items():
        name = prefix + perform(context, normalize(key, "a parameter name"))
        if isinstance(value, Mapping):
            out.update(evaluate_dict(context, value, site, name + "."))
        else:
            out[name] = _evaluate_value(context, value, name, site)
    return out


def _evaluate_value(context: LaunchContext, value: Any, name: str, site: Site | None) -> Any:
    if isinstance(value, ParameterValue):
        return value.evaluate(context, name)
    if isinstance(value, Substitution):
        return _yaml_scalar(perform(context, [value]), name, site)
    if isinstance(value, bool | int | float | str):
        return value
    if isinstance(value, Sequence):
        items = list(value)
        if any(isinstance(item, Substitution) for item in items) and all(
            isinstance(item, str | Substitution) for item in items
        ):  # launch_ros: one string built from the pieces, read as YAML
            return _yaml_scalar(perform(context, normalize(items)), name, site)
        performed = [
            perform(context, normalize(item))
            if not isinstance(item, bool | int | float | str)
            else item
            for item in items
        ]
        kinds = {type(item) for item in performed}
        if kinds == {int, float}:
            return [float(item) for item in performed]
        return _checked(performed, name, site)
    raise LaunchError(
        f"parameter '{name}': a {type(value).__name__} cannot be a ROS 2 parameter; use "
        "bool, int, float, str, or a list of one of those",
        site,
    )


def _yaml_scalar(text: str, name: str, site: Site | None) -> Any:
    try:
        value = bounded_yaml.load(text) if text else ""
    except yaml.YAMLError:
        raise LaunchError(
            f"parameter '{name}': '{text}' cannot be read as a value; wrap it in "
            "ParameterValue(..., value_type=str) to keep it a string",
            site,
        ) from None
    if value is None:
        return text
    return _checked(value, name, site)


def _checked(value: Any, name: str, site: Site | None) -> Any:
    """A value a ROS 2 parameter can hold: bool, int, float, str, or a non-empty uniform list
    of one of them (rcl refuses mixed lists); tuples become lists."""
    if isinstance(value, bool | int | float | str | bytes):
        return value
    if isinstance(value, list | tuple):
        items = list(value)
        kinds = {type(item) for item in items}
        if not items or len(kinds) != 1 or not kinds <= {bool, int, float, str}:
            raise LaunchError(
                f"parameter '{name}': {items!r} is not a ROS 2 parameter list; a list holds "
                "one kind of value (all bool, all int, all float or all str) and is not empty",
                site,
            )
        return items
    raise LaunchError(
        f"parameter '{name}': {value!r} (a {type(value).__name__}) cannot be a ROS 2 "
        "parameter; use bool, int, float, str or a list of one of those",
        site,
    )


# ------------------------------------------------------------------ YAML files
def read_param_file(
    context: LaunchContext, path: str, site: Site | None, substitute: bool = False
) -> list[Rule]:
    """The rules of a ROS 2 parameter file of the workspace, in file order."""
    relative = context.relative(path, site, "the parameter file")
    absolute = os.path.join(context.workdir, relative)
    if not os.path.isfile(absolute):
        raise LaunchError(f"the parameter file '{relative}' is not in your workspace", site)
    if os.path.getsize(absolute) > MAX_PARAM_FILE_BYTES:
        raise LaunchError(
            f"the parameter file '{relative}' is larger than {MAX_PARAM_FILE_BYTES // 1024} KiB",
            site,
        )
    with open(absolute, encoding="utf-8", errors="replace") as file:
        text = file.read()
    if substitute:
        text = re.sub(
            r"\$\(var ([A-Za-z0-9_]+)\)",
            lambda match: str(context.launch_configurations.get(match.group(1), match.group(0))),
            text,
        )
    return parse_param_file(text, relative, site)


def parse_param_file(text: str, relative: str, site: Site | None) -> list[Rule]:
    try:
        data = bounded_yaml.load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f", line {mark.line + 1}" if mark is not None else ""
        raise LaunchError(f"{relative}{where} is not valid YAML: {error}", site) from None
    if not isinstance(data, dict):
        raise LaunchError(_shape(relative, "it does not start with node names"), site)
    rules: list[Rule] = []
    _collect(data, "", relative, site, rules)
    if not rules:
        raise LaunchError(_shape(relative, "it has no 'ros__parameters'"), site)
    return rules


def _shape(relative: str, problem: str) -> str:
    return (
        f"{relative} is not a ROS 2 parameter file ({problem}); it reads "
        "`node_name:` then `ros__parameters:` then `name: value` lines (`/**:` for every node)"
    )


def _collect(
    data: dict[Any, Any], prefix: str, relative: str, site: Site | None, rules: list[Rule]
) -> None:
    for key, value in data.items():
        key = str(key)
        if key == "ros__parameters":
            if not prefix:
                raise LaunchError(
                    _shape(relative, "'ros__parameters' needs a node name above it"), site
                )
            if not isinstance(value, dict):
                raise LaunchError(
                    f"{relative}: '{prefix}' ros__parameters must hold `name: value` lines",
                    site,
                )
            rules.append((prefix, _flatten(value, "", relative, site)))
        elif isinstance(value, dict):
            _collect(value, f"{prefix}/{key.strip('/')}" if prefix else key, relative, site, rules)
        else:
            raise LaunchError(
                _shape(
                    relative,
                    f"'{key}' holds a value where a node name or 'ros__parameters' was expected",
                ),
                site,
            )


def _flatten(params: dict[Any, Any], prefix: str, relative: str, site: Site | None) -> dict:
    out: dict[str, Any] = {}
    for key, value in params.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(_flatten(value, name + ".", relative, site))
        elif value is None:
            raise LaunchError(f"{relative}: parameter '{name}' has no value", site)
        else:
            out[name] = _checked(value, name, site)
    return out


# ------------------------------------------------------------------ matching
def node_key_matches(key: str, fqn: str) -> bool:
    """rclpy's rule: `/*` stands for one namespace token, `/**` for any number of them."""
    key = key if key.startswith("/") else "/" + key
    pattern = key.replace("/*", "(/\\w+)")
    try:
        return re.fullmatch(pattern, fqn) is not None
    except re.error:
        return False


@dataclass
class Resolved:
    params: dict[str, Any]
    unmatched: list[str]  # keys naming a node whose name is unknown (notes for the student)


def resolve(rules: list[Rule], fqn: str | None) -> Resolved:
    """The parameters a node with fully qualified name `fqn` gets from `rules`; with `fqn`
    None (the node's name is unknown) only wildcard keys that match any name apply."""
    merged: dict[str, dict[str, Any]] = {}
    for key, params in rules:
        merged.setdefault(key, {}).update(params)
    out: dict[str, Any] = {}
    unmatched: list[str] = []
    for key, params in merged.items():
        if fqn is not None:
            if node_key_matches(key, fqn):
                out.update(params)
        elif key == WILDCARD:
            out.update(params)
        else:
            unmatched.append(key)
    return Resolved(out, unmatched)
