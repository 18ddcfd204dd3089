"""launch's substitutions (launch/substitutions/*.py, launch_ros/substitutions/*.py): text
that is only known once the description is visited, with the arguments it was given.

What a run cannot do is refused with a sentence when performed: `Command` and `FindExecutable`
run programs (xacro, mostly: the robot's description comes from the run), `EnvironmentVariable`
without a default reads a shell environment a run does not have."""

from __future__ import annotations

import hashlib
import math
import os
from collections.abc import Iterable
from typing import Any

from sandbox.launch2.context import LaunchContext
from sandbox.launch2.errors import LaunchError, SubstitutionFailure, caller_site


class Substitution:
    """launch.Substitution: `perform(context) -> str`."""

    def __init__(self) -> None:
        self.site = caller_site()

    def perform(self, context: LaunchContext) -> str:
        raise NotImplementedError

    def describe(self) -> str:
        return type(self).__name__

    def __repr__(self) -> str:
        return f"<{self.describe()}>"


SomeSubstitutions = str | Substitution | Iterable[str | Substitution]


def normalize(value: Any, what: str = "value") -> list[Substitution]:
    """launch.utilities.normalize_to_list_of_substitutions, with a sentence for a number
    (ros2 launch raises TypeError: launch arguments and their defaults are text)."""
    if isinstance(value, str):
        return [TextSubstitution(text=value)]
    if isinstance(value, Substitution):
        return [value]
    if isinstance(value, bool | int | float) or value is None:
        raise LaunchError(
            f"{what} must be text or substitutions, got {value!r}; write it as a string "
            f"('{value}'): launch arguments and configurations are text"
        )
    try:
        items = list(value)
    except TypeError:
        raise LaunchError(
            f"{what} must be text or substitutions, got a {type(value).__name__}"
        ) from None
    out: list[Substitution] = []
    for item in items:
        if isinstance(item, str):
            out.append(TextSubstitution(text=item))
        elif isinstance(item, Substitution):
            out.append(item)
        else:
            raise LaunchError(
                f"{what} must be text or substitutions; the list holds {item!r} "
                f"(a {type(item).__name__})"
            )
    return out


def perform(context: LaunchContext, substitutions: list[Substitution]) -> str:
    return "".join(item.perform(context) for item in substitutions)


def perform_value(context: LaunchContext, value: Any, what: str = "value") -> str:
    return perform(context, normalize(value, what))


class TextSubstitution(Substitution):
    def __init__(self, *, text: str) -> None:
        super().__init__()
        if not isinstance(text, str):
            raise LaunchError(f"TextSubstitution(text=...) takes a string, got {text!r}")
        self.text = text

    def perform(self, context: LaunchContext) -> str:
        return self.text

    def describe(self) -> str:
        return repr(self.text)


class LaunchConfiguration(Substitution):
    """The value of a launch configuration (an argument, or SetLaunchConfiguration)."""

    def __init__(self, variable_name: SomeSubstitutions, *, default: Any = None) -> None:
        super().__init__()
        self.variable_name = normalize(variable_name, "LaunchConfiguration's name")
        self.default = None if default is None else normalize(default, "default")

    def perform(self, context: LaunchContext) -> str:
        name = perform(context, self.variable_name)
        if name in context.launch_configurations:
            value = context.launch_configurations[name]
            return value if isinstance(value, str) else str(value)
        if self.default is not None:
            return perform(context, self.default)
        known = sorted(
            key for key in context.launch_configurations if not key.startswith(_INTERNAL)
        )
        raise SubstitutionFailure(
            f"launch configuration '{name}' does not exist: declare it with "
            f"DeclareLaunchArgument('{name}', default_value='...') before it is used, or pass "
            f"{name}:=VALUE (set here: {', '.join(known) or 'none'})",
            self.site,
        )

    def describe(self) -> str:
        return f"LaunchConfiguration('{''.join(s.describe() for s in self.variable_name)}')"


# Configurations launch_ros keeps for itself (namespace, SetParameter, SetRemap).
_INTERNAL = ("ros_namespace", "global_params", "ros_remaps")


class PathJoinSubstitution(Substitution):
    def __init__(self, substitutions: Iterable[Any]) -> None:
        super().__init__()
        self.parts = [normalize(part, "a PathJoinSubstitution part") for part in substitutions]

    def perform(self, context: LaunchContext) -> str:
        performed = [perform(context, part) for part in self.parts]
        return os.path.join(*performed) if performed else ""

    def __truediv__(self, other: Any) -> PathJoinSubstitution:
        return PathJoinSubstitution([*self.parts, other])


