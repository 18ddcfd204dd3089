"""The editor's help as the API offers it: diagnostics (ruff's and our API checks', merged),
completion, hover and formatting of a student's text. Nothing here runs the student's code,
and nothing here reads it either: jedi, ruff and our checks read it inside the editor's
sandbox (sandbox_host.py, host.py), each request in a process of its own with its own limits.

Each student has one request analysed at a time, behind a bounded queue (gate.py: EditorBusy,
the route's 429). When one part cannot answer (ruff or jedi past its budget, the sandbox
starting or restarting), the others still do and an `info` diagnostic, or the completion's
`note`, says what is missing.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from server.editor import ruff_tool, syntax
from server.editor.context import RunContext, robot_catalog
from server.editor.diagnostics import Diagnostic, Severity
from server.editor.frames import Cause, Op
from server.editor.gate import EditorBusy, EditorGate
from server.editor.limits import LIMITS
from server.editor.sandbox_host import AnalysisUnavailable, SandboxedHost
from server.editor.stubs import step_module

__all__ = ["CodeTooLarge", "EditorBusy", "EditorService", "InvalidText"]

LIMIT_RULE = "robodojo-limit"  # a diagnostic that says part of the analysis did not answer
ANYONE = ""  # the user of calls made without one (the command line, benchmarks)
# What stopped a request that asking again would not help: the file itself.
FILE_CAUSES = frozenset({Cause.TIME, Cause.CPU, Cause.MEMORY, Cause.FAILED})


class CodeTooLarge(ValueError):
    """The text is larger than the lab's per-file code limit; the message says so."""


class InvalidText(ValueError):
    """The text is not Unicode a file can hold (JSON allows unpaired surrogates)."""


def _note(message: str) -> Diagnostic:
    return Diagnostic(1, 0, 1, 0, Severity.INFO, LIMIT_RULE, _sentence(message))


def _sentence(message: str) -> str:
    return message[:1].upper() + message[1:] + "."


class EditorService:
    def __init__(
        self,
        max_code_bytes: int,
        workers: int = LIMITS.concurrent_requests,
        cache_dir: Path | None = None,
        sandboxed: bool = True,
    ) -> None:
        """`workers`: requests analysed at once (0 turns the help off); `sandboxed=False` is
        the lab's --unsafe-no-sandbox (sandbox_host.py)."""
        self.max_code_bytes = max_code_bytes
        self.limits = dataclasses.replace(LIMITS, concurrent_requests=workers)
        self.gate = EditorGate(self.limits)
        self.host = SandboxedHost(self.limits, cache_dir, sandboxed)

    def start(self) -> None:
        if self.limits.concurrent_requests > 0:
            self.host.start()

    def close(self) -> None:
        self.host.close()

    def check_size(self, code: str) -> None:
        try:
            size = len(code.encode())
        except UnicodeEncodeError as error:
            raise InvalidText(
                f"the text holds a character that is not valid Unicode ({code[error.start]!r} "
                f"at character {error.start}); remove it"
            ) from None
        if size > self.max_code_bytes:
            raise CodeTooLarge(
                f"the file is {size / 1024:.0f} KiB, larger than the lab's limit of "
                f"{self.max_code_bytes / 1024:.0f} KiB per file; split it into modules or "
                "nodes"
            )

    def lint(self, code: str, context: RunContext, user: str = ANYONE) -> list[dict]:
        self.check_size(code)
        with self.gate.turn(user, "lint"):
            from_ruff_job = self.host.submit(Op.RUFF_CHECK, code, user=user)
            checks_job = self.host.submit(Op.CHECKS, code, user=user, **self._context(context))
            found: list[Diagnostic] = []
            python_syntax: list[Diagnostic] = []
            try:
                answer = self.host.result(checks_job)
                found += [_diagnostic(d) for d in answer["diagnostics"]]
                python_syntax = [_diagnostic(d) for d in answer["syntax"]]
            except AnalysisUnavailable as error:
                found.append(_note(str(error)))
            except (KeyError, TypeError, ValueError):  # from a request process gone wrong
                found.append(_note("the analysis sent an answer that could not be read"))
            try:
                from_ruff = ruff_tool.diagnostics(self.host.result(from_ruff_job))
            except (AnalysisUnavailable, ruff_tool.RuffUnavailable) as error:
                from_ruff = [_note(f"{error}; Python's own syntax check ran")]
        found += from_ruff
        # Python's verdict where ruff saw no syntax error, and always for code nested deeper
        # than CPython compiles (ruff's parser takes it): it would fail when run.
        ruff_saw_syntax = any(d.rule == syntax.SYNTAX_RULE for d in from_ruff)
        found += [d for d in python_syntax if not ruff_saw_syntax or d.message == syntax.TOO_DEEP]
        found.sort(key=lambda d: (d.line, d.column))
        return [d.to_json() for d in found[: self.limits.max_diagnostics]]

    def complete(
        self, code: str, line: int, column: int, context: RunContext, user: str = ANYONE
    ) -> dict:
        """Completions and signature help; past its budget (or with the analysis stopped) an
        empty list and a `note` saying why (typing goes on)."""
        self.check_size(code)
        with self.gate.turn(user, "complete"):
            job = self.host.submit(
                Op.COMPLETE, code, user=user, line=line, column=column, **self._context(context)
            )
            try:
                return self.host.result(job)
            except AnalysisUnavailable as error:
                return {"completions": [], "signature": None, "note": _sentence(str(error))}

    def hover(
        self, code: str, line: int, column: int, context: RunContext, user: str = ANYONE
    ) -> dict:
        self.check_size(code)
        with self.gate.turn(user, "hover"):
            job = self.host.submit(
                Op.HOVER, code, user=user, line=line, column=column, **self._context(context)
            )
            try:
                return self.host.result(job)
            except AnalysisUnavailable as error:
                return {"text": None, "note": _sentence(str(error))}

    def format(self, code: str, user: str = ANYONE) -> str:
        """The text as ruff format writes it: FormatError for a syntax error, RuffUnavailable
        when ruff gave no answer (past its budget or memory: the sentence says)."""
        self.check_size(code)
        with self.gate.turn(user, "format"):
            try:
                answer = self.host.result(self.host.submit(Op.RUFF_FORMAT, code, user=user))
            except AnalysisUnavailable as error:
                if error.cause in FILE_CAUSES:  # the file is the reason: asking again won't do
                    raise ruff_tool.FormatError(f"cannot format this file: {error}") from None
                raise ruff_tool.RuffUnavailable(str(error)) from None
        return ruff_tool.formatted(answer)

    def _context(self, context: RunContext) -> dict:
        """The job's robot and extra topics; the step API's stub module for those topics is
        written here, by the server, since the sandbox's view of the stubs is read-only."""
        root = self.host.stub_root
        if context.extra_topics and root is not None and context.robot in robot_catalog():
            step_module(root, context.robot, context.extra_topics)
        return {"robot": context.robot, "extra_topics": [tuple(t) for t in context.extra_topics]}


def _diagnostic(item: dict) -> Diagnostic:
    return Diagnostic(**{**item, "severity": Severity(item["severity"])})
