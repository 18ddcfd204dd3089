"""launch_ros's actions (launch_ros/actions/*.py): Node, PushRosNamespace, SetParameter,
SetParametersFromFile, SetRemap. A Node becomes a PlannedNode: its workspace file, name,
namespace (PushRosNamespace's prefix for a relative one), parameters resolved for its fully
qualified name (sandbox/launch2/parameters.py), remappings and command line."""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping
from typing import Any

from sandbox.launch2 import packages, parameters
from sandbox.launch2.actions import Action, _Refused
from sandbox.launch2.context import LaunchContext
from sandbox.launch2.errors import LaunchError, Site
from sandbox.launch2.plan import PlannedNode
from sandbox.launch2.substitutions import Substitution, normalize, perform

_NODE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")  # rmw's validate_node_name
_NS_TOKEN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")  # rmw's validate_namespace, per token
_OUTPUTS = ("screen", "log", "both", "own_log", "full")


def prefix_namespace(base: str | None, ns: str | None) -> str | None:
    """launch_ros.utilities.prefix_namespace: `ns` under `base` unless `ns` is absolute."""
    if base is None and ns is None:
        return None
    if ns is None:
        combined = base
    elif not base or ns.startswith("/"):
        combined = ns
    else:
        combined = ("" if base == "/" else base) + "/" + ns
    return combined if combined == "/" else combined.rstrip("/")


def make_absolute(ns: str | None) -> str | None:
    """launch_ros.utilities.make_namespace_absolute."""
    return ns if ns is None or ns.startswith("/") else "/" + ns


def check_namespace(ns: str, site: Site | None) -> None:
    tokens = [token for token in ns.split("/")[1:] if token != ""]
    if ns != "/" and (ns.endswith("/") or "//" in ns or not all(map(_NS_TOKEN.match, tokens))):
        raise LaunchError(
            f"namespace '{ns}' is not valid: '/'-separated names of letters, digits and '_', "
            "each starting with a letter or '_'",
            site,
        )


