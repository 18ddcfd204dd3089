"""The CrowBot firmware emulator in its own process, as a real robot is: it can be frozen with
SIGSTOP (a stalled firmware, a WiFi link stuck without closing the socket) and resumed, and it
reports every command it receives (tests/hardware/crowbot_firmware.py ``main``).

    with RobotProcess("127.0.0.1", port) as robot:       # or prefix=["ip", "netns", "exec", ns]
        robot.wait_for(lambda r: r.topic == "Control")
        robot.freeze(); ...; resumed_s = robot.resume()
        robot.received_after(resumed_s)
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


@dataclass(frozen=True, slots=True)
class Received:
    """One message the emulated robot decoded: its monotonic time [s] (the clock is shared by
    every process on the machine), topic, frame size [bytes], Control's linear.x and the Leds'
    colour."""

    t: float
    topic: str
    bytes: int
    linear: float | None = None
    leds: list[int] | None = None


class RobotProcess:
    """See the module docstring; `prefix` runs it inside something (a network namespace)."""

    def __init__(
        self,
        host: str,
        port: int,
        *,
        rate_hz: float = 20.0,
        reconnect: bool = False,
        prefix: Sequence[str] = (),
    ) -> None:
        command = [
            *prefix,
            sys.executable,
            "-m",
            "tests.hardware.crowbot_firmware",
            host,
            str(port),
            "--rate",
            str(rate_hz),
        ]
        if reconnect:
            command.append("--reconnect")
        self.command = command
        self.received: list[Received] = []
        self._lock = threading.Lock()
        self._process: subprocess.Popen[str] | None = None
        self._reader: threading.Thread | None = None

    def start(self) -> RobotProcess:
        self._process = subprocess.Popen(
            self.command,
            cwd=REPO,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        self._reader = threading.Thread(target=self._read, name="robot-process", daemon=True)
        self._reader.start()
        return self

    def _read(self) -> None:
        assert self._process is not None and self._process.stdout is not None
        for line in self._process.stdout:
            with self._lock:
                self.received.append(Received(**json.loads(line)))

    def wait_for(self, predicate: Callable[[Received], bool], timeout_s: float = 10.0) -> bool:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            with self._lock:
                if any(predicate(r) for r in self.received):
                    return True
            if self._process is not None and self._process.poll() is not None:
                return False
            time.sleep(0.01)
        return False

    def received_after(self, t_s: float, topic: str = "Control") -> list[Received]:
        with self._lock:
            return [r for r in self.received if r.t >= t_s and r.topic == topic]

    def freeze(self) -> None:
        assert self._process is not None
        os.kill(self._process.pid, signal.SIGSTOP)

    def resume(self) -> float:
        """SIGCONT; returns the monotonic time just before it (all read after is the backlog)."""
        assert self._process is not None
        resumed_s = time.monotonic()
        os.kill(self._process.pid, signal.SIGCONT)
        return resumed_s

    def stderr(self) -> str:
        process = self._process
        if process is None or process.poll() is None or process.stderr is None:
            return ""
        return process.stderr.read()

    def stop(self) -> None:
        process = self._process
        if process is None:
            return
        if process.poll() is None:
            os.kill(process.pid, signal.SIGCONT)  # a frozen process cannot end
            assert process.stdin is not None
            process.stdin.close()
            try:
                process.wait(5.0)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(5.0)
        if self._reader is not None:
            self._reader.join(5.0)
        for stream in (process.stdout, process.stderr):
            if stream is not None:
                stream.close()

    def __enter__(self) -> RobotProcess:
        return self.start()

    def __exit__(self, *exc_info: object) -> None:
        self.stop()
