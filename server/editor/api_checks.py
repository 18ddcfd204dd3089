"""Checks that know RoboDojo's APIs, run on the student's text without executing it: message
fields that do not exist, topic names the exercise's robot does not have (and types that do not
match its topics), message names a `<pkg>.msg` module lacks, and the step API's contract
(`def step(obs)`, `SUBSCRIBE`, `RATE_HZ`). Ruff covers Python itself (lint.py).

Every finding says what is wrong and what there is instead, as the sandbox's own errors do at
run time ("`Twist` has no field `linear_x`; fields: linear, angular").
"""

from __future__ import annotations

import ast
import difflib
from functools import cache

from sandbox.step_api import MAX_RATE_HZ
from server.editor.api_types import (
    RCLPY_TOPIC_CALLS,
    ROS2,
    ROSPY_TOPIC_CALLS,
    Kind,
    TypeScope,
    called_name,
    dialect_of,
    functions,
    scope_nodes,
)
from server.editor.context import RobotTopics, Topics
from server.editor.diagnostics import Diagnostic, Severity, char_column

ACCEPTED_ROS2 = frozenset({("geometry_msgs/Twist", "geometry_msgs/TwistStamped")})
OBS_MEMBERS = frozenset({"time", "get", "keys"})  # sandbox.step_api.Observation's own names


def _hint(word: str, candidates) -> str:
    close = difflib.get_close_matches(word, list(candidates), n=1)
    return f"Did you mean `{close[0]}`? " if close else ""


