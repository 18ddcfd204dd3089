"""launch's description and actions (launch/launch_description.py, launch/actions/*.py), as
far as they decide which nodes start with what: arguments, configurations, groups, includes,
conditions. Actions that run programs or wait for events are refused with a sentence (a run
starts its nodes at once, in its sandbox)."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from typing import Any

from sandbox.launch2.conditions import Condition
from sandbox.launch2.context import LaunchContext
from sandbox.launch2.errors import LaunchError, caller_site
from sandbox.launch2.substitutions import Substitution, normalize, perform

MAX_INCLUDE_DEPTH = 8  # nested includes; deeper is a loop or a robot's bringup, not an exercise


class LaunchDescriptionEntity:
    """Something a visit handles; `visit` returns the entities to visit next, in order."""

    def visit(self, context: LaunchContext) -> list[Any] | None:
        return None

    def describe_sub_entities(self) -> list[Any]:
        return []


class Action(LaunchDescriptionEntity):
    """launch.Action: visited only if its condition (if any) holds."""

    def __init__(self, *, condition: Condition | None = None) -> None:
        self.site = caller_site()
        if condition is not None and not isinstance(condition, Condition):
            raise LaunchError(
                f"condition= takes IfCondition(...) or UnlessCondition(...), got {condition!r}"
            )
        self.condition = condition

    def visit(self, context: LaunchContext) -> list[Any] | None:
        if self.condition is not None and not self.condition.evaluate(context):
            return None
        return self.execute(context)

    def execute(self, context: LaunchContext) -> list[Any] | None:
        return None


class LaunchDescription(LaunchDescriptionEntity):
    def __init__(
        self, initial_entities: Iterable[Any] | None = None, *, deprecated_reason: str | None = None
    ) -> None:
        self.site = caller_site()
        self.entities: list[Any] = []
        self.deprecated_reason = deprecated_reason
        for entity in initial_entities or []:
            self.add_entity(entity)

    def add_entity(self, entity: Any) -> None:
        if not isinstance(entity, LaunchDescriptionEntity):
            raise LaunchError(
                f"a LaunchDescription holds actions (Node, DeclareLaunchArgument, ...); "
                f"got {entity!r}"
            )
        self.entities.append(entity)

    add_action = add_entity

    def visit(self, context: LaunchContext) -> list[Any] | None:
        return list(self.entities)

    def describe_sub_entities(self) -> list[Any]:
        return list(self.entities)

    def get_launch_arguments(self) -> list[DeclareLaunchArgument]:
        """The DeclareLaunchArgument actions visible without visiting (not inside includes)."""
        found: list[DeclareLaunchArgument] = []

        def walk(entities: list[Any], conditional: bool) -> None:
            for entity in entities:
                if isinstance(entity, DeclareLaunchArgument):
                    entity.conditionally_included = conditional
                    found.append(entity)
                elif isinstance(entity, GroupAction | LaunchDescription):
                    inner = conditional or getattr(entity, "condition", None) is not None
                    walk(entity.describe_sub_entities(), inner)

        walk(self.entities, False)
        return found


class DeclareLaunchArgument(Action):
    def __init__(
        self,
        name: str,
        *,
        default_value: Any = None,
        description: str | None = None,
        choices: list[str] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        if not isinstance(name, str) or not name:
            raise LaunchError(f"DeclareLaunchArgument's name must be a string, got {name!r}")
        self.name = name
        self.default_value = (
            None
            if default_value is None
            else normalize(default_value, f"DeclareLaunchArgument('{name}')'s default_value")
        )
        if choices is not None and not choices:
            raise LaunchError(f"DeclareLaunchArgument('{name}'): choices=[] is empty; use None")
        if choices is not None and isinstance(default_value, str) and default_value not in choices:
            raise LaunchError(
                f"DeclareLaunchArgument('{name}'): the default_value '{default_value}' is not "
                f"one of its choices {choices}"
            )
        self.description = description or "no description given"
        self.choices = choices
        self.conditionally_included = False
        from sandbox.launch2 import evaluate

        evaluate.declared(name)

    def execute(self, context: LaunchContext) -> list[Any] | None:
        context.declared_arguments.add(self.name)
        if self.name not in context.launch_configurations:
            if self.default_value is None:
                raise LaunchError(
                    f"launch argument '{self.name}' has no default_value and was not given: "
                    f"pass {self.name}:=VALUE (or give it a default_value)",
                    self.site,
                )
            context.launch_configurations[self.name] = perform(context, self.default_value)
        value = context.launch_configurations[self.name]
        if self.choices is not None and value not in self.choices:
            raise LaunchError(
                f"launch argument '{self.name}' is '{value}'; it must be one of "
                f"{', '.join(self.choices)}",
                self.site,
            )
        return None


class SetLaunchConfiguration(Action):
    def __init__(self, name: Any, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.name = normalize(name, "SetLaunchConfiguration's name")
        self.value = normalize(value, "SetLaunchConfiguration's value")

    def execute(self, context: LaunchContext) -> list[Any] | None:
        context.launch_configurations[perform(context, self.name)] = perform(context, self.value)
        return None


class UnsetLaunchConfiguration(Action):
    def __init__(self, name: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.name = normalize(name, "UnsetLaunchConfiguration's name")

    def execute(self, context: LaunchContext) -> list[Any] | None:
        context.launch_configurations.pop(perform(context, self.name), None)
        return None


class PushLaunchConfigurations(Action):
    def execute(self, context: LaunchContext) -> list[Any] | None:
        context.push_launch_configurations()
        return None


class PopLaunchConfigurations(Action):
    def execute(self, context: LaunchContext) -> list[Any] | None:
        context.pop_launch_configurations()
        return None


class _ResetLaunchConfigurations(Action):
    def __init__(self, keep: dict[Any, Any]) -> None:
        super().__init__()
        self.keep = keep

    def execute(self, context: LaunchContext) -> list[Any] | None:
        kept = {
            perform(context, normalize(key)): perform(context, normalize(value))
            for key, value in self.keep.items()
        }
        context.launch_configurations.clear()
        context.launch_configurations.update(kept)
        return None


class GroupAction(Action):
    """Actions in a scope: with scoped=True what they set stays inside the group."""

    def __init__(
        self,
        actions: Iterable[Any],
        *,
        scoped: bool = True,
        forwarding: bool = True,
        launch_configurations: dict[Any, Any] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.actions = list(actions)
        for action in self.actions:
            if not isinstance(action, LaunchDescriptionEntity):
                raise LaunchError(f"GroupAction holds actions; got {action!r}")
        self.scoped, self.forwarding = scoped, forwarding
        self.configurations = dict(launch_configurations or {})

    def describe_sub_entities(self) -> list[Any]:
        return list(self.actions)

    def execute(self, context: LaunchContext) -> list[Any] | None:
        sets = [SetLaunchConfiguration(k, v) for k, v in self.configurations.items()]
        for item in sets:
            item.site = self.site
        if not self.scoped:
            return [*sets, *self.actions]
        if self.forwarding:
            return [PushLaunchConfigurations(), *sets, *self.actions, PopLaunchConfigurations()]
        reset = _ResetLaunchConfigurations(self.configurations)
        return [PushLaunchConfigurations(), reset, *self.actions, PopLaunchConfigurations()]


class LaunchDescriptionSource:
    """Where an included description comes from: a path (text or substitutions)."""

    kind = "any"

    def __init__(self, launch_file_path: Any) -> None:
        self.site = caller_site()
        self.location = normalize(launch_file_path, "the launch file's path")


class PythonLaunchDescriptionSource(LaunchDescriptionSource):
    kind = "python"


class AnyLaunchDescriptionSource(LaunchDescriptionSource):
    kind = "any"


class FrontendLaunchDescriptionSource(LaunchDescriptionSource):
    kind = "frontend"


class XMLLaunchDescriptionSource(FrontendLaunchDescriptionSource):
    pass


class YAMLLaunchDescriptionSource(FrontendLaunchDescriptionSource):
    pass


class IncludeLaunchDescription(Action):
    """Another launch file of the workspace, with `launch_arguments` set as configurations
    first (not scoped: wrap it in a GroupAction to keep them inside, as in ros2 launch)."""

    def __init__(
        self,
        launch_description_source: Any,
        *,
        launch_arguments: Iterable[tuple[Any, Any]] | dict[Any, Any] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        if not isinstance(launch_description_source, LaunchDescriptionSource):
            launch_description_source = AnyLaunchDescriptionSource(launch_description_source)
        self.source = launch_description_source
        if isinstance(launch_arguments, dict):
            launch_arguments = launch_arguments.items()
        pairs = []
        for pair in launch_arguments or ():
            if not isinstance(pair, tuple | list) or len(pair) != 2:
                raise LaunchError(
                    "launch_arguments takes (name, value) pairs, e.g. "
                    "{'speed': '0.2'}.items(); got " + repr(pair)
                )
            pairs.append((normalize(pair[0], "an argument name"), normalize(pair[1], "a value")))
        self.launch_arguments = pairs

    def execute(self, context: LaunchContext) -> list[Any] | None:
        from sandbox.launch2.evaluate import load_launch_file

        path = perform(context, self.source.location)
        relative = context.relative(path, self.site, "the included launch file")
        if context.include_depth >= MAX_INCLUDE_DEPTH:
            raise LaunchError(
                f"includes are nested more than {MAX_INCLUDE_DEPTH} deep (does "
                f"'{relative}' include itself?)",
                self.site,
            )
        description = load_launch_file(relative, context, self.site)
        names = [perform(context, name) for name, _ in self.launch_arguments]
        for argument in description.get_launch_arguments():
            if argument.conditionally_included or argument.default_value is not None:
                continue
            if argument.name not in names:
                raise LaunchError(
                    f"the included '{relative}' needs launch argument '{argument.name}' "
                    f"(it has no default_value); pass it in launch_arguments "
                    f"(given: {', '.join(names) or 'none'})",
                    self.site,
                )
        sets = []
        for name, value in self.launch_arguments:
            action = SetLaunchConfiguration(name, value)
            action.site = self.site
            sets.append(action)
        return [*sets, _Included(description, relative, os.path.join(context.workdir, relative))]


class _Included(LaunchDescriptionEntity):
    """An included description, visited with its file as the current launch file."""

    def __init__(self, description: LaunchDescription, relative: str, absolute: str) -> None:
        self.description, self.relative, self.absolute = description, relative, absolute

    def visit(self, context: LaunchContext) -> list[Any] | None:
        context.extend_locals(
            {
                "current_launch_file_path": self.absolute,
                "current_launch_file_directory": os.path.dirname(self.absolute),
            }
        )
        context.include_depth += 1
        return [*self.description.entities, _Leave()]


class _Leave(LaunchDescriptionEntity):
    def visit(self, context: LaunchContext) -> list[Any] | None:
        context.include_depth -= 1
        return None


class OpaqueFunction(Action):
    """function(context, *args, **kwargs) -> actions, called when visited."""

    def __init__(
        self,
        *,
        function: Callable[..., Any],
        args: Iterable[Any] | None = None,
        kwargs: dict[str, Any] | None = None,
        **left: Any,
    ) -> None:
        super().__init__(**left)
        if not callable(function):
            raise LaunchError(f"OpaqueFunction(function=...) takes a function, got {function!r}")
        self.function, self.args, self.kwargs = function, list(args or ()), dict(kwargs or {})

    def execute(self, context: LaunchContext) -> list[Any] | None:
        result = self.function(context, *self.args, **self.kwargs)
        if result is None:
            return None
        if not isinstance(result, list | tuple):
            raise LaunchError(
                f"the OpaqueFunction's function returned {result!r}; it returns a list of "
                "actions (or None)",
                self.site,
            )
        return list(result)


class LogInfo(Action):
    def __init__(self, *, msg: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.msg = normalize(msg, "LogInfo's msg")

    def execute(self, context: LaunchContext) -> list[Any] | None:
        context.note(self.site, f"LogInfo: {perform(context, self.msg)}")
        return None


class TimerAction(Action):
    """Its actions start with the others: a run starts every node at once (noted)."""

    def __init__(self, *, period: Any, actions: Iterable[Any], **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.period, self.actions = period, list(actions)

    def describe_sub_entities(self) -> list[Any]:
        return list(self.actions)

    def execute(self, context: LaunchContext) -> list[Any] | None:
        period = self.period
        if isinstance(period, Substitution | list):
            period = perform(context, normalize(period))
        context.note(
            self.site,
            f"TimerAction(period={period}): its actions start with the others (a run starts "
            "every node at once; wait in the node's code if it must start later)",
        )
        return list(self.actions)


class SetEnvironmentVariable(Action):
    def __init__(self, name: Any, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)

    def execute(self, context: LaunchContext) -> list[Any] | None:
        context.note(self.site, "SetEnvironmentVariable is ignored: nodes get no environment")
        return None


class _Refused(Action):
    """An action a run cannot do; visiting it is an error with a sentence."""

    sentence = ""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(condition=kwargs.get("condition"))

    def execute(self, context: LaunchContext) -> list[Any] | None:
        raise LaunchError(self.sentence, self.site)


class ExecuteProcess(_Refused):
    sentence = (
        "ExecuteProcess runs a program; a run starts only the Python nodes of your workspace "
        "(launch_ros.actions.Node with package= and executable=)"
    )


class RegisterEventHandler(_Refused):
    sentence = (
        "RegisterEventHandler (OnProcessExit, OnProcessStart, ...) is not run: a run starts "
        "every node at once; list the nodes in the LaunchDescription itself"
    )


class EmitEvent(_Refused):
    sentence = "EmitEvent is not run: a run ends when its duration is over or a node asks"


class Shutdown(_Refused):
    sentence = "Shutdown() is not run: a run ends when its duration is over or a node asks"
