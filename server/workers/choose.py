"""Which executor a web process sends its runs to (issue 16), from its settings."""

from __future__ import annotations

import os

from sandbox.launcher import Launcher
from server.store.db import Store
from server.workers.inprocess import InProcessExecutor
from server.workers.seams import RunExecutor


def local_worker_count(settings) -> int:
    """How many worker processes the embedded lab starts: `workers`, one per core when unset;
    0 runs every run in the web process itself."""
    return settings.workers if settings.workers is not None else os.cpu_count() or 1


def make_executor(settings, store: Store, launcher: Launcher, hardware=None) -> RunExecutor:
    """With a Redis URL, the cluster's queue (runs go to `robodojo worker` processes on any
    machine); else worker processes of this machine (the default), or this process's threads
    (`workers` 0). Without Redis, runs on a real robot execute in this process: its connection
    is here."""
    if settings.redis_url:
        from server.workers.cluster import QueueExecutor
        from server.workers.mirror import Mirrors

        return QueueExecutor(store, settings.redis_url, Mirrors())
    count = local_worker_count(settings)
    if count == 0:
        return InProcessExecutor(store, settings, launcher, hardware)
    from server.workers.processes import LocalProcessExecutor  # multiprocessing, on demand

    return LocalProcessExecutor(store, settings, launcher, hardware, processes=count)
