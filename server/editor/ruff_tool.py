"""Ruff, run as a program on the student's text (never on a file of theirs): `ruff check` for
pyflakes' findings and syntax errors (rules F and E9, no style nags), `ruff format` on request.
`--isolated` so no configuration file near the server's working folder changes what students
get; a fixed file name, so nothing of the request reaches ruff's command line.
"""

from __future__ import annotations

import json
import subprocess
from functools import cache

from server.editor import syntax
from server.editor.diagnostics import Diagnostic, Severity
from server.editor.limits import LIMITS

STDIN_NAME = "controller.py"
RULES = "F,E9"  # pyflakes (undefined names, unused imports, ...) and syntax errors
# ruff 0.5-0.11 gives syntax errors no code, later ones "invalid-syntax"; the contract names
# them E999, ruff's old code, as editors and students know it.
SYNTAX_RULE = syntax.SYNTAX_RULE


class RuffUnavailable(RuntimeError):
    """Ruff did not answer (missing, timed out, crashed); the message is a sentence."""


class FormatError(ValueError):
    """The text cannot be formatted (a syntax error); the message names the line."""


@cache
def ruff_binary() -> str:
    from ruff.__main__ import find_ruff_bin

    return str(find_ruff_bin())


def _run(arguments: list[str], code: str, timeout_s: float) -> subprocess.CompletedProcess:
    try:
        return subprocess.run(
            [ruff_binary(), *arguments],
            input=code.encode(),
            capture_output=True,
            timeout=timeout_s,
            check=False,
        )
    except subprocess.TimeoutExpired:
        raise RuffUnavailable(f"the linter stopped after {timeout_s:g} s on this file") from None
    except (OSError, ImportError) as error:
        raise RuffUnavailable(f"the linter could not start ({error})") from None


def check(code: str) -> list[Diagnostic]:
    """Ruff's findings for `code`, with positions as the contract gives them."""
    done = _run(
        ["check", "--isolated", "--no-cache", "--select", RULES, "--output-format", "json",
         "--stdin-filename", STDIN_NAME, "--exit-zero", "-"],
        code,
        LIMITS.ruff_timeout_s,
    )  # fmt: skip
    if done.returncode != 0:
        raise RuffUnavailable(f"the linter failed on this file (exit status {done.returncode})")
    try:
        findings = json.loads(done.stdout)
    except ValueError:
        raise RuffUnavailable("the linter's answer could not be read") from None
    return [_diagnostic(item) for item in findings]


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


def format_code(code: str) -> str:
    """`code` as ruff format writes it; FormatError naming the line for a syntax error."""
    done = _run(
        ["format", "--isolated", "--no-cache", "--stdin-filename", STDIN_NAME, "-"],
        code,
        LIMITS.format_timeout_s,
    )
    if done.returncode == 0:
        return done.stdout.decode()
    error = done.stderr.decode(errors="replace").strip().splitlines()
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
