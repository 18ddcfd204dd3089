"""`robodojo worker`: run jobs of a cluster on this machine (issue 16).

    robodojo worker --redis-url redis://queue:6379/0 --database-url postgresql://lab@db/robodojo \\
                    --data /srv/robodojo [--processes N] [--runs-per-process M]

N processes (default: one per core), each a Dramatiq worker taking up to M runs at once with a
RunHost executing them (server/workers/worker.py). The `--data` folder must be the lab's shared
data volume, at the same path as on the web processes (recordings, logs and artifacts are read
from there by whichever web process is asked). With N > 1 this process only watches its
children: a child that exits is started again; SIGTERM stops them all cleanly.
"""

from __future__ import annotations

import argparse
import ctypes
import logging
import os
import signal
import subprocess
import sys
import threading

log = logging.getLogger("robodojo.worker")
RESTART_DELAY_S = 2.0  # [s] before a child that exited is started again
PR_SET_PDEATHSIG = 1  # prctl(2): a signal the child gets when this process dies


def _settings(args: argparse.Namespace):
    from server.api.settings import Settings

    overrides = {}
    for key in ("data", "database_url", "redis_url", "runs_per_process"):
        value = getattr(args, key, None)
        if value is not None:
            overrides[key] = value
    if args.processes is not None:
        overrides["worker_processes"] = args.processes
    if args.rosserial_port is not None:  # a bench worker: the robots connect to it
        overrides["rosserial_port"] = args.rosserial_port
        if args.rosserial_host is not None:
            overrides["rosserial_host"] = args.rosserial_host
    if args.unsafe_no_sandbox:
        overrides["unsafe_no_sandbox"] = True
    return Settings(**overrides)


def cmd_worker(args: argparse.Namespace) -> int:
    settings = _settings(args)
    if not settings.redis_url:
        raise ValueError("robodojo worker needs --redis-url (or ROBODOJO_REDIS_URL)")
    if not settings.database_url:
        raise ValueError(
            "robodojo worker needs --database-url postgresql://... (the lab's shared database); "
            "a worker cannot share the web process's SQLite file across machines"
        )
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    logging.getLogger("alembic.runtime.plugins").setLevel(logging.WARNING)
    bench = args.rosserial_port is not None
    # A bench is one process: its robots connect to one port (server/workers/bench.py).
    processes = 1 if bench else settings.worker_processes or os.cpu_count() or 1
    if processes == 1 or args.one_process:
        from server.workers.worker import WorkerProcess

        settings.data.mkdir(parents=True, exist_ok=True)
        WorkerProcess(settings, settings.runs_per_process, bench=bench).run()
        return 0
    return _supervise(processes)


def _supervise(count: int) -> int:
    """Start `count` one-process workers with this command's arguments and keep them going."""
    argv = [sys.executable, "-m", "server.cli", *sys.argv[1:], "--one-process"]
    stopping = threading.Event()
    children: list[subprocess.Popen | None] = [None] * count

    def stop(*_) -> None:
        stopping.set()

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    print(f"RoboDojo worker: starting {count} worker processes", flush=True)
    while not stopping.is_set():
        for index, child in enumerate(children):
            if child is None or child.poll() is not None:
                if child is not None:
                    log.warning("worker process %d exited (%s); starting it again",
                                child.pid, child.returncode)  # fmt: skip
                    if stopping.wait(RESTART_DELAY_S):
                        break
                children[index] = subprocess.Popen(argv, preexec_fn=_die_with_parent)
        stopping.wait(0.5)
    for child in children:
        if child is not None and child.poll() is None:
            child.terminate()
    for child in children:
        if child is not None:
            try:
                child.wait(60)
            except subprocess.TimeoutExpired:
                child.kill()
    return 0


def _die_with_parent() -> None:
    """In the child: a SIGKILL of the supervisor kills the workers too (their runs are then
    lost workers' runs, ended within seconds), instead of orphans nobody watches."""
    libc = ctypes.CDLL("libc.so.6", use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL)


def add_command(commands) -> None:
    worker = commands.add_parser(
        "worker", help="run a cluster's runs on this machine (jobs from Redis)"
    )
    worker.add_argument("--redis-url", default=None, help="redis://host:6379/0, the run queue")
    worker.add_argument("--database-url", default=None, help="postgresql://..., the lab's store")
    worker.add_argument(
        "--data", default=None, help="the lab's shared data folder (same path on every machine)"
    )
    worker.add_argument(
        "--processes", type=int, default=None, help="worker processes (default: one per core)"
    )
    worker.add_argument(
        "--runs-per-process", type=int, default=None, help="runs each process takes at once"
    )
    worker.add_argument(
        "--unsafe-no-sandbox",
        action="store_true",
        help="DANGER: run student code without bubblewrap (trusted code on a laptop only)",
    )
    worker.add_argument(
        "--rosserial-port",
        type=int,
        default=None,
        help="make this the bench worker: real CrowBots connect to this TCP port (11411; 0 = "
        "any free port) and their runs run here (one process)",
    )
    worker.add_argument(
        "--rosserial-host",
        default=None,
        help="address the bench's rosserial port listens on (default 0.0.0.0; best: the robots' "
        "VLAN/SSID interface)",
    )
    worker.add_argument("--one-process", action="store_true", help=argparse.SUPPRESS)
    worker.set_defaults(func=cmd_worker)
