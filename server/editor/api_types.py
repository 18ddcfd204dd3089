"""What a name in a student's file holds, as far as the editor's checks can tell without running
it: a message class imported from `<pkg>.msg`, an instance made from one, a message a callback
receives, the step API's `obs`. Flow-insensitive and per function: a name given two different
types in one function is not known (no check is better than a wrong one).
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from dataclasses import dataclass

from server.editor.messages import ROS1, ROS2, MessageInfo, message_info, message_names, packages

ROS2_IMPORT = re.compile(r"^\s*(import\s+rclpy|from\s+rclpy[\s.])", re.MULTILINE)
# Calls that tie a topic name to a message class: (name index, class index) among the arguments.
ROSPY_TOPIC_CALLS = {"Subscriber": (0, 1), "Publisher": (0, 1), "wait_for_message": (0, 1)}
RCLPY_TOPIC_CALLS = {"create_subscription": (1, 0), "create_publisher": (1, 0)}
CALLBACK_INDEX = {"Subscriber": 2, "create_subscription": 2}


def dialect_of(code: str) -> int:
    """ROS 2 when the file imports rclpy, as the server decides a node's dialect."""
    return ROS2 if ROS2_IMPORT.search(code) else ROS1


@dataclass(frozen=True, slots=True)
class Kind:
    """What an expression holds: a message class or instance (or a list of them), or `obs`."""

    what: str  # "class", "instance", "array", "obs"
    message: MessageInfo | None = None


def scope_nodes(scope: ast.AST) -> Iterator[ast.AST]:
    """The nodes of a function's (or the module's) body, not those of functions inside it.
    Iterative: a hostile file nested thousands deep must not exhaust the recursion limit."""
    stack = list(ast.iter_child_nodes(scope))
    while stack:
        node = stack.pop()
        yield node
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda | ast.ClassDef):
            if isinstance(node, ast.ClassDef):  # its methods are scopes; its body is not
                stack.extend(n for n in node.body if not isinstance(n, ast.FunctionDef))
            stack.extend(getattr(node, "decorator_list", []))
            continue
        stack.extend(ast.iter_child_nodes(node))


def functions(tree: ast.Module) -> list[ast.FunctionDef | ast.AsyncFunctionDef]:
    return [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)]


def called_name(call: ast.Call) -> str | None:
    """`Subscriber` for `rospy.Subscriber(...)`, `Subscriber(...)` or `self.node.Subscriber`."""
    func = call.func
    if isinstance(func, ast.Attribute):
        return func.attr
    if isinstance(func, ast.Name):
        return func.id
    return None


