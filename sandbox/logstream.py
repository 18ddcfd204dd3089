"""A node's log stream (its stdout and stderr), drained by the parent and capped.

The child writes into a pipe; the parent reads whatever is there whenever it waits for the node,
so a node that prints never blocks on a full pipe. Past `total_bytes` the rest is read and
dropped, and one note says how much; lines longer than `line_bytes` are cut with a note.
"""

from __future__ import annotations

import os
from collections import deque


class LogStream:
    def __init__(self, fd: int, total_bytes: int, line_bytes: int) -> None:
        self._fd = fd
        self.total_bytes = total_bytes
        self.line_bytes = line_bytes
        self.kept_bytes = 0
        self.dropped_bytes = 0
        self._reported_dropped = 0
        self._partial = b""
        self._lines: deque[str] = deque()

    def drain(self) -> bool:
        """Read everything available now; False once the child closed its end."""
        while True:
            try:
                chunk = os.read(self._fd, 1 << 16)
            except BlockingIOError:
                return True
            except OSError:
                return False
            if not chunk:
                self._flush_partial()
                return False
            self._take(chunk)

    def _take(self, chunk: bytes) -> None:
        room = self.total_bytes - self.kept_bytes
        if room <= 0:
            self.dropped_bytes += len(chunk)
            return
        if len(chunk) > room:
            self.dropped_bytes += len(chunk) - room
            chunk = chunk[:room]
        self.kept_bytes += len(chunk)
        data = self._partial + chunk
        *complete, self._partial = data.split(b"\n")
        for raw in complete:
            self._lines.append(self._line(raw))
        if len(self._partial) > self.line_bytes:
            self._lines.append(self._line(self._partial))
            self._partial = b""

    def _line(self, raw: bytes) -> str:
        text = raw[: self.line_bytes].decode("utf-8", errors="replace")
        if len(raw) > self.line_bytes:
            text += f" [... line cut at {self.line_bytes} bytes]"
        return text

    def _flush_partial(self) -> None:
        if self._partial:
            self._lines.append(self._line(self._partial))
            self._partial = b""

    def take(self) -> list[str]:
        """Lines since the last call, with a truncation note once the cap was hit."""
        lines = list(self._lines)
        self._lines.clear()
        if self.dropped_bytes > self._reported_dropped:
            lines.append(
                f"[log truncated: {self.dropped_bytes} bytes dropped so far after the "
                f"{self.total_bytes // 1024} KiB cap]"
            )
            self._reported_dropped = self.dropped_bytes
        return lines
