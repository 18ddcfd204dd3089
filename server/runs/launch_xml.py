"""The two lexical layers of a roslaunch file: XML elements that remember their line, and
substitution args (`$(arg x)`, `$(find pkg)`, ...).

Substitution args follow roslaunch's substitution_args.py and the roslaunch XML page
(http://wiki.ros.org/roslaunch/XML, "substitution args"): `$(arg)`, `$(env)`, `$(optenv)`,
`$(anon)` and `$(dirname)` resolve first, `$(find)` after, left to right. `$(eval ...)` is
Python's eval in roslaunch; a web server does not run it, so it is refused with a sentence.
`$(env VAR)` reads the server's environment in roslaunch: refused too (a run has no shell
environment); `$(optenv VAR default)` gives its default.
"""

from __future__ import annotations

import re
import xml.parsers.expat
from collections.abc import Callable
from dataclasses import dataclass, field

MAX_LAUNCH_BYTES = 256 * 1024  # [bytes] a launch file larger than this is not hand-written
_SUBSTITUTION = re.compile(r"\$\(([^()]*)\)")
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
