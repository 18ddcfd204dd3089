"""Completion, signature help and hover from jedi, which reads the student's text and the source
of the modules it imports; it never runs them. jedi sees what a node sees: the dialect's
`rospy` or `rclpy` (sandbox/ros_compat, sandbox/ros_compat2), the message packages as source
stubs (stubs.py) and the installed libraries (numpy, math, ...).

Static only: `jedi.Script`, never `jedi.Interpreter` (which evaluates live objects), with an
in-process environment (no helper interpreter), and `load_unsafe_extensions` off, so jedi does
not import compiled modules from the project's folders; for the standard library's and numpy's
compiled parts it reads typeshed and the installed packages' stubs.

jedi sees only the paths it is given: modules are looked for there alone (not through this
process's import machinery, whose editable-install finder and imported modules named the
server's own packages), the sys.path modifications it would follow in the student's text
(`sys.path.append("/anywhere")`) are ignored, and file names are completed inside the project
folder only (`open("/root/` offers nothing). In the lab this runs inside the
editor's sandbox (server/editor/host.py), whose walls show nothing of the server besides.

The step API's `obs` is given its robot's type by a one-line prelude: the analysed text is
`from _robodojo_step_<robot> import Observation ...` followed by the student's file, with
`def step(obs` annotated. Positions are shifted by that line and back.
"""

from __future__ import annotations

import importlib.machinery
import os
import re
import sys
from pathlib import Path

import jedi

from server.editor.api_types import dialect_of
from server.editor.context import Topics
from server.editor.limits import LIMITS
from server.editor.messages import ROS2
from server.editor.stubs import SANDBOX_DIR, step_module

STEP_DEF = re.compile(r"^def\s+step\s*\(\s*([A-Za-z_]\w*)\s*(?=[,)])", re.MULTILINE)
SETUP_DEF = re.compile(r"^def\s+setup\s*\(\s*([A-Za-z_]\w*)\s*(?=[,)])", re.MULTILINE)
OBS_ALIAS, INFO_ALIAS = "_RoboDojoObservation", "_RoboDojoNodeInfo"
HIDDEN_PREFIXES = ("_RoboDojo", "_robodojo")
KINDS = {  # jedi's completion types -> the contract's
    "module": "module",
    "class": "class",
    "function": "function",
    "keyword": "keyword",
    "property": "property",
    "instance": "variable",
    "statement": "variable",
    "param": "variable",
    "path": "text",
}


class Analyser:
    """jedi over a file, with a project per dialect (their `std_msgs` differ).

    `project_dir`: the folder the student's file is analysed as being in, and the only one
    whose file names are completed (default: `stub_root/project`); `library_root`: the folder
    that holds the `sandbox` package rospy's source imports (default: `stub_root/common`)."""

    def __init__(
        self,
        stub_root: Path,
        robots: tuple[str, ...],
        cache_dir: Path | None = None,
        project_dir: Path | None = None,
        library_root: Path | None = None,
    ) -> None:
        self.stub_root = stub_root
        self.robots = robots
        self.project_dir = project_dir or stub_root / "project"
        confine_jedi(self.project_dir)
        # jedi keeps what it parsed (numpy's, rospy's source) on disk: a fresh worker, or one
        # that replaced a killed one, starts warm when this folder outlives it.
        jedi.settings.cache_directory = str(cache_dir or stub_root / "jedi-cache")
        jedi.settings.call_signatures_validity = 0.0  # each request is a new text
        # The interpreter's own library and installed packages; not the working folder, so
        # the server's own packages are not offered to students.
        stdlib = f"/lib/python{sys.version_info[0]}.{sys.version_info[1]}"
        libraries = [p for p in sys.path if p and ("site-packages" in p or p.endswith(
            (stdlib, ".zip", "lib-dynload")))]  # fmt: skip
        common = str(library_root or stub_root / "common")
        self.environment = jedi.InterpreterEnvironment()
        self.projects = {
            version: jedi.Project(
                self.project_dir,
                sys_path=[str(stub_root / folder), str(SANDBOX_DIR / compat), common, *libraries],
                smart_sys_path=False,
                load_unsafe_extensions=False,
            )
            for version, folder, compat in ((1, "ros1", "ros_compat"), (2, "ros2", "ros_compat2"))
        }

    def _script(self, code: str, robot: str | None, extra: Topics) -> tuple[jedi.Script, int, str]:
        """The script for `code` and how many lines its prelude adds."""
        dialect = dialect_of(code)
        prelude, text = 0, code
        step = STEP_DEF.search(code)
        if step and robot in self.robots and dialect != ROS2:
            module = step_module(self.stub_root, robot, extra)
            text = code[: step.end(1)] + f": {OBS_ALIAS}" + code[step.end(1) :]
            setup = SETUP_DEF.search(text)
            if setup:
                text = text[: setup.end(1)] + f": {INFO_ALIAS}" + text[setup.end(1) :]
            prelude_line = (
                f"from {module} import NodeInfo as {INFO_ALIAS}, Observation as {OBS_ALIAS}"
            )
            text = f"{prelude_line}\n{text}"
            prelude = 1
        path = self.project_dir / "controller.py"
        script = jedi.Script(
            text, path=path, project=self.projects[dialect], environment=self.environment
        )
        return script, prelude, text

    @staticmethod
    def _column(text: str, line: int, column: int) -> int:
        """The column in the analysed text: a `def step(obs` line grew by its annotation."""
        lines = text.split("\n")
        if not 1 <= line <= len(lines):
            return column
        return min(column + _added_on_line(lines[line - 1]), len(lines[line - 1]))

    def complete(
        self, code: str, line: int, column: int, robot: str | None, extra: Topics = ()
    ) -> dict:
        script, prelude, text = self._script(code, robot, extra)
        line = _clamp_line(code, line)
        at_line, at_column = line + prelude, self._column(text, line + prelude, column)
        typed = _typed_prefix(code, line, column)
        out = []
        for completion in script.complete(at_line, at_column):
            name = completion.name
            if name.startswith(HIDDEN_PREFIXES) or (
                name.startswith("_") and not typed.startswith("_")
            ):
                continue
            out.append((completion, name))
            if len(out) >= LIMITS.max_completions:
                break
        completions = []
        for index, (completion, name) in enumerate(out):
            documented = index < LIMITS.documented_completions
            completions.append(_completion_json(completion, name, documented, self.stub_root))
        signature = self._signature(script, at_line, at_column)
        return {"completions": completions, "signature": signature}

    @staticmethod
    def _signature(script: jedi.Script, line: int, column: int) -> dict | None:
        signatures = script.get_signatures(line, column)
        if not signatures:
            return None
        signature = signatures[0]
        return {
            "label": signature.to_string(),
            "params": [p.to_string() for p in signature.params],
            "active": signature.index if signature.index is not None else -1,
            "doc": _trim(signature.docstring(raw=True)),
        }

    def hover(
        self, code: str, line: int, column: int, robot: str | None, extra: Topics = ()
    ) -> dict:
        script, prelude, text = self._script(code, robot, extra)
        line = _clamp_line(code, line)
        at_line, at_column = line + prelude, self._column(text, line + prelude, column)
        for name in script.goto(at_line, at_column, follow_imports=True):
            text_out = self._hover_text(name)
            if text_out:
                return {"text": _trim(text_out)}
        for name in script.infer(at_line, at_column):
            text_out = self._hover_text(name)
            if text_out:
                return {"text": _trim(text_out)}
        return {"text": None}

    def _hover_text(self, name) -> str | None:
        if name.name.startswith(HIDDEN_PREFIXES):
            return None
        doc = name.docstring()
        if doc or name.type not in ("statement", "param", "instance"):
            return doc or None
        values = name.infer()[:3]  # a variable: say what it holds
        if not values:
            return None
        if self._in_stubs(values[0]) and values[0].docstring():
            return f"{name.name}: {values[0].docstring()}"
        return f"{name.name}: {' | '.join(v.name for v in values)}"

    def _in_stubs(self, name) -> bool:
        path = name.module_path
        return path is not None and Path(path).is_relative_to(self.stub_root)


