"""The workers' roster in the store: reports renew a worker, a silent one is lost and its
active runs (only those) end "failed: worker lost" exactly once whoever reaps, a worker alive
in Redis but cut off from the database is not reaped, and the listing says who is what."""

from __future__ import annotations

import time

import pytest

from server.store import runs as run_store
from server.store import workers as roster
from server.store.db import Store
from server.store.workers import WorkerReport
from tests.cluster.conftest import queued_run

pytestmark = pytest.mark.slow


@pytest.fixture(params=["sqlite", "postgresql"])
def store(request, tmp_path):
    if request.param == "sqlite":
        url = f"sqlite:///{tmp_path / 'robodojo.db'}"
    else:
        url = request.getfixturevalue("postgres_url")
    opened = Store.open(url)
    yield opened
    opened.close()


def running_on(store: Store, tmp_path, worker: str, state: str = "running") -> str:
    run_id = queued_run(store, tmp_path)
    with store.session() as db:
        assert run_store.claim(db, run_id, worker)
        run_store.set_state(db, run_id, state)
    return run_id


def test_a_silent_workers_active_runs_fail_once_and_others_are_untouched(store, tmp_path):
    now = time.time()
    with store.session() as db:
        roster.report(db, WorkerReport("a:1", "a", 4, 2, "ready"), now=now - 30)
        roster.report(db, WorkerReport("b:2", "b", 4, 1, "ready"), now=now)
    lost_1 = running_on(store, tmp_path, "a:1")
    lost_2 = running_on(store, tmp_path, "a:1", state="paused")
    done = running_on(store, tmp_path, "a:1", state="finished")
    healthy = running_on(store, tmp_path, "b:2")
    queued = queued_run(store, tmp_path)
    with store.session() as db:
        ended = roster.reap(db, now=now)
    assert sorted(ended) == sorted([lost_1, lost_2])
    with store.session() as db:
        assert roster.reap(db, now=now + 1) == []  # a second reaper finds nothing to do
        for run_id in (lost_1, lost_2):
            record = run_store.get(db, run_id)
            assert (record.state, record.reason) == ("failed", roster.WORKER_LOST)
        assert run_store.get(db, done).state == "finished"
        assert run_store.get(db, healthy).state == "running"
        assert run_store.get(db, queued).state == "created"
        states = {w["id"]: w["state"] for w in roster.listing(db, now=now)}
    assert states == {"a:1": "lost", "b:2": "ready"}


def test_a_worker_alive_in_redis_but_cut_off_from_the_database_keeps_its_runs(store, tmp_path):
    now = time.time()
    with store.session() as db:
        roster.report(db, WorkerReport("c:3", "c", 4, 1, "ready"), now=now - 30)
    run_id = running_on(store, tmp_path, "c:3")
    with store.session() as db:
        assert roster.reap(db, now=now, alive=lambda worker: worker == "c:3") == []
        assert run_store.get(db, run_id).state == "running"


def test_reports_renew_and_the_listing_shows_capacity_and_silence(store):
    now = time.time()
    with store.session() as db:
        roster.report(db, WorkerReport("d:4", "d", 8, 0, "ready"), now=now - 10)
        roster.report(db, WorkerReport("d:4", "d", 8, 3, "paused", "no database"), now=now - 1)
        roster.report(db, WorkerReport("e:5", "e", 6, 0, "ready"), now=now - 8)
        listed = {w["id"]: w for w in roster.listing(db, now=now)}
        assert roster.capacity(db, now=now) == 0  # d is paused, e is silent
    assert listed["d:4"]["running"] == 3 and listed["d:4"]["state"] == "paused"
    assert listed["d:4"]["message"] == "no database" and listed["d:4"]["last_seen_s"] == 1.0
    assert listed["e:5"]["state"] == "lost"  # silent past LOST_AFTER_S, not reaped yet


def test_processes_starting_at_once_on_a_new_database_all_open_it(postgres_url):
    """A cluster's web processes and workers start together on an empty PostgreSQL database:
    one migrates, the others wait for it (an advisory lock) instead of failing on the
    migrations' CREATE TABLE."""
    from concurrent.futures import ThreadPoolExecutor

    def open_and_close(_) -> list[str]:
        opened = Store.open(postgres_url)
        try:
            return opened.tables()
        finally:
            opened.close()

    with ThreadPoolExecutor(4) as starting:
        tables = list(starting.map(open_and_close, range(4)))
    assert all("workers" in found and found == tables[0] for found in tables)
