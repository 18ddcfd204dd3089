"""A worker that loses the database says so (log, its state and message in the roster kept in
Redis) and stops taking jobs (its Dramatiq consumers pause); when the database is back it takes
jobs again. Its Redis report keeps the reapers from ending its runs meanwhile."""

from __future__ import annotations

import contextlib
import json

import pytest
from sqlalchemy.exc import OperationalError

from server.api.settings import Settings
from server.store import workers as roster
from server.workers.cluster import worker_key
from server.workers.worker import WorkerProcess
from tests.waiting import wait_until

pytestmark = pytest.mark.slow


def test_a_worker_without_its_database_pauses_and_says_so(private_redis, tmp_path, monkeypatch):
    settings = Settings(data=tmp_path / "data", database_url=f"sqlite:///{tmp_path / 'db'}",
                        redis_url=private_redis.url, sandbox_pool=0)  # fmt: skip
    process = WorkerProcess(settings, capacity=1)
    process.start()
    try:
        consumers = process.worker.consumers
        wait_until(lambda: consumers, 20, "the worker's consumers started")
        healthy = process.store.session

        @contextlib.contextmanager
        def unreachable():
            raise OperationalError("connect", {}, ConnectionRefusedError("connection refused"))
            yield

        monkeypatch.setattr(process.store, "session", unreachable)
        wait_until(lambda: process.state == roster.WorkerState.PAUSED, 20, "the worker paused")
        assert all(consumer.paused for consumer in consumers.values())
        assert "cannot reach the database" in process.message

        def reported() -> dict:
            raw = process.client.get(worker_key(process.id))
            return json.loads(raw) if raw else {}

        wait_until(lambda: reported().get("state") == "paused", 20, "Redis has its report")
        assert "taking no runs until it is back" in reported()["message"]

        monkeypatch.setattr(process.store, "session", healthy)
        wait_until(lambda: process.state == roster.WorkerState.READY, 20, "the worker resumed")
        assert not any(consumer.paused for consumer in consumers.values())

        def listed_state() -> str:
            with process.store.session() as db:
                return {w["id"]: w["state"] for w in roster.listing(db)}[process.id]

        wait_until(lambda: listed_state() == "ready", 20, "the roster lists it ready again")
    finally:
        process.stop()