class _ConfinedOs:
    """The `os` jedi's file-name completion sees: listing a folder outside `root` finds
    nothing (an absolute path, `..`, a link out)."""

    def __init__(self, root: Path) -> None:
        self._root = os.path.realpath(root)

    def __getattr__(self, name: str):
        return getattr(os, name)

    def scandir(self, path):
        real = os.path.realpath(path)
        if real != self._root and not real.startswith(self._root + os.sep):
            raise FileNotFoundError(path)
        return os.scandir(real)


def _find_on_given_path(string, path=None, full_name=None, is_global_search=True):
    """jedi's `_find_module`, asking only for the interpreter's built-in modules and the path
    jedi was given: not the process's other finders (an editable install's named the server's
    own packages) nor sys.modules (the modules this process has imported)."""
    from jedi.inference.compiled.subprocess import functions

    if path is None and string in sys.builtin_module_names:
        spec = importlib.machinery.BuiltinImporter.find_spec(string)
    else:
        spec = importlib.machinery.PathFinder.find_spec(string, path)
    if spec is None:
        raise ImportError(f"no module {string} on the analysis' path")
    if spec.loader is None and not spec.has_location:  # a namespace package
        paths = spec.submodule_search_locations._path
        return functions.ImplicitNSInfo(string if not path else full_name, paths), True
    return functions._from_loader(spec.loader, string)


def confine_jedi(project_dir: Path) -> None:
    """jedi from now on in this process: modules found on its given path only, no sys.path
    taken from the analysed text, and file names completed within `project_dir` only (module
    docstring)."""
    import jedi.api.file_name
    import jedi.inference.compiled.subprocess.functions
    import jedi.inference.sys_path

    jedi.inference.compiled.subprocess.functions._find_module = _find_on_given_path
    jedi.inference.sys_path.check_sys_path_modifications = lambda module_context: []
    jedi.api.file_name.os = _ConfinedOs(project_dir)


def _added_on_line(line: str) -> int:
    if STEP_DEF.match(line) or SETUP_DEF.match(line):
        return len(f": {OBS_ALIAS}") if line.startswith("def step") else len(f": {INFO_ALIAS}")
    return 0


def _clamp_line(code: str, line: int) -> int:
    return max(1, min(line, code.count("\n") + 1))


def _typed_prefix(code: str, line: int, column: int) -> str:
    text = code.split("\n")[line - 1][:column]
    match = re.search(r"[A-Za-z_]\w*$", text)
    return match.group(0) if match else ""


def _trim(text: str) -> str:
    if len(text) <= LIMITS.max_hover_chars:
        return text
    return text[: LIMITS.max_hover_chars - 1] + "…"


def _completion_json(completion, name: str, documented: bool, stub_root: Path) -> dict:
    kind = KINDS.get(completion.type, "variable")
    path = completion.module_path
    in_stubs = path is not None and Path(path).is_relative_to(stub_root)
    doc = completion.docstring(raw=in_stubs, fast=True) if documented or in_stubs else ""
    if in_stubs and completion.type in ("statement", "instance"):
        kind = "property"  # a message's field, or a topic of obs
    detail = doc.split("\n", 1)[0] if in_stubs and doc else completion.type
    return {"label": name, "type": kind, "detail": detail, "doc": _trim(doc)}
