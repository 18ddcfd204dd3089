"""The two lexical layers of a roslaunch file: XML elements that remember their line, and
substitution args (`$(arg x)`, `$(find pkg)`, ...).

Substitution args follow roslaunch's substitution_args.py and the roslaunch XML page
(http://wiki.ros.org/roslaunch/XML, "substitution args"): `$(arg)`, `$(env)`, `$(optenv)`,
`$(anon)` and `$(dirname)` resolve first, `$(find)` after, left to right. `$(eval ...)` is
Python's eval in roslaunch; a web server does not run it, so it is refused with a sentence.

YAML is read as rosparam reads it (tools/rosparam/src/rosparam/__init__.py): yaml.safe_load
plus the angle tags, `deg(90)` / `!degrees 90` (to radians) and `rad(pi/2)` / `!radians pi/2`.
rosparam evaluates a radian expression with Python's eval; here it is arithmetic on numbers and
`pi` only (+ - * / and parentheses), which covers what rosparam documents.
`$(env VAR)` reads the server's environment in roslaunch: refused too (a run has no shell
environment); `$(optenv VAR default)` gives its default.
"""

from __future__ import annotations

import ast
import math
import operator
import re
import xml.parsers.expat
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import yaml

from sandbox import bounded_yaml, python_ast

MAX_LAUNCH_BYTES = 256 * 1024  # [bytes] a launch file larger than this is not hand-written
_SUBSTITUTION = re.compile(r"\$\(([^()]*)\)")
_PARAM_TYPES = ("auto", "str", "string", "int", "double", "bool", "boolean", "yaml")
_COMMANDS = ("find", "env", "optenv", "dirname", "anon", "arg", "eval")


class XmlError(ValueError):
    """The text is not well-formed XML (or declares entities); `line` is where [1-based]."""

    def __init__(self, message: str, line: int) -> None:
        super().__init__(message)
        self.line = line


class SubstitutionError(ValueError):
    """A substitution arg cannot be resolved; the message says which and why."""


class ArgNotSet(SubstitutionError):
    """`$(arg name)` of an arg declared without a value and not passed in."""


@dataclass
class Element:
    """One XML element: tag, attributes in order, child elements, text, and its line [1-based]."""

    tag: str
    attrs: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)
    text: str = ""


def parse_xml(text: str) -> Element:
    """The root element of `text`; XmlError if it is not well-formed XML.
    Expat does not fetch external entities; DOCTYPE internal entities are refused outright
    (entity expansion is the one way a small XML file becomes a large one)."""
    parser = xml.parsers.expat.ParserCreate()
    stack: list[Element] = []
    roots: list[Element] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        element = Element(tag, dict(attrs), parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    def end(_tag: str) -> None:
        stack.pop()

    def data(chunk: str) -> None:
        if stack:
            stack[-1].text += chunk

    def entity(*_args: object) -> None:
        raise XmlError("entity declarations are not allowed in a launch file", 0)

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = data
    parser.EntityDeclHandler = entity
    try:
        parser.Parse(text, True)
    except xml.parsers.expat.ExpatError as error:
        message = xml.parsers.expat.ErrorString(error.code)
        raise XmlError(f"this is not well-formed XML ({message})", error.lineno) from None
    except XmlError as error:
        raise XmlError(str(error), parser.CurrentLineNumber) from None
    return roots[0]


@dataclass
class Substitutions:
    """What `$(...)` can see: the args in scope, the workspace's package folders, the file
    being read, and the anonymous names given so far (one per id for the whole launch)."""

    args: dict[str, str | None]
    find: Callable[[str], str]
    dirname: str
    anon: dict[str, str]
    make_anon: Callable[[str], str]

    def resolve(self, text: str | None) -> str | None:
        if text is None or "$" not in text:
            return text
        if text.startswith("$(eval ") and text.endswith(")"):
            raise SubstitutionError(
                "$(eval ...) runs Python in roslaunch and is not run here; compute the value "
                "with $(arg ...) and if/unless, or pass it as a launch argument"
            )
        first = self._replace(text, ("env", "optenv", "dirname", "anon", "arg"))
        return self._replace(first, ("find",))

    def _replace(self, text: str, commands: tuple[str, ...]) -> str:
        def one(match: re.Match[str]) -> str:
            words = match.group(1).split()
            if not words or words[0] not in _COMMANDS:
                raise SubstitutionError(
                    f"unknown substitution '$({match.group(1)})'; roslaunch knows "
                    + ", ".join(f"$({c} ...)" for c in _COMMANDS[:-1])
                )
            command, params = words[0], words[1:]
            if command not in commands:
                return match.group(0)
            return getattr(self, "_" + command)(params, match.group(0))

        return _SUBSTITUTION.sub(one, text)

    def _arg(self, params: list[str], whole: str) -> str:
        if len(params) != 1:
            raise SubstitutionError(f"{whole} takes exactly one arg name")
        name = params[0]
        if name not in self.args:
            declared = ", ".join(sorted(self.args)) or "none"
            raise SubstitutionError(
                f"arg '{name}' is not declared here; declare it with <arg name=\"{name}\" "
                f'default="..."/> (args declared here: {declared})'
            )
        value = self.args[name]
        if value is None:
            raise ArgNotSet(f"arg '{name}' has no value: give it a default, or pass {name}:=VALUE")
        return value

    def _env(self, params: list[str], whole: str) -> str:
        raise SubstitutionError(
            f"{whole} reads an environment variable, and a run has no shell environment; "
            "use $(optenv VAR default) or a launch argument"
        )

    def _optenv(self, params: list[str], whole: str) -> str:
        if not params:
            raise SubstitutionError(f"{whole} must name an environment variable")
        return " ".join(params[1:])

    def _dirname(self, params: list[str], whole: str) -> str:
        return self.dirname

    def _anon(self, params: list[str], whole: str) -> str:
        if len(params) != 1:
            raise SubstitutionError(f"{whole} takes exactly one name")
        if params[0] not in self.anon:
            self.anon[params[0]] = self.make_anon(params[0])
        return self.anon[params[0]]

    def _find(self, params: list[str], whole: str) -> str:
        if len(params) != 1:
            raise SubstitutionError(f"{whole} takes exactly one package name")
        return self.find(params[0])


class RosparamLoader(yaml.SafeLoader):
    """yaml.SafeLoader with rosparam's angle tags."""


_OPERATORS = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.USub: operator.neg,
    ast.UAdd: operator.pos,
}


