"""ROS 2 command-line arguments, parsed as rcl parses them (ros2/rcl src/rcl/arguments.c).

    node.py --ros-args -p speed:=0.2 -r cmd_vel:=/robot/cmd_vel --params-file p.yaml \
            -r __node:=driver -r __ns:=/robot1 --log-level debug -- user args

- ROS arguments sit between `--ros-args` and `--` (or the end); everything else is the
  program's own (`rclpy.utilities.remove_ros_args` returns those).
- `-p [node:]name:=value`: a parameter override, the value typed as YAML (`1` int, `0.5` float,
  `true` bool, `[1, 2]` an integer array, anything else a string).
- `-r [node:]from:=to`: a remapping (sandbox.ros2_names.RemapRule); a bare `from:=to` outside
  `--ros-args` still counts, with rcl's deprecation warning.
- `--params-file FILE`: a YAML file `node_name: {ros__parameters: {...}}` (`/**` for every
  node, `/ns/node`, `/**/node`); nested keys become dotted names (`pid.kp`).
- `--log-level [logger:=]LEVEL`.
- Anything else inside `--ros-args` is unknown: rclpy raises UnknownROSArgsError listing them.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from sandbox.ros2_names import RemapRule, Ros2NameError

ROS_ARGS = "--ros-args"
END = "--"
_FLAGS_WITH_VALUE = {"-e", "--enclave", "--log-config-file", "--log-file-name"}
_SWITCHES = {
    f"--{way}-{what}"
    for way in ("enable", "disable")
    for what in ("stdout-logs", "rosout-logs", "external-lib-logs")
}
LOG_LEVELS = ("debug", "info", "warn", "error", "fatal", "unset")
ALL_NODES = "/**"


class RosArgumentError(ValueError):
    """A ROS argument that cannot be used; the message says which and why."""


def parse_value(text: str) -> Any:
    """A parameter value as rcl types it (YAML)."""
    import yaml  # lazy: only nodes given parameters on their command line pay for it

    from sandbox import bounded_yaml

    try:
        return bounded_yaml.load(text)
    except yaml.YAMLError as error:
        raise RosArgumentError(f"cannot read the value '{text}' as YAML: {error}") from None


def flatten(parameters: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """{"pid": {"kp": 1}} -> {"pid.kp": 1}: nested parameter names are dotted in ROS 2."""
    flat: dict[str, Any] = {}
    for key, value in parameters.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            flat.update(flatten(value, name + "."))
        else:
            flat[name] = value
    return flat


@dataclass
class RosArguments:
    """What one command line says to ROS (rcl_arguments_t)."""

    remaps: list[RemapRule] = field(default_factory=list)
    # node pattern ("/**", "name", "/ns/name") -> parameter name -> value, in the order given
    parameters: list[tuple[str, dict[str, Any]]] = field(default_factory=list)
    log_levels: dict[str, str] = field(default_factory=dict)  # "" is the default level
    unknown: list[str] = field(default_factory=list)
    program_args: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def parameters_for(self, node_name: str, namespace: str) -> dict[str, Any]:
        """The overrides that apply to node `namespace/node_name`; later ones win."""
        full = namespace.rstrip("/") + "/" + node_name
        found: dict[str, Any] = {}
        for pattern, values in self.parameters:
            if node_matches(pattern, node_name, full):
                found.update(values)
        return found


def node_matches(pattern: str, node_name: str, full_name: str) -> bool:
    """A parameters-file key against a node (rcl's wildcards): `/**` every node, `name`,
    `/ns/name`, `/**/name` that name in any namespace, `/*/name` in a namespace one deep."""
    pattern = pattern.strip()
    if "/" not in pattern:
        return pattern == node_name
    if not pattern.startswith("/"):
        pattern = "/" + pattern
    regex = ""
    for token in pattern.strip("/").split("/"):
        if token == "**":
            regex += "(/[^/]+)*"
        else:
            regex += "/" + re.escape(token).replace(r"\*", "[^/]*")
    return re.fullmatch(regex, full_name) is not None


def load_params_file(path: str) -> list[tuple[str, dict[str, Any]]]:
    """A ROS 2 parameters file: `node: {ros__parameters: {...}}` per node pattern."""
    import yaml

    from sandbox import bounded_yaml

    if not os.path.exists(path):
        raise RosArgumentError(
            f"--params-file {path}: no such file in the workspace (paths are relative to it)"
        )
    try:
        with open(path, encoding="utf-8") as stream:
            document = bounded_yaml.load(stream.read())
    except yaml.YAMLError as error:
        raise RosArgumentError(f"--params-file {path}: not valid YAML: {error}") from None
    if not isinstance(document, Mapping):
        raise RosArgumentError(
            f"--params-file {path}: expected `node_name: {{ros__parameters: {{...}}}}` at the top"
        )
    found: list[tuple[str, dict[str, Any]]] = []
    _collect_nodes(document, "", path, found)
    return found


def _collect_nodes(
    document: Mapping[str, Any], prefix: str, path: str, found: list[tuple[str, dict[str, Any]]]
) -> None:
    for key, value in document.items():
        if not isinstance(value, Mapping):
            raise RosArgumentError(
                f"--params-file {path}: '{prefix}{key}' holds a value where a node name with "
                "ros__parameters under it was expected"
            )
        if "ros__parameters" in value:
            parameters = value["ros__parameters"]
            if not isinstance(parameters, Mapping):
                raise RosArgumentError(
                    f"--params-file {path}: ros__parameters of '{prefix}{key}' is not a mapping"
                )
            found.append((prefix + str(key), flatten(parameters)))
        else:  # a namespace level: /ns: {node: {ros__parameters: ...}}
            _collect_nodes(value, f"{prefix}{str(key).rstrip('/')}/", path, found)


def parse(argv: Iterable[str]) -> RosArguments:
    """Parse a whole command line (without the program name) as rcl_parse_arguments does."""
    result = RosArguments()
    args = list(argv)
    inside = False
    index = 0
    while index < len(args):
        arg = args[index]
        if not inside:
            if arg == ROS_ARGS:
                inside = True
            elif _is_remap_rule(arg):
                result.remaps.append(_remap(arg))
                result.warnings.append(
                    f"Found remap rule '{arg}'. This syntax is deprecated. Use "
                    f"'{ROS_ARGS} -r {arg}' instead."
                )
            else:
                result.program_args.append(arg)
            index += 1
            continue
        following = args[index + 1] if index + 1 < len(args) else None
        if arg == ROS_ARGS:
            index += 1
        elif arg == END:
            inside = False
            index += 1
        elif arg in ("-p", "--param") and following is not None:
            result.parameters.append(_param_rule(following))
            index += 2
        elif arg in ("-r", "--remap") and following is not None:
            result.remaps.append(_remap(following))
            index += 2
        elif arg == "--params-file" and following is not None:
            result.parameters.extend(load_params_file(following))
            index += 2
        elif arg == "--log-level" and following is not None:
            logger, _, level = following.rpartition(":=")
            if level.lower() not in LOG_LEVELS:
                raise RosArgumentError(
                    f"--log-level {following}: the level is one of {', '.join(LOG_LEVELS)}"
                )
            result.log_levels[logger] = level.lower()
            index += 2
        elif arg in _FLAGS_WITH_VALUE and following is not None:
            index += 2
        elif arg in _SWITCHES:
            index += 1
        else:
            result.unknown.append(arg)
            index += 1
    return result


def _is_remap_rule(arg: str) -> bool:
    try:
        RemapRule.parse(arg)
    except (ValueError, Ros2NameError):
        return False
    return True


def _remap(text: str) -> RemapRule:
    try:
        return RemapRule.parse(text)
    except Ros2NameError as error:
        raise RosArgumentError(f"-r {text}: {error}") from None
    except ValueError as error:
        raise RosArgumentError(str(error)) from None


def _param_rule(text: str) -> tuple[str, dict[str, Any]]:
    source, separator, value = text.partition(":=")
    if not separator or not source:
        raise RosArgumentError(
            f"-p {text}: a parameter is given as NAME:=VALUE, e.g. -p speed:=0.2"
        )
    node, _, name = source.rpartition(":")
    return (node or ALL_NODES, {name: parse_value(value)})


def remove_ros_args(argv: Iterable[str]) -> list[str]:
    """The arguments that are not ROS's (rclpy.utilities.remove_ros_args): every
    `--ros-args ... [--]` section goes, and so do bare `from:=to` rules."""
    kept: list[str] = []
    inside = False
    for arg in argv:
        if arg == ROS_ARGS:
            inside = True
        elif inside:
            if arg == END:
                inside = False
        elif not _is_remap_rule(arg):
            kept.append(arg)
    return kept
