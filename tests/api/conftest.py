"""The real server for the API tests: `robodojo serve` in a subprocess on a free loopback port,
with its own data folder, driven over HTTP (httpx) and websockets like a browser would.

One server per test session (starting one costs ~2 s); each test makes its own users through
the admin API, so tests do not see each other's data.
"""

from __future__ import annotations

import os
import re
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import httpx
import pytest

START_TIMEOUT_S = 60.0  # [s] cold start with a sandbox pool on a loaded 2-core machine
# [s] for the last lines after the server exits; a sandbox that outlives it may hold the pipe
OUTPUT_END_TIMEOUT_S = 2.0
LOGIN_LINE = re.compile(r"log in as the instructor at (\S+/login\?token=(\S+))")
# Drives forward and stops before the wall (the CLI demo's controller, trimmed).
STEP_CONTROLLER = """\
RATE_HZ = 20
SUBSCRIBE = ["Distance"]


def step(obs):
    if obs.Distance is None:
        return None
    print("distance", obs.Distance.data)
    blocked = 0 < obs.Distance.data < 20
    return {"Control": (0.0, 0.0) if blocked else (0.1, 0.0)}
"""


@dataclass
class PostgresDatabase:
    url: str
    admin: object

    def drop(self) -> None:
        name = self.url.rsplit("/", 1)[1]
        self.admin.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
        self.admin.close()


def create_postgres_database() -> PostgresDatabase:
    """A new, empty database on the test PostgreSQL (tests/store/conftest.py says where)."""
    import uuid

    from tests.store.conftest import POSTGRES_URL, _postgres_admin

    admin = _postgres_admin()
    name = f"robodojo_api_{uuid.uuid4().hex[:10]}"
    admin.execute(f'CREATE DATABASE "{name}"')
    return PostgresDatabase(f"{POSTGRES_URL.rsplit('/', 1)[0]}/{name}", admin)


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


@dataclass
class LabServer:
    url: str
    admin_token: str
    process: subprocess.Popen
    data: Path
    output: list[str] = field(default_factory=list)
    clients: list[httpx.Client] = field(default_factory=list)
    database_url: str = ""  # the store the server uses, for tests that look behind the API
    output_pump: threading.Thread | None = None  # reads the server's output into `output`

    def client(self, token: str | None = None) -> httpx.Client:
        """A client closed at the end of the test (the `_close_clients` fixture)."""
        headers = {"Authorization": f"Bearer {token}"} if token else {}
        client = httpx.Client(base_url=self.url, headers=headers, timeout=30.0)
        self.clients.append(client)
        return client

    def close_clients(self) -> None:
        while self.clients:
            self.clients.pop().close()

    def admin(self) -> httpx.Client:
        return self.client(self.admin_token)

    def new_user(self, name: str = "student", role: str = "student") -> tuple[dict, str]:
        with self.admin() as admin:
            answer = admin.post("/api/admin/users", json={"name": name, "role": role})
        assert answer.status_code == 201, answer.text
        user = answer.json()
        return user, user["token"]

    def student(self, name: str = "student") -> httpx.Client:
        """A logged-in browser-like client: opened the invite link, holds the cookie."""
        user, token = self.new_user(name)
        # A real browser sends its page's Origin with every POST; the CSRF guard checks it.
        client = self.client()
        client.headers["Origin"] = self.url
        answer = client.get(f"/login?token={token}", follow_redirects=False)
        assert answer.status_code == 303, answer.text
        client.user = user  # type: ignore[attr-defined]
        client.token = token  # type: ignore[attr-defined]
        return client