class Checker:
    def __init__(self, code: str, tree: ast.Module, robot: RobotTopics | None) -> None:
        self.lines = code.splitlines()
        self.tree = tree
        self.robot = robot
        obs_types = {t: robot.types[t] for t in robot.sensors} if robot else {}
        self.types = TypeScope(tree, dialect_of(code), obs_types)
        self.found: list[Diagnostic] = []
        self.subscribed = self._subscribe_list()
        # ROS 2 Jazzy's TurtleBot3 takes TwistStamped on cmd_vel, and so does every Twist
        # command topic of a ROS 2 run (server/runs/dialect.py).
        self.accepted = ACCEPTED_ROS2 if self.types.dialect == ROS2 else frozenset()

    def add(self, node: ast.AST, severity: Severity, rule: str, message: str,
            start_col: int | None = None) -> None:  # fmt: skip
        line, end_line = node.lineno, node.end_lineno or node.lineno
        column = node.col_offset if start_col is None else start_col
        self.found.append(
            Diagnostic(
                line,
                char_column(self.lines, line, column),
                end_line,
                char_column(self.lines, end_line, node.end_col_offset or column),
                severity,
                rule,
                message,
            )
        )

    def run(self) -> list[Diagnostic]:
        self._imports()
        for scope in [None, *functions(self.tree)]:
            names = self.types.names(scope)
            for node in scope_nodes(scope or self.tree):
                if isinstance(node, ast.Attribute):
                    self._attribute(node, names)
                elif isinstance(node, ast.Subscript):
                    self._obs_key(node, names)
                elif isinstance(node, ast.Call):
                    self._call(node, names)
        self._step_contract()
        return sorted(self.found, key=lambda d: (d.line, d.column))

    # -- message fields ------------------------------------------------------------------------

    def _attribute(self, node: ast.Attribute, names: dict) -> None:
        if node.attr.startswith("_"):
            return
        holder: Kind | None = self.types.kind(node.value, names)
        if holder is None:
            return
        attr_col = max(node.end_col_offset - len(node.attr), 0) if node.end_col_offset else None
        if holder.what == "obs":
            self._obs_name(node, node.attr, attr_col)
        elif holder.what == "instance" and holder.message is not None:
            info = holder.message
            if node.attr not in info.attributes:
                self.add(node, Severity.ERROR, "robodojo-field",
                         f"`{info.short_name}` has no field `{node.attr}`. "
                         f"{_hint(node.attr, info.attributes)}Fields: {info.field_names()}.",
                         attr_col)  # fmt: skip

    def _call(self, node: ast.Call, names: dict) -> None:
        callee = self.types.kind(node.func, names)
        if callee is not None and callee.what == "class" and callee.message is not None:
            info = callee.message
            for keyword in node.keywords:
                if keyword.arg is not None and info.field(keyword.arg) is None:
                    self.add(keyword, Severity.ERROR, "robodojo-field",
                             f"`{info.short_name}` has no field `{keyword.arg}`. "
                             f"{_hint(keyword.arg, [f.name for f in info.fields])}"
                             f"Fields: {info.field_names()}.")  # fmt: skip
        self._topic_call(node, names)

    def _imports(self) -> None:
        for node, _alias, package, name in self.types.bad_imports:
            from server.editor.messages import message_names

            valid = message_names(self.types.dialect, package)
            close = difflib.get_close_matches(name, valid, n=3)
            hint = f"Did you mean {' or '.join(f'`{c}`' for c in close)}?" if close else (
                f"It has {len(valid)} types, e.g. {', '.join(valid[:8])}.")  # fmt: skip
            self.add(node, Severity.ERROR, "robodojo-import",
                     f"`{package}.msg` has no message `{name}`. {hint}")  # fmt: skip

    # -- topics ---------------------------------------------------------------------------------

    def _topic_call(self, node: ast.Call, names: dict) -> None:
        name = called_name(node)
        if name is None or self.robot is None:
            return
        positions = ROSPY_TOPIC_CALLS.get(name) or RCLPY_TOPIC_CALLS.get(name)
        if positions is None or len(node.args) <= max(positions):
            return
        topic_arg, class_arg = node.args[positions[0]], node.args[positions[1]]
        if not isinstance(topic_arg, ast.Constant) or not isinstance(topic_arg.value, str):
            return
        topic = topic_arg.value.lstrip("/")
        if "~" in topic or ("/" in topic and topic not in self.robot.types):
            return  # a private or namespaced name: another node's business
        if topic not in self.robot.types:
            self._unknown_topic(topic_arg, topic)
            return
        kind = self.types.kind(class_arg, names)
        expected = self.robot.types[topic]
        given = kind.message.type_name if kind and kind.what == "class" and kind.message else None
        if given is not None and given != expected and (expected, given) not in self.accepted:
            self.add(class_arg, Severity.ERROR, "robodojo-topic-type",
                     f"Topic `{topic}` of robot {self.robot.robot} carries {expected}, not "
                     f"{given}; use {expected.split('/')[1]} "
                     f"(from {expected.split('/')[0]}.msg).")  # fmt: skip

    def _unknown_topic(self, node: ast.AST, topic: str) -> None:
        """A name close to one of the robot's topics is likely a typo, and a topic of another
        robot a mix-up; any other name is likely a topic between the student's own nodes."""
        close = difflib.get_close_matches(topic, list(self.robot.types), n=1)
        owners = [r for r, names in _other_robots_topics().items() if topic in names]
        if close:
            why = f"Did you mean `{close[0]}`?"
        elif owners and self.robot.robot not in owners:
            why = f"`{topic}` is a topic of {' and '.join(owners)}."
        else:
            return
        self.add(node, Severity.WARNING, "robodojo-topic",
                 f"Robot {self.robot.robot} has no topic `{topic}`. {why} Its topics: "
                 f"{self.robot.listing()}. (A topic between your own nodes is fine.)")  # fmt: skip

    def _obs_key(self, node: ast.Subscript, names: dict) -> None:
        holder = self.types.kind(node.value, names)
        key = node.slice
        if holder is not None and holder.what == "obs" and isinstance(key, ast.Constant):
            self._obs_name(key, str(key.value).lstrip("/"), None)

    def _obs_name(self, node: ast.AST, name: str, column: int | None) -> None:
        if self.robot is None or name in OBS_MEMBERS:
            return
        sensors = self.robot.sensors
        if name not in sensors:
            self.add(node, Severity.ERROR, "robodojo-topic",
                     f"obs has no `{name}`: robot {self.robot.robot}'s sensor topics are "
                     f"{', '.join(sensors)} (and obs.time). {_hint(name, sensors)}".rstrip(),
                     column)  # fmt: skip
        elif self.subscribed is not None and name not in self.subscribed:
            self.add(node, Severity.ERROR, "robodojo-topic",
                     f"obs has no `{name}`: it is not in SUBSCRIBE. Add it there, e.g. "
                     f"SUBSCRIBE = {[*self.subscribed, name]!r}.", column)  # fmt: skip

    # -- the step API ---------------------------------------------------------------------------

    def _top_assignment(self, name: str) -> ast.Assign | None:
        for node in self.tree.body:
            if isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id == name for t in node.targets
            ):
                return node
        return None

    def _subscribe_list(self) -> list[str] | None:
        node = self._top_assignment("SUBSCRIBE")
        if node is None or not isinstance(node.value, ast.List | ast.Tuple):
            return None
        items = [e.value for e in node.value.elts if isinstance(e, ast.Constant)]
        if not all(isinstance(i, str) for i in items) or len(items) != len(node.value.elts):
            return None
        return [i.lstrip("/") for i in items]

    def _step_contract(self) -> None:
        step = _top_function(self.tree, "step")
        if step is None:
            return
        if isinstance(step, ast.AsyncFunctionDef):
            self.add(step, Severity.ERROR, "robodojo-step",
                     "step must be a plain function (def step(obs):), not async; RoboDojo "
                     "calls it once per period and waits for its answer.")  # fmt: skip
        args = step.args
        positional = [*args.posonlyargs, *args.args]
        required = len(positional) - len(args.defaults)
        required_keywords = any(d is None for d in args.kw_defaults)
        if required > 1 or (not positional and args.vararg is None) or required_keywords:
            self.add(_def_line(step), Severity.ERROR, "robodojo-step",
                     f"step must take one argument, the observation (def step(obs):); yours "
                     f"takes {_arguments(step)}.")  # fmt: skip
        setup = _top_function(self.tree, "setup")
        if setup is not None and len(setup.args.args) - len(setup.args.defaults) > 1:
            self.add(_def_line(setup), Severity.ERROR, "robodojo-step",
                     f"setup takes at most one argument, info (def setup(info):); yours takes "
                     f"{_arguments(setup)}.")  # fmt: skip
        self._rate()
        self._subscribe_names()

    def _rate(self) -> None:
        node = self._top_assignment("RATE_HZ")
        if node is None or not isinstance(node.value, ast.Constant):
            return
        rate = node.value.value
        number = isinstance(rate, int | float) and not isinstance(rate, bool)
        if not number or not 0 < rate <= MAX_RATE_HZ:
            self.add(node.value, Severity.ERROR, "robodojo-step",
                     f"RATE_HZ must be a number of calls per second, 0 < RATE_HZ <= "
                     f"{MAX_RATE_HZ:g}; it is {rate!r}.")  # fmt: skip

    def _subscribe_names(self) -> None:
        node = self._top_assignment("SUBSCRIBE")
        if node is None or self.robot is None or not isinstance(node.value, ast.List | ast.Tuple):
            return
        for item in node.value.elts:
            if isinstance(item, ast.Constant) and isinstance(item.value, str):
                name = item.value.lstrip("/")
                if name not in self.robot.sensors:
                    self.add(item, Severity.ERROR, "robodojo-topic",
                             f"SUBSCRIBE names `{name}`, which is not a sensor topic of robot "
                             f"{self.robot.robot}. {_hint(name, self.robot.sensors)}Sensor "
                             f"topics: {', '.join(self.robot.sensors)}.")  # fmt: skip


