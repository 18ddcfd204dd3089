"""Run admission across web processes (issue 16): limits are counted from the database, so two
web processes (two Stores on one database, each with its own RunService) starting runs for one
student at the same moment must still keep the student's limit and the lab's."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest

from server.api.settings import Settings
from server.runs.spec import NodeSpec
from server.service import disk
from server.service.runs import RunLimitError, RunRequest, RunService
from server.store import accounts
from server.store import runs as run_store
from server.store.db import Store
from tests.store.conftest import postgres_url, store_url  # noqa: F401 (fixtures)

WEB_PROCESSES = 2
ROUNDS = 3
# [s] between the count and the insert: widens the window two admissions could both pass through
COUNT_TO_INSERT_S = 0.05


class HeldExecutor:
    """Takes every run and never ends it: each stays active, as a long run would."""

    def submit(self, job) -> None:
        pass


@pytest.fixture
def services(store_url, tmp_path) -> Iterator[list[RunService]]:  # noqa: F811 (a fixture)
    settings = Settings(data=tmp_path, database_url=store_url, max_runs_per_student=1)
    stores = [Store.open(store_url) for _ in range(WEB_PROCESSES)]
    yield [RunService(store, settings, None, executor=HeldExecutor()) for store in stores]
    for store in stores:
        store.close()


def request() -> RunRequest:
    code = "def step(obs):\n    return {}\n"
    return RunRequest(
        robot="crowbot",
        world="wall_approach",
        exercise=None,
        nodes=(NodeSpec("driver", code, "driver.py"),),
        clock=None,
        duration_s=1.0,
        seed=None,
    )


def admit_at_once(services: list[RunService], user_ids: list[str]) -> list[object]:
    """Each service starts a run for its user at the same moment: the records or the refusals."""
    barrier = threading.Barrier(len(services))
    outcomes: list[object] = [None] * len(services)

    def start(index: int) -> None:
        barrier.wait()
        try:
            outcomes[index] = services[index].start(user_ids[index], request())
        except RunLimitError as error:
            outcomes[index] = error

    threads = [threading.Thread(target=start, args=(i,)) for i in range(len(services))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(60)
    return outcomes


def slow_budget_check(monkeypatch) -> None:
    check = disk.check_budgets

    def slow(*args, **kwargs):  # called after the counts, before the record is stored
        time.sleep(COUNT_TO_INSERT_S)
        return check(*args, **kwargs)

    monkeypatch.setattr(disk, "check_budgets", slow)


def new_user(store: Store, name: str) -> str:
    with store.session() as db:
        return accounts.create_user(db, name, accounts.Role.STUDENT).user.id


def active(store: Store, user_id: str | None = None) -> int:
    with store.session() as db:
        return run_store.active_count(db, user_id)


def test_two_web_processes_starting_at_once_keep_a_students_limit(services, monkeypatch):
    slow_budget_check(monkeypatch)
    for round_ in range(ROUNDS):
        student = new_user(services[0].store, f"twice-{round_}")
        outcomes = admit_at_once(services, [student] * WEB_PROCESSES)
        refused = [o for o in outcomes if isinstance(o, RunLimitError)]
        assert len(refused) == WEB_PROCESSES - 1, outcomes
        assert "you already have 1 runs going" in str(refused[0])
        assert active(services[0].store, student) == 1


def test_two_web_processes_starting_at_once_keep_the_labs_limit(services, monkeypatch):
    slow_budget_check(monkeypatch)
    monkeypatch.setattr(services[0].settings, "max_runs_total", WEB_PROCESSES)  # both share it
    store = services[0].store
    first = new_user(store, "first")
    services[0].start(first, request())  # the lab holds WEB_PROCESSES runs: one place left
    students = [new_user(store, f"late-{i}") for i in range(WEB_PROCESSES)]
    outcomes = admit_at_once(services, students)
    refused = [o for o in outcomes if isinstance(o, RunLimitError)]
    assert len(refused) == WEB_PROCESSES - 1, outcomes
    assert "maximum of 2 runs" in str(refused[0])
    assert active(store) == WEB_PROCESSES