class Node(Action):
    def __init__(
        self,
        *,
        executable: Any = None,
        package: Any = None,
        name: Any = None,
        namespace: Any = None,
        exec_name: Any = None,
        parameters: Iterable[Any] | None = None,
        remappings: Iterable[tuple[Any, Any]] | None = None,
        ros_arguments: Iterable[Any] | None = None,
        arguments: Iterable[Any] | None = None,
        output: Any = "log",
        emulate_tty: bool = False,
        respawn: Any = False,
        respawn_delay: float | None = None,
        prefix: Any = None,
        cwd: Any = None,
        env: Any = None,
        additional_env: Any = None,
        sigterm_timeout: Any = None,
        sigkill_timeout: Any = None,
        log_cmd: bool = False,
        cached_output: bool = False,
        on_exit: Any = None,
        **kwargs: Any,
    ) -> None:
        for old_name in ("node_executable", "node_name", "node_namespace"):
            if old_name in kwargs:  # ROS 2 Dashing/Eloquent's spelling, removed in Galactic
                raise LaunchError(
                    f"Node({old_name}=...) is the spelling of ROS 2 Eloquent and before; write "
                    f"{old_name.removeprefix('node_')}=..."
                )
        super().__init__(**kwargs)
        if executable is None:
            raise LaunchError(
                "Node(...) needs executable=: the node's program, e.g. executable='talker' "
                "(a setup.py console_scripts name, or the workspace file talker.py)"
            )
        self.executable = normalize(executable, "Node's executable")
        self.package = None if package is None else normalize(package, "Node's package")
        self.name = None if name is None else normalize(name, "Node's name")
        self.namespace = None if namespace is None else normalize(namespace, "Node's namespace")
        if parameters is not None and (
            isinstance(parameters, str | Mapping) or not isinstance(parameters, Iterable)
        ):
            raise LaunchError(
                "parameters= takes a list: [{'name': value}, 'file.yaml', ...], "
                f"got {parameters!r}"
            )
        self.parameters = list(parameters or [])
        self.remappings = []
        for pair in remappings or []:
            if not isinstance(pair, tuple | list) or len(pair) != 2:
                raise LaunchError(
                    f"remappings= takes ('from', 'to') pairs, e.g. [('cmd_vel', "
                    f"'robot/cmd_vel')]; got {pair!r}"
                )
            self.remappings.append((normalize(pair[0]), normalize(pair[1])))
        self.ros_arguments = [normalize(a, "a ros_arguments item") for a in ros_arguments or []]
        self.arguments = [normalize(a, "an arguments item") for a in arguments or []]
        if prefix is not None:
            raise LaunchError(
                "prefix= (gdb, valgrind, xterm...) starts the node inside another program; a "
                "run starts every node in its sandbox: remove it"
            )
        if on_exit is not None:
            raise LaunchError("on_exit= is not run: a run ends when its duration is over")
        self.respawn = respawn

    # ------------------------------------------------------------------ visiting
    def execute(self, context: LaunchContext) -> list[Any] | None:
        site = self.site
        package = perform(context, self.package) if self.package else ""
        executable = perform(context, self.executable)
        name = None
        if self.name is not None:
            name = perform(context, self.name).lstrip("/")
            if not _NODE_NAME.match(name):
                raise LaunchError(
                    f"node name '{name}' is not valid: letters, digits and '_', not starting "
                    "with a digit",
                    site,
                )
        own_ns = None if self.namespace is None else perform(context, self.namespace)
        base = context.launch_configurations.get("ros_namespace")
        namespace = make_absolute(prefix_namespace(base, own_ns))
        if namespace is not None:
            check_namespace(namespace, site)
        if not package:
            raise LaunchError(
                f"Node(executable='{executable}') needs package=: the package whose "
                "executable it is (your package's name, from its package.xml)",
                site,
            )
        path, entry = packages.find_executable(package, executable, site)
        if entry is not None and packages.runs_entry_itself(path):
            entry = None
        code_name = packages.node_name_in_code(path)
        runtime_ns = namespace or "/"
        runtime_name = name or code_name
        fqn = None
        if runtime_name is not None:
            fqn = ("" if runtime_ns == "/" else runtime_ns) + "/" + runtime_name
        rules = self._rules(context, name, namespace, site)
        resolved = parameters.resolve(rules, fqn)
        for key in resolved.unmatched:
            context.note(
                site,
                f"parameters for node '{key}' were not given to '{executable}': the launch "
                "file gives it no name= and its code's node name could not be read; add "
                "name='...' to this Node",
            )
        remaps = [
            (str(a), str(b)) for a, b in context.launch_configurations.get("ros_remaps", [])
        ] + [(perform(context, a), perform(context, b)) for a, b in self.remappings]
        for source, target in remaps:
            if not source or not target:
                raise LaunchError(f"remapping ('{source}', '{target}') has an empty side", site)
        args = [perform(context, a) for a in self.arguments]
        if self.ros_arguments:
            args += ["--ros-args", *(perform(context, a) for a in self.ros_arguments)]
        if name is not None:
            args += ["--ros-args", "-r", f"__node:={name}"]
        respawn = self.respawn
        if isinstance(respawn, Substitution | list):
            respawn = perform(context, normalize(respawn)).strip().lower() in ("true", "1")
        if respawn:
            context.note(
                site, f"'{executable}' has respawn=True; a node that ends is not restarted"
            )
        context.nodes.append(
            PlannedNode(
                package=package,
                executable=executable,
                file=path,
                entry=entry,
                name=name,
                code_name=code_name,
                namespace=runtime_ns,
                params=resolved.params,
                remaps=remaps,
                args=args,
                launch_file=site.filename if site else "",
                line=site.line if site else None,
            )
        )
        return None

    def _rules(
        self, context: LaunchContext, name: str | None, namespace: str | None, site: Site | None
    ) -> list[parameters.Rule]:
        rules: list[parameters.Rule] = []
        for item in context.launch_configurations.get("global_params", []):
            if isinstance(item, tuple):
                rules.append((parameters.WILDCARD, {item[0]: item[1]}))
            else:
                rules.extend(parameters.read_param_file(context, item, site))
        own_key = parameters.WILDCARD
        if name is not None and namespace is not None:
            own_key = ("" if namespace == "/" else namespace) + "/" + name
        for entry in self.parameters:
            if isinstance(entry, Mapping):
                rules.append((own_key, parameters.evaluate_dict(context, entry, site)))
            elif isinstance(entry, parameters.Parameter):
                param_name = perform(context, entry.name)
                rules.append(
                    (parameters.WILDCARD, {param_name: entry.value.evaluate(context, param_name)})
                )
            elif isinstance(entry, parameters.ParameterFile):
                path = perform(context, entry.path)
                rules.extend(parameters.read_param_file(context, path, site, entry.allow_substs))
            elif isinstance(entry, str | os.PathLike | Substitution | list | tuple):
                path = perform(
                    context,
                    normalize(
                        str(entry) if isinstance(entry, os.PathLike) else entry,
                        "a parameter file's path",
                    ),
                )
                rules.extend(parameters.read_param_file(context, path, site))
            else:
                raise LaunchError(
                    "parameters= holds dicts ({'speed': 0.2}) and parameter file paths; got "
                    f"{entry!r}",
                    site,
                )
        return rules