@cache
def _other_robots_topics() -> dict[str, frozenset[str]]:
    from server.editor.context import robot_catalog

    return {r: frozenset(name for name, _, _ in rows) for r, rows in robot_catalog().items()}


def _top_function(tree: ast.Module, name: str) -> ast.FunctionDef | ast.AsyncFunctionDef | None:
    return next(
        (
            n
            for n in tree.body
            if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef) and n.name == name
        ),
        None,
    )


def _def_line(function: ast.FunctionDef | ast.AsyncFunctionDef) -> ast.AST:
    """The `def name(...)` part of a function, to underline instead of its whole body."""
    marker = ast.Name(id=function.name)
    marker.lineno = marker.end_lineno = function.lineno
    marker.col_offset = function.col_offset
    marker.end_col_offset = function.col_offset + len("def ") + len(function.name)
    return marker


def _arguments(function: ast.FunctionDef | ast.AsyncFunctionDef) -> str:
    names = [a.arg for a in (*function.args.posonlyargs, *function.args.args)]
    if not names:
        return "none"
    return f"{len(names)} ({', '.join(names)})"


def check(
    code: str, tree: ast.Module, robot_id: str | None, extra: Topics = ()
) -> list[Diagnostic]:
    """Our API's diagnostics for `code`, parsed as `tree`, for a run of `robot_id` (None: not
    known) whose built-in nodes publish `extra`."""
    return Checker(code, tree, RobotTopics.of(robot_id, extra)).run()
