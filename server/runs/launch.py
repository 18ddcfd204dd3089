"""ROS 1 `.launch` files read into a run: nodes with their parameters, remappings, arguments
and namespaces, plus the global parameters.

The format and its semantics are roslaunch's (ros/ros_comm tools/roslaunch: xmlloader.py,
loader.py; http://wiki.ros.org/roslaunch/XML): <launch>, <arg>, <param>, <rosparam>, <remap>,
<group>, <include>, <node>, `if`/`unless` on every element, substitution args. A node's
`pkg`/`type` name a file of the student's workspace (type="wall_follower.py" is the workspace
file of that name, in any folder); `$(find pkg)` is the workspace (or the folder of the
workspace's package.xml naming `pkg`). The robot and the world come from the run's settings,
so includes of robot or simulator packages (turtlebot3_gazebo, ...) and nodes from ROS itself
(rviz, gazebo, robot_state_publisher) are refused with a sentence saying so, and so is what a
run does not do (<machine>, <test>, <env>, `command=` parameters, `$(eval)`).

Like roslaunch, a node gets `__name:=<name>` on its command line (so init_node's name is the
launch file's), its <remap>s, and its namespace; private parameters (`~x`, or <param> inside
<node>) become `/<ns>/<node>/x`. All parameters go to `LaunchPlan.params` with global names
written without the leading slash ("robot1/follower/speed"), the form RunSpec.params uses.

Pure: the workspace is a mapping of relative path -> text or bytes, so the web API and the CLI
share this reader. Every error is a LaunchFileError naming the file and the line.
"""

from __future__ import annotations

import posixpath
import re
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from sandbox.names import canonicalize, make_global_ns, ns_join
from server.runs.launch_xml import (
    MAX_LAUNCH_BYTES,
    Element,
    SubstitutionError,
    Substitutions,
    XmlError,
    convert_value,
    parse_xml,
)
from server.runs.spec import NodeSpec, RunSpecError

MAX_INCLUDE_DEPTH = 8  # nested <include>s; deeper is a loop or a robot stack, not an exercise
# ROS packages that are the robot, the simulator or tools around them: a run has its own.
ROBOT_PACKAGES = re.compile(
    r"^(turtlebot3(_\w+)?|gazebo_ros|gazebo_plugins|robot_state_publisher|joint_state_publisher"
    r"(_gui)?|rviz|rqt\w*|stage_ros|turtlesim|map_server|amcl|move_base|gmapping|"
    r"slam_gmapping|hector_\w+|cartographer\w*|xacro|urdf\w*|rosbag|topic_tools|tf|tf2_ros|"
    r"teleop_twist_keyboard|husky_\w+|jackal_\w+|pr2_\w+|kobuki\w*|turtlebot(_\w+)?)$"
)


class LaunchFileError(RunSpecError):
    """The launch file cannot be run as written; the message names the file and the line."""

    def __init__(self, filename: str, line: int | None, message: str) -> None:
        where = f"{filename}, line {line}" if line else filename
        super().__init__(f"{where}: {message}")
        self.filename = filename
        self.line = line
        self.problem = message


@dataclass(frozen=True, slots=True)
class LaunchPlan:
    """What a launch file starts: its nodes and the parameters it sets (global names without
    the leading slash, as RunSpec.params), with notes on what was accepted but not done."""

    nodes: tuple[NodeSpec, ...]
    params: dict[str, object] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    ros_version: int = 1  # 2 for a ROS 2 Python launch file (server/runs/launch_py.py)


def load_launch(
    path: str, workspace: Mapping[str, str | bytes], args: Mapping[str, str] | None = None
) -> LaunchPlan:
    """Read the launch file `path` (a key of `workspace`) with launch arguments `args`
    (as `name:=value` on roslaunch's command line). Raises LaunchFileError."""
    reader = _Reader(workspace)
    path = reader.normalize(path, path, None)
    passed = {str(key): str(value) for key, value in (args or {}).items()}
    root_scope = _Scope(ns="/", filename=path, args={}, passed=passed)
    reader.read_file(path, root_scope, depth=0, line=None)
    unused = sorted(set(passed) - root_scope.declared)
    if unused:
        declared = ", ".join(sorted(root_scope.declared)) or "none"
        raise LaunchFileError(
            path,
            None,
            f"launch argument(s) {', '.join(unused)} are not declared by this file "
            f"(its <arg>s: {declared})",
        )
    return reader.plan()