class ThisLaunchFileDir(Substitution):
    def perform(self, context: LaunchContext) -> str:
        return _current(context, "current_launch_file_directory")


class ThisLaunchFile(Substitution):
    def perform(self, context: LaunchContext) -> str:
        return _current(context, "current_launch_file_path")


def _current(context: LaunchContext, key: str) -> str:
    values = context.get_locals_as_dict()
    if key not in values:
        raise SubstitutionFailure("used outside of a launch file")
    return values[key]


class EnvironmentVariable(Substitution):
    def __init__(self, name: SomeSubstitutions, *, default_value: Any = None) -> None:
        super().__init__()
        self.name = normalize(name, "EnvironmentVariable's name")
        self.default_value = None if default_value is None else normalize(default_value)

    def perform(self, context: LaunchContext) -> str:
        name = perform(context, self.name)
        if self.default_value is not None:
            return perform(context, self.default_value)
        raise SubstitutionFailure(
            f"EnvironmentVariable('{name}') reads the shell environment, and a run has none; "
            "give it a default_value or use a launch argument",
            self.site,
        )


class AnonName(Substitution):
    """A name made unique for this launch (the same name gives the same result in one
    launch, as launch's anon names are cached per context)."""

    def __init__(self, name: SomeSubstitutions) -> None:
        super().__init__()
        self.name = normalize(name, "AnonName's name")

    def perform(self, context: LaunchContext) -> str:
        base = perform(context, self.name)
        digest = hashlib.sha1(base.encode()).hexdigest()[:8]
        return f"{base}_{digest}"


class PythonExpression(Substitution):
    """Python's eval of the performed text with `math` in scope, as launch does; this runs in
    the sandbox like the rest of the launch file."""

    def __init__(self, expression: Any) -> None:
        super().__init__()
        self.expression = normalize(expression, "PythonExpression's expression")

    def perform(self, context: LaunchContext) -> str:
        text = perform(context, self.expression)
        try:
            return str(eval(text, {"math": math}, {}))  # student code, in the sandbox
        except Exception as error:
            raise SubstitutionFailure(
                f"PythonExpression '{text}' failed: {type(error).__name__}: {error}", self.site
            ) from None


class EqualsSubstitution(Substitution):
    def __init__(self, left: Any, right: Any) -> None:
        super().__init__()
        self.left, self.right = normalize(left), normalize(right)

    def perform(self, context: LaunchContext) -> str:
        equal = _loose(perform(context, self.left)) == _loose(perform(context, self.right))
        return "true" if self._want(equal) else "false"

    def _want(self, equal: bool) -> bool:
        return equal


class NotEqualsSubstitution(EqualsSubstitution):
    def _want(self, equal: bool) -> bool:
        return not equal


def _loose(text: str) -> object:
    lowered = text.strip().lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    try:
        return float(lowered)
    except ValueError:
        return text


class FileContent(Substitution):
    def __init__(self, path: Any) -> None:
        super().__init__()
        self.path = normalize(path, "FileContent's path")

    def perform(self, context: LaunchContext) -> str:
        path = perform(context, self.path)
        context.relative(path, self.site, "FileContent")
        try:
            with open(os.path.join(context.workdir, path), encoding="utf-8") as file:
                return file.read()
        except OSError:
            raise SubstitutionFailure(f"FileContent: no file '{path}'", self.site) from None


class Command(Substitution):
    def __init__(self, command: Any, **_: Any) -> None:
        super().__init__()

    def perform(self, context: LaunchContext) -> str:
        raise SubstitutionFailure(
            "Command(...) runs a program (often xacro for a robot description); a run does "
            "not run programs: the robot and its description come from the run's settings",
            self.site,
        )


class FindExecutable(Command):
    pass


class FindPackageShare(Substitution):
    """launch_ros: the package's share folder (here the package's folder of the workspace)."""

    def __init__(self, package: SomeSubstitutions) -> None:
        super().__init__()
        self.package = normalize(package, "FindPackageShare's package")

    def find(self, package: str) -> str:
        from sandbox.launch2.packages import get_package_share_directory

        return get_package_share_directory(package, self.site)

    def perform(self, context: LaunchContext) -> str:
        return self.find(perform(context, self.package))

    def __truediv__(self, other: Any) -> PathJoinSubstitution:
        return PathJoinSubstitution([self, other])


class FindPackagePrefix(FindPackageShare):
    def find(self, package: str) -> str:
        from sandbox.launch2.packages import get_package_prefix

        return get_package_prefix(package, self.site)


class FindPackage(FindPackageShare):
    pass
