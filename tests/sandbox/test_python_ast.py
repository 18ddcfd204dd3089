"""Parsing beside other threads (sandbox/python_ast.py): CPython before 3.11.8 / 3.12.2 fails a
parse with "AST constructor recursion depth mismatch" when a garbage collection inside it lets
another thread's parse in (gh-106905). CI's 3.11.7 failed a grading this way."""

from __future__ import annotations

import ast
import gc
import pathlib
import re
import sys
import threading
import time
from collections.abc import Callable

import pytest

from sandbox import python_ast

SOURCE = "\n".join(
    f"def f{i}(a, b):\n    return [x * a + b for x in range({i}) if x % 2]" for i in range(100)
)
# Where the hammer below is known to find the race: 3.11.0-3.11.7. On 3.12.1 (also before the
# fix) it found none in 30 s (measured 2026-12-01; why was not looked into), so there the witness
# is skipped rather than proving nothing; the lock still guards every parse on every version.
RACE_WITNESSED = sys.version_info < (3, 11, 8)


class _CycleWithFinalizer:
    """Garbage whose collection runs Python code, where the interpreter may switch threads."""

    def __del__(self) -> None:
        sum(range(20))


def _parse_from_threads(parse: Callable[[str], object], seconds: float) -> list[str]:
    """Four threads at different stack depths parse SOURCE, making finalizable cycles between
    parses, with a tiny switch interval and a low collection threshold, until one parse fails
    or `seconds` pass. Returns the failures' sentences."""
    failures: list[str] = []
    stop = threading.Event()

    def parse_at_depth(depth: int) -> None:
        if depth:
            return parse_at_depth(depth - 1)
        while not stop.is_set():
            for _ in range(50):
                garbage = _CycleWithFinalizer()
                garbage.itself = garbage  # type: ignore[attr-defined]
            try:
                parse(SOURCE)
            except SystemError as error:
                failures.append(str(error))
                stop.set()

    switch_interval, threshold = sys.getswitchinterval(), gc.get_threshold()
    sys.setswitchinterval(1e-6)
    gc.set_threshold(50)
    threads = [threading.Thread(target=parse_at_depth, args=(d,)) for d in (1, 8, 16, 24)]
    try:
        for thread in threads:
            thread.start()
        stop.wait(seconds)
    finally:
        stop.set()
        for thread in threads:
            thread.join()
        sys.setswitchinterval(switch_interval)
        gc.set_threshold(*threshold)
    return failures


@pytest.mark.skipif(
    not RACE_WITNESSED,
    reason="this interpreter has CPython's fix for gh-106905, or the hammer does not find it here",
)
def test_the_interpreters_own_parse_fails_beside_other_threads():
    """The witness: on this interpreter the race is real and the hammer below finds it (it takes
    0.01-0.2 s on a quiet machine)."""
    failures = _parse_from_threads(ast.parse, seconds=30)
    assert failures and "recursion depth mismatch" in failures[0]


def test_our_parse_never_fails_beside_other_threads():
    started = time.monotonic()
    assert _parse_from_threads(python_ast.parse, seconds=2) == []
    assert time.monotonic() - started < 30  # the threads ended when asked


def test_parse_and_literal_eval_answer_as_the_interpreters_do():
    assert ast.dump(python_ast.parse(SOURCE)) == ast.dump(ast.parse(SOURCE))
    assert ast.dump(python_ast.parse("1 + x", mode="eval")) == ast.dump(
        ast.parse("1 + x", mode="eval")
    )
    assert python_ast.literal_eval("  [1, 'a', (2.5, None)]") == [1, "a", (2.5, None)]
    for bad in ("def f(:\n", "x = 1\0"):  # a NUL byte: SyntaxError on 3.11.4+, ValueError before
        with pytest.raises((SyntaxError, ValueError)) as theirs:
            ast.parse(bad)
        with pytest.raises(theirs.type):
            python_ast.parse(bad)
    with pytest.raises(ValueError):
        python_ast.literal_eval("__import__('os')")


def test_the_lock_is_re_entrant():
    with python_ast.ONE_PARSE_AT_A_TIME:  # a finalizer parsing on the thread holding it
        assert isinstance(python_ast.parse("x = 1"), ast.Module)


PROJECT = pathlib.Path(__file__).resolve().parents[2]
EXEMPT = ("sandbox/python_ast.py", "sandbox/host.py")


def test_no_module_of_ours_parses_around_the_lock():
    """Every in-process parse of ours goes through sandbox/python_ast.py. A node's own load in
    sandbox/host.py is left out: it runs in the node's process before any thread of its own. A
    literal_eval of a tree already parsed says so on its line ("a tree, no text")."""
    direct_parse = re.compile(r"\bast\.(parse|literal_eval)\(|PyCF_ONLY_AST")
    offenders = [
        f"{path.relative_to(PROJECT)}:{number}"
        for package in ("server", "sandbox")
        for path in sorted((PROJECT / package).rglob("*.py"))
        if path.relative_to(PROJECT).as_posix() not in EXEMPT
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if direct_parse.search(line) and "a tree, no text" not in line
    ]
    assert offenders == [], "parse with sandbox.python_ast instead: " + ", ".join(offenders)