# ------------------------------------------------------------------------------ internals
@dataclass
class _Scope:
    """roslaunch's LoaderContext: namespace, args in scope, remaps and ~params for the nodes
    that follow, and the args passed to the file being read."""

    ns: str
    filename: str
    args: dict[str, str | None]
    passed: dict[str, str]
    declared: set[str] = field(default_factory=set)
    remaps: list[tuple[str, str]] = field(default_factory=list)
    private_params: dict[str, Any] = field(default_factory=dict)

    def child(self, ns: str | None) -> _Scope:
        if not ns:
            child_ns = self.ns
        elif ns.startswith("/"):
            child_ns = make_global_ns(canonicalize(ns))
        else:
            child_ns = make_global_ns(canonicalize(ns_join(self.ns, ns)))
        return _Scope(
            ns=child_ns,
            filename=self.filename,
            args=dict(self.args),
            passed=self.passed,
            declared=self.declared,
            remaps=list(self.remaps),
            private_params=dict(self.private_params),
        )

    def add_remap(self, source: str, target: str) -> None:
        self.remaps = [(s, t) for s, t in self.remaps if s != source] + [(source, target)]


@dataclass
class _NodeDraft:
    name: str  # as in the launch file
    namespace: str  # "/ns/"
    spec: NodeSpec
    where: tuple[str, int]


