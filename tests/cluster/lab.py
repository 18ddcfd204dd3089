"""A whole cluster on loopback for the tests: a private redis-server, a fresh PostgreSQL
database, two web processes (`robodojo serve --redis-url ...`) and two workers (`robodojo
worker ...`), all subprocesses sharing one data folder, as docker/compose.yaml runs them."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from dataclasses import dataclass, field
from pathlib import Path

import httpx

from tests.api.conftest import LabServer, free_port, start_server, stop_server
from tests.waiting import wait_until

ROOT = Path(__file__).resolve().parents[2]
WORKER_START_TIMEOUT_S = 60.0  # [s] a cold interpreter on a loaded 2-core machine
RUNS_PER_WORKER = 1  # so a third run waits on the queue while two run


@dataclass
class Worker:
    process: subprocess.Popen
    output: list[str] = field(default_factory=list)

    @property
    def pid(self) -> int:
        return self.process.pid


@dataclass
class Cluster:
    data: Path
    redis_url: str
    database_url: str
    webs: list[LabServer] = field(default_factory=list)
    workers: list[Worker] = field(default_factory=list)

    @property
    def env(self) -> dict[str, str]:
        return {
            "ROBODOJO_REDIS_URL": self.redis_url,
            "ROBODOJO_DATABASE_URL": self.database_url,
            "ROBODOJO_SANDBOX_POOL": "0",  # cold nodes: no idle sandboxes eating the 2 cores
        }

    # ------------------------------------------------------------------------------ processes
    def start_web(self, port: int | None = None) -> LabServer:
        web = start_server(self.data, self.env, port=port or free_port())
        if self.webs and not web.admin_token:  # the first web process made the instructor
            web.admin_token = self.webs[0].admin_token
        return web

    def restart_web(self, index: int) -> LabServer:
        old = self.webs[index]
        stop_server(old)
        port = int(old.url.rsplit(":", 1)[1])
        new = self.start_web(port)
        new.admin_token = old.admin_token
        self.webs[index] = new
        return new

    def start_worker(self, *extra_args: str) -> Worker:
        """`extra_args`: e.g. "--rosserial-port", "0" for the bench worker."""
        command = [sys.executable, "-m", "server.cli", "worker", "--redis-url", self.redis_url,
                   "--database-url", self.database_url, "--data", str(self.data),
                   "--processes", "1", "--runs-per-process", str(RUNS_PER_WORKER),
                   *extra_args]  # fmt: skip
        env = {**os.environ, **self.env, "PYTHONUNBUFFERED": "1"}
        process = subprocess.Popen(command, cwd=ROOT, env=env, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True)  # fmt: skip
        worker = Worker(process)
        self.workers.append(worker)  # stopped at the end even if its start fails

        def pump() -> None:
            try:
                for line in process.stdout:
                    worker.output.append(line.rstrip("\n"))
            except (ValueError, OSError):
                return

        threading.Thread(target=pump, name="worker-output", daemon=True).start()
        wait_until(
            lambda: (
                process.poll() is not None
                or any("RoboDojo worker" in line for line in worker.output)
            ),
            WORKER_START_TIMEOUT_S,
            "the worker said it is taking runs",
        )
        assert process.poll() is None, "the worker exited:\n" + "\n".join(worker.output[-40:])
        return worker

    def stop(self) -> None:
        for web in self.webs:
            stop_server(web)
        for worker in self.workers:
            if worker.process.poll() is None:
                worker.process.terminate()
        for worker in self.workers:
            try:
                worker.process.wait(30)
            except subprocess.TimeoutExpired:
                worker.process.kill()
                worker.process.wait(10)
            if worker.process.stdout is not None:  # else a ResourceWarning fails the test
                worker.process.stdout.close()

    # ------------------------------------------------------------------------------ clients
    def client_on(self, index: int, like: httpx.Client) -> httpx.Client:
        """The same browser (cookie, token) talking to another web process."""
        web = self.webs[index]
        client = web.client()
        client.cookies = like.cookies
        client.headers["Origin"] = web.url
        client.token = like.token  # type: ignore[attr-defined]
        client.user = like.user  # type: ignore[attr-defined]
        return client

    def worker_of(self, run_id: str) -> Worker:
        """The worker process holding a run (runs.worker_id is host:pid)."""
        from server.store import runs as run_store
        from server.store.db import Store

        store = Store.open(self.database_url)
        try:
            with store.session() as db:
                worker_id = run_store.get(db, run_id).worker_id
        finally:
            store.close()
        pid = int(worker_id.rsplit(":", 1)[1])
        return next(w for w in self.workers if w.pid == pid)


def wait_for_state(client: httpx.Client, run_id: str, states: set[str], timeout_s: float) -> dict:
    run: dict = {}

    def reached() -> bool:
        nonlocal run
        run = client.get(f"/api/runs/{run_id}").json()
        return run.get("state") in states

    wait_until(reached, timeout_s, f"run {run_id} reached one of {sorted(states)}")
    return run
