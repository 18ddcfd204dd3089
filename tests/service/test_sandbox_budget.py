"""One sandbox budget per student (issue 33, finding 4; server/service/sandbox_budget.py): a
run's nodes and the Python launch files being read count together, in jobs at once and in
memory (each sandbox at its cap), counted from the database as the run limits are."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import pytest

from sandbox.limits import DEFAULT_LIMITS
from server.api.settings import Settings
from server.runs.spec import NodeSpec
from server.service.runs import RunLimitError, RunRequest, RunRequestError, RunService
from server.service.sandbox_budget import SandboxBudget
from server.store import accounts, sandbox_leases
from server.store.db import Store
from server.store.sandbox_leases import Holding
from tests.store.conftest import postgres_url, store_url  # noqa: F401 (fixtures)

CAP = DEFAULT_LIMITS.memory_bytes  # [B] one sandbox's memory cap: 768 MiB


class HeldExecutor:
    """Takes every run and never ends it: each stays active, as a long run would."""

    def submit(self, job) -> None:
        pass


@pytest.fixture
def service(store_url, tmp_path) -> Iterator[RunService]:  # noqa: F811 (a fixture)
    store = Store.open(store_url)
    yield RunService(
        store, Settings(data=tmp_path, database_url=store_url), None, executor=HeldExecutor()
    )
    store.close()


def student(service: RunService, name: str = "student") -> str:
    with service.store.session() as db:
        return accounts.create_user(db, name, accounts.Role.STUDENT).user.id


def run_of(nodes: int) -> RunRequest:
    code = "def step(obs):\n    return {}\n"
    return RunRequest(
        robot="crowbot", world="wall_approach", exercise=None, clock=None, duration_s=1.0,
        seed=None, nodes=tuple(NodeSpec(f"n{i}", code, f"n{i}.py") for i in range(nodes)),
    )  # fmt: skip


def test_the_default_budget_holds_ten_sandboxes_of_a_students_runs(service):
    me = student(service)
    service.start(me, run_of(8))  # the largest run: 6 GiB of caps
    with pytest.raises(RunLimitError) as refused:
        service.start(me, run_of(3))  # 11 sandboxes: 8.2 GiB
    assert str(refused.value) == (
        "this run's 3 nodes would take 3 sandboxes of up to 768 MiB each; with the 8 your runs "
        "and jobs hold now that is 8.2 GiB, over your budget of 8.0 GiB: wait for a run to end, "
        "or stop one"
    )
    assert refused.value.retry_after_s == service.settings.retry_after_s
    service.start(me, run_of(2))  # 10 sandboxes: 7.5 GiB
    other = student(service, "other")  # a budget per student
    service.start(other, run_of(8))


def test_launch_files_being_read_are_sandbox_jobs_beside_the_runs(service):
    me = student(service)
    with contextlib.ExitStack() as jobs:
        for _ in range(3):
            jobs.enter_context(service.launch_file_job(me))
        with pytest.raises(RunLimitError, match=r"you already have 3 sandbox jobs going \(0 runs, "
                           r"3 launch files being read\); the limit is 3 at once"):  # fmt: skip
            service.launch_file_job(me).__enter__()
        with pytest.raises(RunLimitError, match="3 sandbox jobs going"):
            service.start(me, run_of(1))
    service.start(me, run_of(1))  # the jobs gave their leases back
    with service.launch_file_job(me):
        pass
    service.start(me, run_of(1))
    # Two runs going: a launch file for a third run is refused before any sandbox starts.
    with pytest.raises(RunLimitError, match="you already have 2 runs going"):
        service.launch_file_job(me).__enter__()


def test_a_lease_is_given_back_when_the_job_fails_and_forgotten_when_it_expires(service):
    me = student(service)
    with pytest.raises(ValueError), service.launch_file_job(me):
        raise ValueError("the reader failed")
    with service.store.session() as db:
        assert sandbox_leases.holding(db, me, now=0.0).leases == 0
        sandbox_leases.take(db, me, "launch file", 1, now=100.0, lasts_s=70.0)  # long dead
    with contextlib.ExitStack() as jobs:
        for _ in range(3):  # the expired lease does not count
            jobs.enter_context(service.launch_file_job(me))


def test_a_job_larger_than_the_whole_budget_is_refused_as_it_is(tmp_path):
    budget = SandboxBudget(max_jobs=3, memory_bytes=2 * CAP, sandbox_memory_bytes=CAP)
    nothing = Holding(runs=0, run_sandboxes=0, leases=0, lease_sandboxes=0)
    refusal = budget.refusal(nothing, 3, "this run's 3 nodes")
    assert refusal is not None and not refusal.waiting_helps
    assert refusal.sentence == (
        "this run's 3 nodes would take 3 sandboxes of up to 768 MiB each (2.2 GiB), more than a "
        "student's budget of 1.5 GiB at once; use fewer nodes"
    )
    assert budget.refusal(nothing, 2, "this run's 2 nodes") is None
    unbounded = SandboxBudget(max_jobs=3, memory_bytes=0, sandbox_memory_bytes=CAP)
    assert unbounded.refusal(nothing, 8, "a run") is None


def test_a_run_too_large_for_the_budget_is_a_422(store_url, tmp_path):  # noqa: F811
    store = Store.open(store_url)
    try:
        settings = Settings(data=tmp_path, database_url=store_url,
                            student_sandbox_memory_bytes=2 * CAP)  # fmt: skip
        service = RunService(store, settings, None, executor=HeldExecutor())
        with pytest.raises(RunRequestError, match="use fewer nodes"):
            service.start(student(service), run_of(3))
    finally:
        store.close()
