"""The README's start command as a user types it: `./scripts/start` with serve's options alone
starts serve with them, a command is passed on, and a wrong option gets serve's own sentence.

The script is run for real, in the environment this suite runs in: scripts/venv reuses an
environment built from the test lock (its stamp says so), so nothing is installed here; outside
such an environment (a developer's own Python) the script would build one, and these are skipped.
"""

from __future__ import annotations

import hashlib
import os
import signal
import socket
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest

from tests.waiting import wait_until

ROOT = Path(__file__).resolve().parent.parent
START = ROOT / "scripts" / "start"
START_TIMEOUT_S = 60.0  # the first start creates the database and probes the sandbox


def built_from_the_current_lock() -> bool:
    """This environment's stamp is what scripts/venv would write now (the lock and
    pyproject.toml unchanged since it was built), so ./scripts/start reuses it as it is. Any
    other environment it would rebuild, deleting the one this suite runs in."""
    stamp = Path(sys.prefix) / "robodojo-lock.stamp"
    if not stamp.exists():
        return False
    inputs = b"".join(
        (ROOT / name).read_bytes() for name in ("requirements/test.txt", "pyproject.toml")
    )
    base = f"{sys.base_prefix} {sys.version.split()[0]}"
    return stamp.read_text().split() == [hashlib.sha256(inputs).hexdigest(), *base.split()]


pytestmark = pytest.mark.skipif(
    not built_from_the_current_lock(),
    reason="not run from an environment scripts/venv built from the current lock (./scripts/test "
    "makes one): ./scripts/start would rebuild it under this suite",
)


def start(*args: str, **kwargs) -> subprocess.Popen:
    # The environment this test runs in, so scripts/venv finds its stamp and installs nothing.
    environment = {**os.environ, "ROBODOJO_VENV": sys.prefix}
    environment.pop("ROBODOJO_FRESH_VENV", None)  # CI's: it would rebuild this environment
    return subprocess.Popen(
        [str(START), *args], cwd=kwargs.pop("cwd", ROOT), env=environment, text=True, **kwargs
    )


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def answers(url: str) -> bool:
    try:
        with urllib.request.urlopen(url, timeout=2) as reply:
            return reply.status == 200
    except OSError:
        return False


def test_options_alone_start_serve_with_them(tmp_path):
    port = free_port()
    server = start(
        "--port", str(port), "--data", str(tmp_path / "data"), "--rosserial-port", "-1",
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
    )  # fmt: skip
    try:
        wait_until(
            lambda: answers(f"http://127.0.0.1:{port}/") or server.poll() is not None,
            START_TIMEOUT_S,
            f"./scripts/start --port {port} answering",
        )
        assert server.poll() is None, server.stdout.read()
        assert (tmp_path / "data").is_dir()  # --data reached serve too
    finally:
        server.send_signal(signal.SIGTERM)
        output, _ = server.communicate(timeout=30)
    assert "log in as the instructor" in output


def test_a_wrong_option_gets_serves_sentence():
    done = start("--prot", "8765", stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    _, errors = done.communicate(timeout=120)
    assert done.returncode == 2
    assert "usage: robodojo serve" in errors
    assert "robodojo serve: error: unrecognized arguments: --prot 8765" in errors


def test_a_command_is_passed_on_as_it_is():
    done = start("robots", stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    output, errors = done.communicate(timeout=120)
    assert done.returncode == 0, errors
    assert [line.split()[0] for line in output.splitlines()][:2] == ["crop_rover", "crowbot"]
