"""Ruff on the student's text (never on a file of theirs): `ruff check` for pyflakes' findings
and syntax errors (rules F and E9, no style nags), `ruff format` on request. Ruff runs inside
the editor's sandbox, one process per request (server/editor/host.py runs these arguments);
this module says what it is asked and reads what it answers.

`--isolated` so no configuration file near ruff's working folder changes what students get; a
fixed file name, so nothing of the request reaches ruff's command line; findings as JSON lines,
so an answer cut at the host's output cap still reads up to its last whole line.
"""

from __future__ import annotations

import json
from functools import cache

from server.editor import syntax
from server.editor.diagnostics import Diagnostic, Severity

STDIN_NAME = "controller.py"
RULES = "F,E9"  # pyflakes (undefined names, unused imports, ...) and syntax errors
# ruff 0.5-0.11 gives syntax errors no code, later ones "invalid-syntax"; the contract names
# them E999, ruff's old code, as editors and students know it.
SYNTAX_RULE = syntax.SYNTAX_RULE


CHECK_ARGUMENTS = ("check", "--isolated", "--no-cache", "--select", RULES, "--output-format",
                   "json-lines", "--stdin-filename", STDIN_NAME, "--exit-zero", "-")  # fmt: skip
FORMAT_ARGUMENTS = ("format", "--isolated", "--no-cache", "--stdin-filename", STDIN_NAME, "-")


class RuffUnavailable(RuntimeError):
    """Ruff did not answer (missing, timed out, crashed); the message is a sentence."""


class FormatError(ValueError):
    """The text cannot be formatted (a syntax error); the message names the line."""


@cache
def ruff_binary() -> str:
    from ruff.__main__ import find_ruff_bin

    return str(find_ruff_bin())


def diagnostics(answer: dict) -> list[Diagnostic]:
    """Ruff's findings from the host's answer to CHECK_ARGUMENTS, with positions as the
    contract gives them."""
    if answer["returncode"] != 0 and not answer["truncated"]:
        raise RuffUnavailable(
            f"the linter failed on this file (exit status {answer['returncode']})"
        )
    lines = answer["stdout"].splitlines()
    if answer["truncated"] and lines:
        lines.pop()  # cut at the cap: the last line may be part of a finding
    try:
        return [_diagnostic(json.loads(line)) for line in lines if line.strip()]
    except (ValueError, KeyError, TypeError):
        raise RuffUnavailable("the linter's answer could not be read") from None


def _diagnostic(item: dict) -> Diagnostic:
    start, end = item["location"], item.get("end_location") or item["location"]
    code = item.get("code")
    message = item["message"]
    if code is None or code == "invalid-syntax":  # a syntax error
        code = None
        message = message.removeprefix("SyntaxError: ")
        message = f"Syntax error: {message[:1].lower()}{message[1:]}"
    return Diagnostic(
        start["row"],
        max(start["column"] - 1, 0),
        end["row"],
        max(end["column"] - 1, 0),
        Severity.ERROR if code is None or code in ERROR_RULES else Severity.WARNING,
        code or SYNTAX_RULE,
        _sentence(message),
    )


# Pyflakes findings that fail when the code runs (the rest are warnings: an unused import).
ERROR_RULES = frozenset({"F821", "F822", "F823", "F706", "F704", "F701", "F702", "F707", "F631",
                         "F632", "F633", "F502", "F503", "F506", "F507", "F508", "F509", "F521",
                         "F522", "F523", "F524", "F525", "F601", "F602", "F811"})  # fmt: skip


def _sentence(message: str) -> str:
    message = message.strip()
    message = message[:1].upper() + message[1:]
    return message if message.endswith((".", "?", "!")) else message + "."


def formatted(answer: dict) -> str:
    """The text from the host's answer to FORMAT_ARGUMENTS; FormatError naming the line for a
    syntax error."""
    if answer["truncated"]:
        raise FormatError(
            "cannot format this file: the formatted text would be larger than the editor "
            "takes back; split the file into modules"
        )
    if answer["returncode"] == 0:
        return answer["stdout"]
    error = answer["stderr"].strip().splitlines()
    text = error[0] if error else ""
    # "error: Failed to parse controller.py:3:7: Expected ..."
    _, _, why = text.partition(f"{STDIN_NAME}:")
    if why:
        line, _, rest = why.partition(":")
        column, _, reason = rest.partition(":")
        raise FormatError(
            f"cannot format: line {line} (column {column}) has a syntax error: "
            f"{reason.strip().rstrip('.')}. Fix it and format again."
        )
    raise FormatError(f"cannot format this file: {text or 'ruff format failed'}")