def start_server(
    data: Path,
    env_extra: dict[str, str] | None = None,
    port: int | None = None,
    own_session: bool = False,
) -> LabServer:
    """`own_session`: the server leads a session and process group of its own, as under a
    service manager, so a test can signal the whole group (os.killpg(process.pid, ...))."""
    port = port or free_port()
    env = dict(os.environ)
    # Several test servers run at once: each takes any free rosserial port, on loopback only
    # (the lab's default is every interface, for a bench's WiFi; a test has no robots outside).
    env.update(
        {
            "ROBODOJO_SANDBOX_POOL": "2",
            "PYTHONUNBUFFERED": "1",
            "ROBODOJO_ROSSERIAL_PORT": "0",
            "ROBODOJO_ROSSERIAL_HOST": "127.0.0.1",
            # One editor analysis worker (a process that reads numpy and rospy for a while at
            # start): tests/api/test_editor.py needs one, the other servers need no more.
            "ROBODOJO_EDITOR_WORKERS": "1",
            # Runs in the server's own threads: quicker to start; the per-core default (worker
            # processes) has tests/workers/test_local_processes.py.
            "ROBODOJO_WORKERS": "0",
        }
    )
    env.update(env_extra or {})
    command = [sys.executable, "-m", "server.cli", "serve", "--port", str(port), "--data",
               str(data)]  # fmt: skip
    process = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
        start_new_session=own_session,
    )
    output: list[str] = []
    found: dict[str, str] = {}

    def pump() -> None:
        assert process.stdout is not None
        try:
            for line in process.stdout:
                output.append(line.rstrip("\n"))
                match = LOGIN_LINE.search(line)
                if match:
                    found["token"] = match.group(2)
        except (ValueError, OSError):  # closed by stop_server: the server is gone
            return

    output_pump = threading.Thread(target=pump, name="lab-output", daemon=True)
    output_pump.start()
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise RuntimeError("the server exited at start:\n" + "\n".join(output[-40:]))
        try:
            if httpx.get(f"{url}/api/health", timeout=1.0).status_code == 200:
                break
        except httpx.TransportError:
            pass
        time.sleep(0.1)
    else:
        process.kill()
        raise RuntimeError("the server did not answer in time:\n" + "\n".join(output[-40:]))
    from server.store.db import sqlite_url

    database_url = env.get("ROBODOJO_DATABASE_URL") or sqlite_url(data)
    return LabServer(
        url, found.get("token", ""), process, data, output, [], database_url, output_pump
    )


def stop_server(server: LabServer, timeout_s: float = 30.0) -> int:
    server.close_clients()
    server.process.terminate()
    try:
        return server.process.wait(timeout_s)
    except subprocess.TimeoutExpired:
        server.process.kill()
        return server.process.wait()
    finally:
        if server.output_pump is not None:  # it reads the last lines, up to the pipe's end
            server.output_pump.join(OUTPUT_END_TIMEOUT_S)
        if server.process.stdout is not None:
            server.process.stdout.close()


# The PostgreSQL twin of every API test is slow in sum (-m "not slow" runs SQLite only).
@pytest.fixture(
    scope="session", params=["sqlite", pytest.param("postgresql", marks=pytest.mark.slow)]
)
def lab(request, tmp_path_factory) -> Iterator[LabServer]:
    """The server on its embedded SQLite, then on a fresh PostgreSQL database: every API test
    runs against both (the PostgreSQL half is skipped, saying why, when none is reachable)."""
    env = {}
    database = None
    if request.param == "postgresql":
        database = create_postgres_database()
        env["ROBODOJO_DATABASE_URL"] = database.url
    server = start_server(tmp_path_factory.mktemp(f"lab-{request.param}"), env)
    assert server.admin_token, "the server printed no login URL:\n" + "\n".join(server.output)
    yield server
    stop_server(server)
    if database is not None:
        database.drop()


@pytest.fixture(autouse=True)
def _close_clients(request) -> Iterator[None]:
    yield
    if "lab" in request.fixturenames:
        request.getfixturevalue("lab").close_clients()


def start_crowbot_run(client, clock: str = "realtime", duration_s: float = 60.0) -> str:
    """Start STEP_CONTROLLER on a CrowBot at the wall (201 expected); the run's id."""
    answer = client.post(
        "/api/runs",
        json={
            "robot": "crowbot",
            "world": "wall_approach",
            "nodes": [{"name": "driver", "code": STEP_CONTROLLER}],
            "clock": clock,
            "duration": duration_s,
        },
    )
    assert answer.status_code == 201, answer.text
    return answer.json()["id"]


def wait_for_end(client: httpx.Client, run_id: str, timeout_s: float = 60.0) -> dict:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        run = client.get(f"/api/runs/{run_id}").json()
        if run["state"] in ("finished", "failed", "interrupted"):
            return run
        time.sleep(0.1)
    raise AssertionError(f"run {run_id} did not end within {timeout_s} s: {run}")
