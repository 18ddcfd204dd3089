"""Python's own parser, one thread at a time.

CPython 3.11.0-3.11.7 and 3.12.0-3.12.1 count the depth of the syntax tree `ast.parse` is turning
into Python objects in one counter per interpreter, not per call (python/cpython gh-106905; fixed
in 3.11.8 and 3.12.2). A garbage collection during that conversion can run a finalizer, the
finalizer's Python code lets another thread in, and that thread's parse resets the counter: the
first parse then fails with "SystemError: AST constructor recursion depth mismatch". The server
parses students' files from many threads at once (grading a submission's cases side by side,
request handlers checking a run), and CI's interpreter is 3.11.7, where this failed a grading.

So every parse in this project that can run beside another thread goes through here. A parse
takes microseconds to a few milliseconds, so waiting for one costs nothing a user notices. The
lock is re-entrant: a finalizer that itself parses, on the thread holding it, must not hang.
"""

from __future__ import annotations

import ast
import threading
from typing import Any, Literal

# Held while source becomes Python AST objects (compiling a tree counts its depth per thread).
ONE_PARSE_AT_A_TIME = threading.RLock()


def parse(
    source: str | bytes, filename: str = "<unknown>", mode: Literal["exec", "eval"] = "exec"
) -> Any:
    """`ast.parse`, safe beside other threads' parses (an ast.Module, or ast.Expression for
    mode="eval"); raises what ast.parse raises (SyntaxError, ValueError for a NUL byte,
    RecursionError or MemoryError for a file too deep)."""
    with ONE_PARSE_AT_A_TIME:
        return ast.parse(source, filename, mode)


def literal_eval(text: str) -> Any:
    """`ast.literal_eval` of a string, safe beside other threads' parses."""
    return ast.literal_eval(parse(text.lstrip(" \t"), mode="eval"))
