"""The analysis workers (server/editor/pool.py): a request past its time limit or a worker that
dies costs that worker, which is replaced; the caller gets a sentence, never a hang."""

from __future__ import annotations

import dataclasses
import os
import signal

import pytest

from server.editor.limits import LIMITS
from server.editor.pool import AnalysisPool, AnalysisUnavailable
from tests.waiting import wait_until

START_S = 120.0  # [s] a worker's start and warm-up on a loaded 2-core machine
CHECKS = {"op": "checks", "code": "from std_msgs.msg import Int32\nInt32().dta\n", "robot": None}


@pytest.fixture(scope="module")
def shared_pool():
    """One started worker for the tests that leave it as they found it."""
    started = AnalysisPool(dataclasses.replace(LIMITS, workers=1))
    started.start()
    assert started.ready.wait(START_S), "the analysis worker did not start"
    yield started
    started.close()


@pytest.fixture
def pool():
    limits = dataclasses.replace(LIMITS, workers=1)
    started = AnalysisPool(limits)
    started.start()
    assert started.ready.wait(START_S), "the analysis worker did not start"
    yield started
    started.close()


def only_worker(pool):
    return wait_until(lambda: len(pool._workers) == 1 and next(iter(pool._workers)),
                      START_S, "one worker running")  # fmt: skip


def test_a_worker_answers_checks(shared_pool):
    answer = shared_pool.call(CHECKS)
    assert [d["rule"] for d in answer["diagnostics"]] == ["robodojo-field"]
    assert answer["syntax"] == []


def test_a_slow_request_is_answered_with_a_sentence_and_its_worker_goes_on(shared_pool):
    pool = shared_pool
    worker = only_worker(pool)
    pool.limits = dataclasses.replace(pool.limits, analysis_timeout_s=0.000_001)
    with pytest.raises(AnalysisUnavailable, match=r"took longer than 1e-06 s"):
        pool.call(CHECKS)
    pool.limits = dataclasses.replace(LIMITS, workers=1, queue_wait_s=START_S)
    assert pool.call(CHECKS)["diagnostics"]  # the same worker, back once it answered
    assert only_worker(pool) is worker and worker.process.poll() is None
    pool.limits = dataclasses.replace(LIMITS, workers=1)


@pytest.mark.slow  # a worker's start and warm-up again
def test_a_request_past_the_hard_limit_kills_the_worker_and_another_takes_over(pool):
    worker = only_worker(pool)
    pool.limits = dataclasses.replace(
        pool.limits, analysis_timeout_s=0.000_001, analysis_hard_timeout_s=0.000_002
    )
    with pytest.raises(AnalysisUnavailable, match=r"took longer than"):
        pool.call(CHECKS)
    wait_until(lambda: worker.process.poll() is not None, START_S, "the slow worker killed")
    pool.limits = dataclasses.replace(LIMITS, workers=1, queue_wait_s=START_S)
    assert pool.call(CHECKS)["diagnostics"]  # the replacement answers
    assert only_worker(pool) is not worker


@pytest.mark.slow  # a worker's start and warm-up again
def test_a_worker_that_dies_is_replaced(pool):
    worker = only_worker(pool)
    os.kill(worker.process.pid, signal.SIGKILL)
    worker.process.wait()
    with pytest.raises(AnalysisUnavailable, match="its worker ended"):
        pool.call(CHECKS)
    pool.limits = dataclasses.replace(pool.limits, queue_wait_s=START_S)
    assert pool.call(CHECKS)["diagnostics"]


def test_hostile_text_is_answered_without_running_into_the_time_limit(shared_pool):
    pool = shared_pool
    worker = only_worker(pool)
    deep = "x = " + "1+" * 100_000 + "1\n"
    assert pool.call({**CHECKS, "code": deep})["syntax"][0]["rule"] == "E999"
    assert pool.call({"op": "complete", "code": deep, "line": 1, "column": 5, "robot": None}) == {
        "completions": [],
        "signature": None,
    }
    assert only_worker(pool) is worker  # the same worker: nothing was killed


@pytest.mark.slow  # a worker's start and warm-up again
def test_close_ends_every_worker():
    pool = AnalysisPool(dataclasses.replace(LIMITS, workers=1))
    pool.start()
    assert pool.ready.wait(START_S)
    worker = only_worker(pool)
    pool.close()
    assert worker.process.poll() is not None
    assert pool.stub_root is not None and not pool.stub_root.exists()
