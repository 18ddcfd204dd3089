"""The cluster's tests run against a PRIVATE redis-server on a free port (so restarting it
disturbs no one else) and, for the whole cluster, a fresh PostgreSQL database. When the binary
or the server is truly absent the tests are skipped, saying which."""

from __future__ import annotations

import shutil
import socket
import subprocess
import time
import uuid
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from server.store import accounts
from server.store import runs as run_store
from server.store.accounts import Role
from server.store.db import Store
from server.store.models import RunRecord
from tests.store.conftest import postgres_url  # noqa: F401  (a fresh database per test)
from tests.waiting import wait_until

REDIS_SERVER = shutil.which("redis-server") or "/usr/bin/redis-server"
REDIS_START_TIMEOUT_S = 20.0  # [s] a loaded 2-core machine


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


@dataclass
class PrivateRedis:
    """A redis-server of this test alone: no persistence, so a restart forgets everything,
    as a Redis without a volume does."""

    port: int
    folder: Path
    process: subprocess.Popen | None = None

    @property
    def url(self) -> str:
        return f"redis://127.0.0.1:{self.port}/0"

    def start(self) -> None:
        self.process = subprocess.Popen(
            [REDIS_SERVER, "--port", str(self.port), "--bind", "127.0.0.1", "--save", "",
             "--appendonly", "no", "--dir", str(self.folder), "--protected-mode", "no"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )  # fmt: skip
        import redis

        client = redis.Redis(port=self.port, socket_connect_timeout=0.5)

        def answers() -> bool:
            try:
                return bool(client.ping())
            except redis.RedisError:
                return False

        try:
            wait_until(answers, REDIS_START_TIMEOUT_S, "the private redis-server answered PING")
        finally:
            client.close()

    def stop(self) -> None:
        if self.process is not None:
            self.process.kill()
            self.process.wait(10)
            self.process = None

    def restart(self, down_s: float = 0.0) -> None:
        self.stop()
        time.sleep(down_s)  # the outage itself is what the test is about
        self.start()


@pytest.fixture
def private_redis(tmp_path) -> Iterator[PrivateRedis]:
    if not Path(REDIS_SERVER).exists():
        pytest.skip(f"redis-server is not installed ({REDIS_SERVER}); the cluster needs it")
    server = PrivateRedis(free_port(), tmp_path)
    server.start()
    yield server
    server.stop()


@pytest.fixture
def sqlite_store(tmp_path) -> Iterator[Store]:
    store = Store.open(f"sqlite:///{tmp_path / 'robodojo.db'}")
    yield store
    store.close()


def queued_run(store: Store, run_dir: Path, state: str = "created") -> str:
    """A run record as a web process stores it before queueing the job."""
    with store.session() as db:
        user = accounts.create_user(db, f"student-{uuid.uuid4().hex[:6]}", Role.STUDENT)
        run_id = uuid.uuid4().hex
        run_store.add(
            db,
            RunRecord(
                id=run_id,
                user_id=user.user.id,
                exercise_id=None,
                robot="crowbot",
                world="empty",
                clock="lockstep",
                duration_s=1.0,
                seed=0,
                state=state,
                reason="",
                created_at=time.time(),
                code=[],
                metrics={},
                nodes={},
                checks=[],
                run_dir=str(run_dir / run_id),
            ),
        )
    return run_id


LAST_LINES_ON_FAILURE = 60  # of each web process and worker: enough to see what went wrong


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item, call):
    """A failed cluster test shows what its processes said last: a web process or worker that
    logged a fault is the likeliest witness of a failure seen only from outside."""
    report = yield
    lab = item.funcargs.get("cluster") if report.when == "call" and report.failed else None
    if lab is not None:
        for index, web in enumerate(lab.webs):
            lines = "\n".join(web.output[-LAST_LINES_ON_FAILURE:])
            report.sections.append((f"web process {index}, last lines", lines))
        for index, worker in enumerate(lab.workers):
            lines = "\n".join(worker.output[-LAST_LINES_ON_FAILURE:])
            report.sections.append((f"worker {index}, last lines", lines))
    return report
