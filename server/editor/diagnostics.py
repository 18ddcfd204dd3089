"""The editor's diagnostic: one finding at a place in the student's file, as the HTTP contract
(docs: /work/agents/editor-contract.md, server/api/routes/editor.py) sends it."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from enum import StrEnum


class Severity(StrEnum):
    ERROR = "error"  # the code fails when it runs (or does not parse)
    WARNING = "warning"  # probably wrong: a name close to a real one
    INFO = "info"  # worth knowing: a topic no robot publishes, an analysis that stopped


@dataclass(frozen=True, slots=True)
class Diagnostic:
    line: int  # 1-based
    column: int  # 0-based, in characters
    end_line: int
    end_column: int
    severity: Severity
    rule: str  # "F821" (ruff), "E999" (syntax), "robodojo-topic", ...
    message: str  # a sentence

    def to_json(self) -> dict:
        out = asdict(self)
        out["severity"] = str(self.severity)
        return out


def char_column(lines: list[str], line: int, byte_offset: int) -> int:
    """The character column of a UTF-8 byte offset on a 1-based line (ast counts bytes)."""
    if not 1 <= line <= len(lines):
        return byte_offset
    return len(lines[line - 1].encode()[:byte_offset].decode("utf-8", errors="replace"))