class TypeScope:
    """The message classes a file imports and the types its names hold, function by function."""

    def __init__(self, tree: ast.Module, dialect: int, obs_types: dict[str, str]) -> None:
        self.tree = tree
        self.obs_types = obs_types  # the step API's obs: sensor topic -> ROS 1 type name
        self.dialect = dialect
        self.known_packages = set(packages(dialect))
        self.classes: dict[str, MessageInfo] = {}  # local name -> message class
        self.modules: dict[str, str] = {}  # local name of `pkg.msg` (or `pkg`) -> package
        self.bad_imports: list[tuple[ast.ImportFrom, ast.alias, str, str]] = []
        self._read_imports()
        self.callback_types: dict[str, MessageInfo | None] = {}  # function name -> message it gets
        self.step_param: str | None = None
        self._read_callbacks()
        self.module_names = self._names(tree, {})
        self._function_names: dict[int, dict[str, Kind]] = {}

    def _read_imports(self) -> None:
        for node in ast.walk(self.tree):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                package, _, kind = node.module.partition(".")
                if kind != "msg" or package not in self.known_packages:
                    continue
                names = message_names(self.dialect, package)
                for alias in node.names:
                    if alias.name == "*":
                        continue
                    if alias.name not in names:
                        self.bad_imports.append((node, alias, package, alias.name))
                    elif info := message_info(self.dialect, f"{package}/{alias.name}"):
                        self.classes[alias.asname or alias.name] = info
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    package, _, kind = alias.name.partition(".")
                    if kind == "msg" and package in self.known_packages:
                        self.modules[alias.asname or package] = package

    def _read_callbacks(self) -> None:
        """Callbacks given to a Subscriber or create_subscription get that message."""
        for node in ast.walk(self.tree):
            if not isinstance(node, ast.Call):
                continue
            name = called_name(node)
            index = CALLBACK_INDEX.get(name or "")
            if index is None or len(node.args) <= index:
                continue
            class_index = (ROSPY_TOPIC_CALLS | RCLPY_TOPIC_CALLS)[name][1]
            kind = self.kind(node.args[class_index], {})
            callback = node.args[index]
            callback_name = getattr(callback, "attr", None) or getattr(callback, "id", None)
            if not callback_name:
                continue
            message = kind.message if kind and kind.what == "class" else None
            if self.callback_types.get(callback_name, message) != message:
                message = None  # one callback for two types: not followed
            self.callback_types[callback_name] = message
        for node in self.tree.body:
            if isinstance(node, ast.FunctionDef) and node.name == "step" and node.args.args:
                self.step_param = node.args.args[0].arg

    def names(self, function: ast.AST | None) -> dict[str, Kind]:
        if function is None:
            return self.module_names
        key = id(function)
        if key not in self._function_names:
            self._function_names[key] = self._names(function, self.module_names)
        return self._function_names[key]

    def _names(self, scope: ast.AST, outer: dict[str, Kind]) -> dict[str, Kind]:
        found: dict[str, Kind | None] = {}

        def give(name: str, kind: Kind | None) -> None:
            if name in found and found[name] != kind:
                found[name] = None  # two different types: unknown
            else:
                found[name] = kind

        if isinstance(scope, ast.FunctionDef | ast.AsyncFunctionDef):
            params = [*scope.args.posonlyargs, *scope.args.args, *scope.args.kwonlyargs]
            positional = [p for p in params if p.arg not in ("self", "cls")]
            first = positional[0].arg if positional else None
            for param in params:
                kind = self._annotation(param.annotation)
                if kind is None and param.arg == first:
                    kind = self._parameter_kind(scope)
                give(param.arg, kind)
        for node in scope_nodes(scope):
            if isinstance(node, ast.Assign):
                kind = self.kind(node.value, {**outer, **_known(found)})
                for target in node.targets:
                    if isinstance(target, ast.Name):
                        give(target.id, kind)
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                give(node.target.id, self._annotation(node.annotation))
            elif isinstance(node, ast.For | ast.AsyncFor | ast.AugAssign | ast.NamedExpr):
                _forget(node.target, give)
            elif isinstance(node, ast.With | ast.AsyncWith):
                for item in node.items:
                    if item.optional_vars is not None:
                        _forget(item.optional_vars, give)
            elif isinstance(node, ast.Global | ast.Nonlocal):
                for name in node.names:
                    give(name, None)
        return {**outer, **_known(found), **{n: None for n, k in found.items() if k is None}}

    def _parameter_kind(self, function: ast.FunctionDef | ast.AsyncFunctionDef) -> Kind | None:
        """What the first parameter of a callback or of the step function receives."""
        if function.name in self.callback_types:
            message = self.callback_types[function.name]
            return Kind("instance", message) if message is not None else None
        if function.name == "step" and function in self.tree.body:
            return Kind("obs")
        return None

    def _annotation(self, annotation: ast.expr | None) -> Kind | None:
        kind = self.kind(annotation, {}) if annotation is not None else None
        if kind and kind.what == "class":
            return Kind("instance", kind.message)
        return None

    def kind(self, expr: ast.AST, names: dict[str, Kind | None]) -> Kind | None:
        """What `expr` holds, or None when the checks cannot tell."""
        if isinstance(expr, ast.Name):
            if expr.id in names:
                return names[expr.id]
            if expr.id in self.classes:
                return Kind("class", self.classes[expr.id])
            return None
        if isinstance(expr, ast.Call):
            callee = self.kind(expr.func, names)
            if callee and callee.what == "class":
                return Kind("instance", callee.message)
            return None
        if isinstance(expr, ast.Subscript):
            holder = self.kind(expr.value, names)
            if holder and holder.what == "obs" and isinstance(expr.slice, ast.Constant):
                return self._topic_kind(str(expr.slice.value).lstrip("/"))
            if holder and holder.what == "array" and not isinstance(expr.slice, ast.Slice):
                return Kind("instance", holder.message)
            return None
        if isinstance(expr, ast.Attribute):
            return self._attribute_kind(expr, names)
        return None

    def _topic_kind(self, topic: str) -> Kind | None:
        """The message on a sensor topic of the step API's obs (ROS 1 classes, as it gives)."""
        type_name = self.obs_types.get(topic)
        info = message_info(ROS1, type_name) if type_name else None
        return Kind("instance", info) if info else None

    def _attribute_kind(self, expr: ast.Attribute, names: dict[str, Kind | None]) -> Kind | None:
        module = _dotted(expr.value)
        if module is not None:  # geometry_msgs.msg.Twist
            package = self.modules.get(module) or self.modules.get(module.removesuffix(".msg"))
            if package is not None and (module.endswith(".msg") or module in self.modules):
                info = message_info(self.dialect, f"{package}/{expr.attr}")
                return Kind("class", info) if info else None
        holder = self.kind(expr.value, names)
        if holder is not None and holder.what == "obs":
            return self._topic_kind(expr.attr)
        if holder is None or holder.what != "instance" or holder.message is None:
            return None
        field = holder.message.field(expr.attr)
        if field is None or field.message_type is None:
            return None
        info = message_info(self.dialect, field.message_type)
        if info is None:
            return None
        return Kind("array" if field.is_array else "instance", info)


def _forget(target: ast.AST, give) -> None:
    """Names bound by a loop, `with ... as`, `+=` or `:=`: their type is not followed."""
    for node in ast.walk(target):
        if isinstance(node, ast.Name):
            give(node.id, None)


def _known(found: dict[str, Kind | None]) -> dict[str, Kind]:
    return {name: kind for name, kind in found.items() if kind is not None}


def _dotted(expr: ast.AST) -> str | None:
    parts = []
    while isinstance(expr, ast.Attribute):
        parts.append(expr.attr)
        expr = expr.value
    if isinstance(expr, ast.Name):
        return ".".join([expr.id, *reversed(parts)])
    return None


__all__ = ["ROS1", "ROS2", "Kind", "TypeScope", "dialect_of", "functions", "scope_nodes"]