class _Reader:
    def __init__(self, workspace: Mapping[str, str | bytes]) -> None:
        self.workspace = {posixpath.normpath(key): value for key, value in workspace.items()}
        self.params: dict[str, Any] = {}
        self.nodes: list[_NodeDraft] = []
        self.notes: list[str] = []
        self.anon: dict[str, str] = {}
        self.reading: list[str] = []
        self.packages = self._packages()

    # -------------------------------------------------------------- workspace
    def _packages(self) -> dict[str, str]:
        """Package name -> folder, from the workspace's package.xml files."""
        found: dict[str, str] = {}
        for key, value in self.workspace.items():
            if posixpath.basename(key) != "package.xml":
                continue
            text = value.decode("utf-8", "replace") if isinstance(value, bytes) else value
            match = re.search(r"<name>\s*([\w-]+)\s*</name>", text)
            if match:
                found[match.group(1)] = posixpath.dirname(key) or "."
        return found

    def normalize(self, path: str, filename: str, line: int | None) -> str:
        clean = posixpath.normpath(path.strip())
        if clean.startswith("/") or clean == ".." or clean.startswith("../"):
            raise LaunchFileError(
                filename,
                line,
                f"'{path}' is outside the workspace; refer to workspace files with "
                "$(find <your package>)/folder/file or a path relative to the workspace",
            )
        return clean

    def text_of(self, path: str, filename: str, line: int | None, what: str) -> str:
        clean = self.normalize(path, filename, line)
        candidates = [clean]
        here = posixpath.dirname(filename)
        if here:
            candidates.append(posixpath.normpath(posixpath.join(here, clean)))
        for candidate in candidates:
            if candidate in self.workspace:
                value = self.workspace[candidate]
                if isinstance(value, bytes):
                    try:
                        return value.decode("utf-8")
                    except UnicodeDecodeError:
                        raise LaunchFileError(
                            filename, line, f"{what} '{path}' is not UTF-8 text"
                        ) from None
                return value
        raise LaunchFileError(
            filename, line, f"{what} '{path}' is not in the workspace ({self._listing(None)})"
        )

    def _listing(self, suffix: str | None) -> str:
        names = sorted(key for key in self.workspace if suffix is None or key.endswith(suffix))
        shown = ", ".join(names[:20]) + (", ..." if len(names) > 20 else "")
        return f"its files: {shown}" if names else "it has no such files"

    def find(self, package: str) -> str:
        if package in self.packages:
            return self.packages[package]
        if ROBOT_PACKAGES.match(package):
            raise _RobotPackage(package)
        return "."

    # -------------------------------------------------------------- files and elements
    def read_file(self, path: str, scope: _Scope, depth: int, line: int | None) -> None:
        parent = self.reading[-1] if self.reading else path
        if depth > MAX_INCLUDE_DEPTH or path in self.reading:
            raise LaunchFileError(parent, line, f"'{path}' includes itself (directly or not)")
        text = self.text_of(path, parent, line, "launch file")
        if len(text.encode()) > MAX_LAUNCH_BYTES:
            raise LaunchFileError(path, None, f"larger than {MAX_LAUNCH_BYTES // 1024} KiB")
        try:
            root = parse_xml(text)
        except XmlError as error:
            raise LaunchFileError(path, error.line, str(error)) from None
        if root.tag != "launch":
            raise LaunchFileError(
                path, root.line, f"the root element must be <launch>, not <{root.tag}>"
            )
        self.reading.append(path)
        scope.filename = path
        try:
            if self._enabled(root, scope) and root.attrs.get("deprecated"):
                self.notes.append(f"{path}: deprecated: {root.attrs['deprecated']}")
            self.read_children(root, scope, depth)
        finally:
            self.reading.pop()

    def read_children(self, parent: Element, scope: _Scope, depth: int) -> None:
        from server.runs.launch_elements import ELEMENTS  # it imports this module

        for element in parent.children:
            handler = ELEMENTS.get(element.tag)
            if handler is None:
                raise self.error(
                    scope,
                    element,
                    f"<{element.tag}> is not a roslaunch element; a launch file holds <node>, "
                    "<param>, <rosparam>, <remap>, <arg>, <group> and <include>",
                )
            if self._enabled(element, scope):
                handler(self, element, scope, depth)

    def error(self, scope: _Scope, element: Element, message: str) -> LaunchFileError:
        return LaunchFileError(scope.filename, element.line, message)

    def attr(self, element: Element, scope: _Scope, name: str) -> str | None:
        try:
            return _SubstitutionsFor(self, scope).resolve(element.attrs.get(name))
        except _RobotPackage as robot:
            raise self.error(scope, element, robot.sentence(element)) from None
        except SubstitutionError as error:
            raise self.error(scope, element, str(error)) from None

    def required(self, element: Element, scope: _Scope, name: str) -> str:
        value = self.attr(element, scope, name)
        if value is None:
            raise self.error(scope, element, f"<{element.tag}> needs a '{name}' attribute")
        return value

    def check_attrs(self, element: Element, scope: _Scope, allowed: tuple[str, ...]) -> None:
        for name in element.attrs:
            if name not in allowed and name not in ("if", "unless"):
                raise self.error(
                    scope,
                    element,
                    f"<{element.tag}> has no attribute '{name}' (its attributes: "
                    f"{', '.join(allowed)}, if, unless)",
                )

    def _enabled(self, element: Element, scope: _Scope) -> bool:
        when, unless = self.attr(element, scope, "if"), self.attr(element, scope, "unless")
        if when is not None and unless is not None:
            raise self.error(scope, element, "an element cannot have both 'if' and 'unless'")
        if when is not None:
            return self.boolean(when, "if", element, scope)
        if unless is not None:
            return not self.boolean(unless, "unless", element, scope)
        return True

    def boolean(self, value: str, label: str, element: Element, scope: _Scope) -> bool:
        lowered = value.strip().lower()
        if lowered in ("true", "1"):
            return True
        if lowered in ("false", "0"):
            return False
        raise self.error(scope, element, f"'{label}' must be true, false, 1 or 0, got '{value}'")

    # -------------------------------------------------------------- the plan
    def plan(self) -> LaunchPlan:
        counts: dict[str, int] = {}
        for draft in self.nodes:
            counts[draft.name] = counts.get(draft.name, 0) + 1
        seen: dict[str, tuple[str, int]] = {}
        nodes = []
        for draft in self.nodes:
            full = draft.namespace + draft.name
            if full in seen:
                filename, line = draft.where
                first = seen[full]
                raise LaunchFileError(
                    filename,
                    line,
                    f"two nodes are named '{full}' (the other at {first[0]}, line {first[1]}); "
                    "give each its own name or namespace",
                )
            seen[full] = draft.where
            label = draft.name if counts[draft.name] == 1 else full.strip("/").replace("/", "_")
            nodes.append(_with_name(draft.spec, label[:40]))
        params = {key.lstrip("/"): value for key, value in self.params.items()}
        return LaunchPlan(nodes=tuple(nodes), params=params, notes=tuple(self.notes))

    def set_param(self, name: str, value: Any) -> None:
        """Set a global parameter; a dict sets a subtree (and replaces what was there)."""
        name = canonicalize(name)
        prefix = name.rstrip("/") + "/"
        for key in [key for key in self.params if key == name or key.startswith(prefix)]:
            del self.params[key]
        for key in [key for key in self.params if name.startswith(key + "/")]:
            del self.params[key]  # a value that becomes a namespace, as the parameter server
        if isinstance(value, dict) and value:
            for child, child_value in value.items():
                self.set_param(ns_join(make_global_ns(name), str(child)), child_value)
        else:
            self.params[name] = value

    def delete_params(self, name: str) -> None:
        name = canonicalize(name)
        prefix = name.rstrip("/") + "/"
        for key in [key for key in self.params if key == name or key.startswith(prefix)]:
            del self.params[key]


class _RobotPackage(SubstitutionError):
    """$(find pkg) of a ROS robot or simulator package: the run provides the robot."""

    def __init__(self, package: str) -> None:
        super().__init__(package)
        self.package = package

    def sentence(self, element: Element) -> str:
        if element.tag == "include":
            return (
                f"this includes a launch file of '{self.package}': the robot and world come "
                "from the run's settings; remove this include"
            )
        return (
            f"$(find {self.package}) refers to a ROS package that is not in your workspace; "
            "the robot and world come from the run's settings"
        )


class _SubstitutionsFor(Substitutions):
    def __init__(self, reader: _Reader, scope: _Scope) -> None:
        seed = scope.filename

        def make_anon(base: str) -> str:
            return f"{base}_{zlib.crc32((seed + base).encode()):08x}"

        super().__init__(
            args=scope.args,
            find=reader.find,
            dirname=posixpath.dirname(scope.filename) or ".",
            anon=reader.anon,
            make_anon=make_anon,
        )


def _with_name(spec: NodeSpec, name: str) -> NodeSpec:
    from dataclasses import replace

    return replace(spec, name=name)


__all__ = ["LaunchFileError", "LaunchPlan", "convert_value", "load_launch"]
