"""Python's own verdict on a student's text: the parser the sandbox compiles it with. Ruff's
parser accepts some files CPython refuses (200 nested brackets, 100 levels of indentation, an
expression 100,000 terms long); those fail when run, so the editor says so before.

Runs in the analysis workers only: CPython's parser guards its C stack, but a file built to
exhaust memory or recursion should cost a worker, never the server.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass

from sandbox import python_ast
from server.editor.diagnostics import Diagnostic, Severity

SYNTAX_RULE = "E999"  # the code ruff used for syntax errors; editors and students know it
TOO_DEEP = (
    "Python cannot compile code nested this deeply or an expression this long (it fails the "
    "same way when run); split it into smaller expressions or functions."
)


@dataclass(frozen=True, slots=True)
class Parsed:
    tree: ast.Module | None
    problems: list[Diagnostic]
    too_deep: bool  # the analysers (jedi, our checks) should not try this text


def parse(code: str) -> Parsed:
    try:
        return Parsed(python_ast.parse(code), [], False)
    except (RecursionError, MemoryError):
        return Parsed(None, [_whole_file(code, TOO_DEEP)], True)
    except SyntaxError as error:
        line = error.lineno or 1
        column = max((error.offset or 1) - 1, 0)
        end_line = error.end_lineno or line
        end_column = max((error.end_offset or column + 2) - 1, column + 1)
        if end_line < line:
            end_line, end_column = line, column + 1
        too_deep = "too many" in error.msg or "too complex" in error.msg
        message = f"Syntax error: {error.msg}." if not too_deep else TOO_DEEP
        return Parsed(None, [Diagnostic(line, column, end_line, end_column, Severity.ERROR,
                                        SYNTAX_RULE, message)], too_deep)  # fmt: skip
    except ValueError as error:  # a NUL byte in the text
        return Parsed(None, [_whole_file(code, f"Python cannot read this text: {error}.")], False)


def _whole_file(code: str, message: str) -> Diagnostic:
    first_line = code.split("\n", 1)[0]
    return Diagnostic(1, 0, 1, len(first_line), Severity.ERROR, SYNTAX_RULE, message)
