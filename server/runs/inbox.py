"""A run's command inbox: commands (server/runs/commands.py) arrive from any thread (the web
server's, the CLI's signal handler) and are taken by the run's own loop between two steps, so the
simulation never sees two threads. A byte on a pipe wakes a realtime loop that sleeps in
select() until its next event.
"""

from __future__ import annotations

import contextlib
import os
import queue

from server.runs.commands import RunCommand


class CommandInbox:
    def __init__(self) -> None:
        self._queue: queue.SimpleQueue[RunCommand] = queue.SimpleQueue()
        self._signal_r, self._signal_w = os.pipe()
        os.set_blocking(self._signal_r, False)
        os.set_blocking(self._signal_w, False)

    def put(self, command: RunCommand) -> None:
        """Any thread."""
        self._queue.put(command)
        with contextlib.suppress(BlockingIOError, OSError):  # a full or closed pipe: no matter
            os.write(self._signal_w, b"!")

    @property
    def fd(self) -> int:
        """Readable while a command waits: a sleeping loop can select() on it."""
        return self._signal_r

    def take_all(self) -> list[RunCommand]:
        """The waiting commands, oldest first (none: the common case, without a system call)."""
        if self._queue.empty():
            return []
        with contextlib.suppress(BlockingIOError, OSError):
            os.read(self._signal_r, 4096)
        commands = []
        while True:
            try:
                commands.append(self._queue.get_nowait())
            except queue.Empty:
                return commands

    def wait(self, timeout_s: float) -> RunCommand | None:
        """Block up to `timeout_s` [s] for one command (a paused loop)."""
        try:
            return self._queue.get(timeout=timeout_s)
        except queue.Empty:
            return None

    def close(self) -> None:
        for fd in (self._signal_r, self._signal_w):
            with contextlib.suppress(OSError):
                os.close(fd)
