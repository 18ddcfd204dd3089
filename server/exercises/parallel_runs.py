"""A check's runs side by side in worker processes, one sandbox launcher per process.

    outcomes = run_in_processes(functools.partial(run_case, exercise, nodes, root), cases)

A lockstep run is a loop in Python (physics, routing, recording) that hands over to its
sandboxed nodes at every wake-up. Runs in threads of one process share one GIL, so two seeds'
loops take turns on one core; in processes they use both cores of the lab machine, and a run's
nodes (separate processes anyway) fill the gaps while its loop waits (issue 18: a check in
seconds). Results are bit for bit those of the same runs in threads: each run is deterministic
on its own and nothing is shared between them.

Workers are forked from the caller when it runs a single thread (the CLI): they start with its
imports, at once. A caller with threads (a test session, a service) gets them from a forkserver
instead, since forking a threaded process can copy a lock another thread holds; the forkserver
imports the engine once (~0.7 s) and forks each worker ready to run.

Every worker makes its own `Launcher` without a warm pool: a cold node is Ready in ~0.1 s and
imports only what its code imports, while a pool refilling in the background would import every
heavy library for nodes nobody takes (measured: 2.5-7 s of CPU per check, on two cores).
"""

from __future__ import annotations

import contextlib
import ctypes
import multiprocessing
import os
import pickle
import signal
import sys
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import TypeVar

from sandbox.launcher import Launcher

Case = TypeVar("Case")
Outcome = TypeVar("Outcome")

# The most worker processes one check starts [processes]. A lockstep run keeps about one core
# busy (its loop and its nodes take turns), so more runs than cores still overlap usefully; each
# worker holds ~100 MiB and its run's nodes, so a check of many seeds queues the rest instead.
MAX_WORKER_PROCESSES = 8

# What a worker imports before it is forked, once per forkserver: the engine, the exercises
# and the message types. A worker then starts in milliseconds instead of ~0.5 s.
_PRELOAD = ["server.exercises.grading", "server.exercises.registry", "server.runs.run"]

_PR_SET_PDEATHSIG = 1  # prctl(2): the signal a process gets when its parent ends

_worker_launcher: Launcher | None = None  # this worker process's own launcher


class GradingError(ValueError):
    """A check could not run its cases in worker processes (the sentence says why)."""


def default_start_method() -> str:
    """Fork a caller that runs a single thread, else use the forkserver (module docstring)."""
    return "fork" if threading.active_count() == 1 else "forkserver"


def _context(start_method: str | None) -> multiprocessing.context.BaseContext:
    start_method = start_method or default_start_method()
    context = multiprocessing.get_context(start_method)
    if start_method != "forkserver":
        return context
    # A worker runs the caller's main module again as __mp_main__ (as under spawn; entry points
    # guard their work with `if __name__ == "__main__"`). Imported once in the forkserver, it
    # costs a worker nothing: for `python -m server.cli` that is ~0.5 s (SQLAlchemy) per worker.
    main_spec = getattr(sys.modules["__main__"], "__spec__", None)
    main_module = [main_spec.name] if main_spec is not None and main_spec.name else []
    context.set_forkserver_preload(_PRELOAD + main_module)
    return context


def _become_a_run_of_its_own() -> None:
    """A worker's first act: a session of its own, and death with the caller.

    The kernel's autogroup scheduler shares the CPU between sessions, and every sandboxed node
    has its own session (bwrap --new-session). Workers left in the caller's session shared one
    share among them while each node they wait on had a whole one, so on a loaded machine every
    handoff waited (ir_scout_avoidance at load 29 on 2 cores: 95 s wall in the caller's session,
    39 s in their own). Out of the caller's session, a worker no longer gets the terminal's
    Ctrl-C: the caller kills it (`run_in_processes`), and the kernel does if the caller dies."""
    parent_pid = os.getppid()  # this process, or the forkserver that forked the worker
    with contextlib.suppress(OSError):
        os.setsid()
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent_pid:  # the parent died before the line above: no one waits
        os._exit(1)


def _in_worker(job: Callable[[Case, Launcher], Outcome], case: Case, unsafe: bool) -> Outcome:
    """One case in a worker process, with the launcher this process keeps for all its cases."""
    global _worker_launcher
    if _worker_launcher is None:
        _worker_launcher = Launcher(pool_size=0, unsafe_no_sandbox=unsafe)
    return job(case, _worker_launcher)


def run_in_processes(
    job: Callable[[Case, Launcher], Outcome],
    cases: Sequence[Case],
    unsafe_no_sandbox: bool = False,
    start_method: str | None = None,
) -> list[Outcome]:
    """`job(case, launcher)` for every case, each in a worker process; outcomes in case order.

    `job`, the cases and the outcomes cross process boundaries, so they must pickle: module-level
    functions (a `functools.partial` of one), dataclasses, plain values. A job that raises
    raises here (a `SandboxUnavailable` from a worker's launcher, say). `start_method`: "fork" or
    "forkserver"; None picks as the module docstring says."""
    try:
        pickle.dumps((job, list(cases)))
    except (pickle.PicklingError, TypeError, AttributeError) as error:
        raise GradingError(
            "this check cannot run in worker processes: everything a run needs must be sendable "
            "to another process (checks as module-level functions, not lambdas or closures); "
            f"Python says: {error}"
        ) from None
    workers = max(1, min(len(cases), MAX_WORKER_PROCESSES))
    try:
        with ProcessPoolExecutor(
            max_workers=workers,
            mp_context=_context(start_method),
            initializer=_become_a_run_of_its_own,
        ) as pool:
            futures = [pool.submit(_in_worker, job, case, unsafe_no_sandbox) for case in cases]
            try:
                return [future.result() for future in futures]
            except KeyboardInterrupt:
                # The workers, in sessions of their own, did not get it: end them (their nodes
                # die with them) instead of waiting for their runs to finish.
                for process in list(pool._processes.values()):  # no public way to stop them
                    process.kill()
                pool.shutdown(wait=False, cancel_futures=True)
                raise
    except BrokenProcessPool:
        raise GradingError(
            "a grading worker process died before its run finished (killed, or out of memory); "
            "run the check again, and if it keeps happening, with fewer seeds"
        ) from None
