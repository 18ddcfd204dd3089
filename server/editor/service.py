"""The editor's help as the API offers it: diagnostics (ruff's and our API checks', merged),
completion, hover and formatting of a student's text. Nothing here runs the student's code.

Ruff runs as its own short process per request; our checks and jedi run in the analysis
workers (pool.py). When one part cannot answer (ruff missing or slow, the workers busy or
stopped on a hostile file), the others still do and an `info` diagnostic says what is missing.
"""

from __future__ import annotations

import dataclasses
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from server.editor import ruff_tool, syntax
from server.editor.context import RunContext
from server.editor.diagnostics import Diagnostic, Severity
from server.editor.limits import LIMITS
from server.editor.pool import AnalysisPool, AnalysisUnavailable

LIMIT_RULE = "robodojo-limit"  # a diagnostic that says part of the analysis did not answer


class CodeTooLarge(ValueError):
    """The text is larger than the lab's per-file code limit; the message says so."""


class InvalidText(ValueError):
    """The text is not Unicode a file can hold (JSON allows unpaired surrogates)."""


def _note(message: str) -> Diagnostic:
    return Diagnostic(
        1, 0, 1, 0, Severity.INFO, LIMIT_RULE, message[:1].upper() + message[1:] + "."
    )


class EditorService:
    def __init__(
        self, max_code_bytes: int, workers: int = LIMITS.workers, cache_dir: Path | None = None
    ) -> None:
        self.max_code_bytes = max_code_bytes
        self.pool = AnalysisPool(dataclasses.replace(LIMITS, workers=workers), cache_dir)
        self._ruff = ThreadPoolExecutor(max_workers=4, thread_name_prefix="editor-ruff")

    def start(self) -> None:
        if self.pool.limits.workers > 0:
            self.pool.start()

    def close(self) -> None:
        self.pool.close()
        self._ruff.shutdown(wait=False, cancel_futures=True)

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

    def lint(self, code: str, context: RunContext) -> list[dict]:
        self.check_size(code)
        ruff_answer = self._ruff.submit(ruff_tool.check, code)
        found: list[Diagnostic] = []
        python_syntax: list[Diagnostic] = []
        try:
            answer = self.pool.call({"op": "checks", "code": code, **context.to_json()})
            found += [_diagnostic(d) for d in answer["diagnostics"]]
            python_syntax = [_diagnostic(d) for d in answer["syntax"]]
        except AnalysisUnavailable as error:
            found.append(_note(str(error)))
        try:
            from_ruff = ruff_answer.result()
        except ruff_tool.RuffUnavailable as error:
            from_ruff = [_note(f"{error}; Python's own syntax check ran")]
        found += from_ruff
        # Python's verdict where ruff saw no syntax error, and always for code nested deeper
        # than CPython compiles (ruff's parser takes it): it would fail when run.
        ruff_saw_syntax = any(d.rule == syntax.SYNTAX_RULE for d in from_ruff)
        found += [d for d in python_syntax if not ruff_saw_syntax or d.message == syntax.TOO_DEEP]
        found.sort(key=lambda d: (d.line, d.column))
        return [d.to_json() for d in found[: LIMITS.max_diagnostics]]

    def complete(self, code: str, line: int, column: int, context: RunContext) -> dict:
        self.check_size(code)
        try:
            return self.pool.call(
                {
                    "op": "complete",
                    "code": code,
                    "line": line,
                    "column": column,
                    **context.to_json(),
                }
            )
        except AnalysisUnavailable:
            return {"completions": [], "signature": None}  # typing goes on; lint says why

    def hover(self, code: str, line: int, column: int, context: RunContext) -> dict:
        self.check_size(code)
        try:
            return self.pool.call(
                {"op": "hover", "code": code, "line": line, "column": column, **context.to_json()}
            )
        except AnalysisUnavailable:
            return {"text": None}

    def format(self, code: str) -> str:
        self.check_size(code)
        return ruff_tool.format_code(code)


def _diagnostic(item: dict) -> Diagnostic:
    return Diagnostic(**{**item, "severity": Severity(item["severity"])})