def _arithmetic(node: ast.AST) -> float:
    if isinstance(node, ast.Expression):
        return _arithmetic(node.body)
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
        return float(node.value)
    if isinstance(node, ast.Name) and node.id == "pi":
        return math.pi
    if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
        return _OPERATORS[type(node.op)](_arithmetic(node.left), _arithmetic(node.right))
    if isinstance(node, ast.UnaryOp) and type(node.op) in _OPERATORS:
        return _OPERATORS[type(node.op)](_arithmetic(node.operand))
    raise ValueError("not arithmetic")


def _angle(text: str, prefix: str) -> float:
    text = text.strip()
    if text.startswith(prefix + "(") and text.endswith(")"):
        text = text[len(prefix) + 1 : -1]
    try:
        return _arithmetic(python_ast.parse(text, mode="eval"))
    except (SyntaxError, ValueError, ZeroDivisionError):
        raise yaml.YAMLError(
            f"invalid angle '{text}': use a number or arithmetic with pi, e.g. rad(pi/2)"
        ) from None


def _radians(loader: yaml.SafeLoader, node: yaml.Node) -> float:
    return _angle(str(loader.construct_scalar(node)), "rad")  # type: ignore[arg-type]


def _degrees(loader: yaml.SafeLoader, node: yaml.Node) -> float:
    return math.radians(_angle(str(loader.construct_scalar(node)), "deg"))  # type: ignore[arg-type]


RosparamLoader.add_constructor("!radians", _radians)
RosparamLoader.add_constructor("!degrees", _degrees)
RosparamLoader.add_implicit_resolver("!degrees", re.compile(r"^deg\([^\)]*\)$"), ["d"])
RosparamLoader.add_implicit_resolver("!radians", re.compile(r"^rad\([^\)]*\)$"), ["r"])


def load_yaml(text: str) -> Any:
    """YAML as rosparam reads it, its aliases bounded (sandbox/bounded_yaml.py: this runs in the
    run worker, outside any sandbox); yaml.YAMLError on bad input."""
    return bounded_yaml.load(text, RosparamLoader)  # a SafeLoader subclass: no Python objects


def convert_value(value: str, kind: str) -> Any:
    """A <param> value as roslaunch types it (loader.convert_value): `auto` tries int, then
    float (a '.' in it), then true/false, else a string; ValueError with a sentence."""
    kind = kind.lower().strip()
    if kind not in _PARAM_TYPES:
        raise ValueError(f"unknown param type '{kind}'; use one of {', '.join(_PARAM_TYPES)}")
    if kind == "auto":
        try:
            if "." in value:
                return float(value)
            if "_" not in value:  # roslaunch keeps 1_000 a string (Python would read 1000)
                return int(value)
        except ValueError:
            pass
        if value.lower() in ("true", "false"):
            return value.lower() == "true"
        return value
    if kind in ("str", "string"):
        return value
    if kind == "int":
        try:
            return int(value)
        except ValueError:
            raise ValueError(f"'{value}' is not an int") from None
    if kind == "double":
        try:
            return float(value)
        except ValueError:
            raise ValueError(f"'{value}' is not a double") from None
    if kind in ("bool", "boolean"):
        lowered = value.lower().strip()
        if lowered in ("true", "1", "false", "0"):
            return lowered in ("true", "1")
        raise ValueError(f"'{value}' is not a bool (true, false, 1 or 0)")
    try:
        return load_yaml(value)
    except yaml.YAMLError as error:
        raise ValueError(f"the value is not valid YAML: {error}") from None
