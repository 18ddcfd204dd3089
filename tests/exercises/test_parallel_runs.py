"""A check's runs in worker processes: each case in another process with a launcher of its own,
outcomes back in case order, and every way it can go wrong said in a sentence."""

from __future__ import annotations

import functools
import os
import signal
import subprocess
import sys
import threading
import time

import psutil
import pytest

from sandbox.launcher import Launcher
from server.exercises.parallel_runs import GradingError, default_start_method, run_in_processes
from tests.waiting import wait_until


def _where(offset: int, case: int, launcher: Launcher) -> tuple[int, int, int, bool]:
    return case + offset, os.getpid(), launcher.pool_size, launcher.sandboxed


def _session(case: int, launcher: Launcher) -> int:
    return os.getsid(0)


def _linger(case: int, launcher: Launcher) -> int:
    time.sleep(120)  # the behaviour under test: a run still going when its caller is killed
    return case


def _refuse(case: int, launcher: Launcher) -> int:
    if case == 2:
        raise ValueError(f"case {case} has nothing to judge")
    return case


def _die(case: int, launcher: Launcher) -> int:
    os.kill(os.getpid(), signal.SIGKILL)
    return case


@pytest.mark.parametrize("start_method", ["fork", "forkserver"])
def test_each_case_runs_in_a_worker_process_with_a_cold_sandbox_launcher(start_method):
    outcomes = run_in_processes(functools.partial(_where, 100), [3, 1, 2], False, start_method)
    assert [value for value, *_ in outcomes] == [103, 101, 102]  # in case order
    pids = {pid for _, pid, _, _ in outcomes}
    assert os.getpid() not in pids
    # No warm pool: it would import every heavy library for nodes nobody takes.
    assert all(pool_size == 0 and sandboxed for _, _, pool_size, sandboxed in outcomes)


def test_a_job_that_raises_raises_in_the_caller():
    with pytest.raises(ValueError, match="case 2 has nothing to judge"):
        run_in_processes(_refuse, [1, 2, 3], False, "forkserver")


def test_a_job_that_cannot_reach_another_process_is_refused_with_a_sentence():
    with pytest.raises(GradingError, match="module-level functions, not lambdas"):
        run_in_processes(lambda case, launcher: case, [1])


@pytest.mark.parametrize("start_method", ["fork", "forkserver"])
def test_a_worker_that_dies_is_reported_as_a_sentence_not_a_traceback(start_method):
    with pytest.raises(GradingError, match="worker process died before its run finished"):
        run_in_processes(_die, [1], False, start_method)


def test_a_caller_with_threads_is_not_forked():
    """Forking a threaded process can copy a lock another thread holds: the forkserver then."""
    release = threading.Event()
    other = threading.Thread(target=release.wait)
    other.start()
    try:
        assert default_start_method() == "forkserver"
    finally:
        release.set()
        other.join()
    assert default_start_method() == ("fork" if threading.active_count() == 1 else "forkserver")


@pytest.mark.parametrize("start_method", ["fork", "forkserver"])
def test_a_worker_has_a_session_of_its_own_as_its_nodes_do(start_method):
    """The scheduler shares the CPU between sessions: a worker weighs as one of its nodes."""
    sessions = run_in_processes(_session, [1, 2], False, start_method)
    assert os.getsid(0) not in sessions and len(set(sessions)) == 2


def test_the_workers_die_with_a_caller_that_is_killed():
    script = (
        "from server.exercises.parallel_runs import run_in_processes\n"
        "from tests.exercises.test_parallel_runs import _linger\n"
        "if __name__ == '__main__':\n"
        "    run_in_processes(_linger, [1, 2], False, 'fork')\n"
    )
    caller = subprocess.Popen([sys.executable, "-c", script])
    try:
        workers = wait_until(
            lambda: psutil.Process(caller.pid).children(), 60, "the caller forked its workers"
        )
    finally:
        caller.kill()
        caller.wait(timeout=30)
    wait_until(
        lambda: not any(w.is_running() and w.status() != psutil.STATUS_ZOMBIE for w in workers),
        30,
        "the workers of a killed caller ended",
    )