class LifecycleNode(Node):
    def __init__(self, *, name: Any, namespace: Any, **kwargs: Any) -> None:
        super().__init__(name=name, namespace=namespace, **kwargs)


class PushRosNamespace(Action):
    def __init__(self, namespace: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.namespace = normalize(namespace, "PushRosNamespace's namespace")

    def execute(self, context: LaunchContext) -> list[Any] | None:
        pushed = perform(context, self.namespace)
        previous = context.launch_configurations.get("ros_namespace")
        namespace = make_absolute(prefix_namespace(previous, pushed)) or "/"
        check_namespace(namespace, self.site)
        context.launch_configurations["ros_namespace"] = namespace
        return None


class SetParameter(Action):
    """A parameter for every Node after it (in its scope)."""

    def __init__(self, name: Any, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.params = {name: value} if not isinstance(name, list) else {tuple(name): value}

    def execute(self, context: LaunchContext) -> list[Any] | None:
        evaluated = parameters.evaluate_dict(context, self.params, self.site)
        existing = list(context.launch_configurations.get("global_params", []))
        context.launch_configurations["global_params"] = existing + list(evaluated.items())
        return None


class SetParametersFromFile(Action):
    def __init__(self, filename: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.filename = normalize(filename, "SetParametersFromFile's filename")

    def execute(self, context: LaunchContext) -> list[Any] | None:
        path = perform(context, self.filename)
        context.relative(path, self.site, "the parameter file")
        existing = list(context.launch_configurations.get("global_params", []))
        context.launch_configurations["global_params"] = [*existing, path]
        return None


class SetRemap(Action):
    def __init__(self, src: Any, dst: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.src, self.dst = normalize(src), normalize(dst)

    def execute(self, context: LaunchContext) -> list[Any] | None:
        existing = list(context.launch_configurations.get("ros_remaps", []))
        pair = (perform(context, self.src), perform(context, self.dst))
        context.launch_configurations["ros_remaps"] = [*existing, pair]
        return None


class ComposableNodeContainer(_Refused):
    sentence = (
        "composable nodes (ComposableNodeContainer) are C++ components loaded into one "
        "process; a run starts Python nodes: use launch_ros.actions.Node"
    )


class LoadComposableNodes(ComposableNodeContainer):
    pass


class SetUseSimTime(SetParameter):
    def __init__(self, value: Any, **kwargs: Any) -> None:
        super().__init__("use_sim_time", value, **kwargs)
