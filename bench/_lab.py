"""A whole lab on this machine for a benchmark, in one of two shapes, started and torn down:

* ``single``: one `robodojo serve`, with its default of one worker process per core (no Redis),
  or `--workers N` (0: every run in the web process, the baseline);
* ``cluster``: a private redis-server on a free port, a fresh PostgreSQL database on the
  machine's server (created here, dropped at the end), two `robodojo serve --redis-url
  --database-url` web processes and two `robodojo worker` processes, all on loopback and one
  data folder (the shared data volume of docs/deploy.md, here a folder on one disk).

    with open_lab("cluster", data_dir, env) as lab:          # or ("single", ..., serve_workers=0)
        lab.webs[0].url, lab.admin_token, lab.worker_processes()
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import psutil
from _common import BenchError, LabProcess, free_port, spawn, stop, wait_until_up

MODES = ("single", "cluster")
POSTGRES_URL = "postgresql://postgres@127.0.0.1:5432"  # the machine's server, trust auth
CLUSTER_WEBS = 2  # web processes behind "one address" (students spread over them)
CLUSTER_WORKERS = 2  # `robodojo worker` processes, one per core of this machine
REDIS_START_TIMEOUT_S = 10.0  # [s] redis-server answering PING
FORKSERVER = "multiprocessing.forkserver"  # in the command line of a forkserver and its children
WORKER_START_S = 3.0  # [s] a worker's start before it takes jobs (it needs no address to poll)
# A lab that has just started still warms up for tens of seconds (the editor's analysis workers
# load jedi's view of rospy, rclpy and numpy: ~7 s of CPU each, one after the other); measuring
# runs over that measures the start-up. Wait until the lab's processes use less than this...
SETTLED_CORES = 0.1  # [cores] over one SETTLE_WINDOW_S
SETTLE_WINDOW_S = 1.0  # [s]
SETTLED_WINDOWS = 5  # quiet windows in a row
SETTLE_TIMEOUT_S = 120.0  # [s] ... or this long, then say so and go on


@dataclass
class Lab:
    mode: str
    serve_workers: int | None  # single: `serve --workers`; None: its default (one per core)
    webs: list[LabProcess]
    workers: list[LabProcess] = field(default_factory=list)  # cluster: `robodojo worker`s
    services: list[LabProcess] = field(default_factory=list)  # redis-server
    database: str | None = None  # cluster: the PostgreSQL database made for this lab

    @property
    def admin_token(self) -> str:
        return self.webs[0].admin_token

    def web_processes(self) -> list[psutil.Process]:
        return [psutil.Process(web.pid) for web in self.webs]

    def worker_processes(self) -> list[psutil.Process]:
        """The processes that hold runs, without their sandboxes: the cluster's workers and the
        processes they start, the per-core workers below the single web process, none when the
        web process holds the runs itself."""
        if self.workers:
            roots = [psutil.Process(worker.pid) for worker in self.workers]
            return roots + [p for root in roots for p in _lab_descendants(root)]
        return [p for web in self.web_processes() for p in _lab_descendants(web)]

    def service_counters(self) -> dict[str, float]:
        """Cumulative counters of the cluster's Redis and PostgreSQL (empty for a single lab):
        compared before and after a window, the load a class puts on them."""
        counters: dict[str, float] = {}
        for service in self.services:
            counters |= redis_counters(service)
        if self.database is not None:
            counters |= postgres_counters(self.database)
        return counters

    def describe(self) -> str:
        if self.mode == "single" and self.serve_workers == 0:
            return "single, --workers 0: every run in the one web process"
        workers = len(self.worker_processes())
        return f"{self.mode}: {len(self.webs)} web process(es), {workers} worker processes"


def _lab_descendants(process: psutil.Process) -> list[psutil.Process]:
    """The processes below `process` that hold runs: forked from a multiprocessing forkserver
    (the per-core workers, a cluster worker's processes). Not the forkserver itself, nor its
    resource tracker, the editor's analysis workers or a sandbox (bwrap, or unsandboxed
    `python -I -S -c`) and what runs in it."""
    found = []
    with contextlib.suppress(psutil.Error):
        parent_is_forkserver = FORKSERVER in " ".join(process.cmdline())
        for child in process.children():
            with contextlib.suppress(psutil.Error):
                command = child.cmdline()
                if not child.name().startswith("python") or "-I" in command[:3]:
                    continue  # a sandbox: its subtree holds no worker
                text = " ".join(command)
                if FORKSERVER in text and parent_is_forkserver:
                    found.append(child)
                found.extend(_lab_descendants(child))
    return found


def start_web(
    name: str, data: Path, env: dict[str, str], extra: list[str], login: bool = True
) -> LabProcess:
    port = free_port()
    command = [sys.executable, "-m", "server.cli", "serve", "--port", str(port)]
    command += ["--data", str(data), *extra]
    web = spawn(name, command, env, f"http://127.0.0.1:{port}")
    try:
        wait_until_up(web, login=login)
    except BaseException:  # Ctrl-C included: never leave a process behind
        stop(web)
        raise
    return web


def serve_knows(option: str) -> bool:
    """Whether this checkout's `robodojo serve` has `option` (before issue 16 landed, the one
    server ran every run itself and had no --workers)."""
    help_text = subprocess.run(
        [sys.executable, "-m", "server.cli", "serve", "--help"],
        capture_output=True,
        text=True,
        cwd=Path(__file__).resolve().parents[1],
    ).stdout
    return option in help_text


@contextlib.contextmanager
def open_lab(
    mode: str,
    data: Path,
    env: dict[str, str],
    serve_workers: int | None = None,
    worker_args: list[str] | None = None,
) -> Iterator[Lab]:
    """The lab in `mode`, stopped (and its database dropped) however the block ends."""
    if mode not in MODES:
        raise BenchError(f"no lab mode {mode!r}: one of {', '.join(MODES)}")
    started: list[LabProcess] = []
    database = None
    try:
        if mode == "single":
            extra = []
            if serve_workers is not None and serve_knows("--workers"):
                extra = ["--workers", str(serve_workers)]
            elif serve_workers:  # 0 is what a serve without --workers does: runs in-process
                raise BenchError("this checkout's `robodojo serve` has no --workers option")
            web = start_web("the web process", data, env, extra)
            started.append(web)
            lab = Lab(mode, serve_workers, [web])
            settle(lab)
            yield lab
            return
        redis = start_redis()
        started.append(redis)
        database = create_database()
        urls = ["--redis-url", redis.url, "--database-url", f"{POSTGRES_URL}/{database}"]
        # Web 1 first: it makes the fresh database's tables (processes starting together on an
        # empty database race to create them) and the instructor.
        webs = [start_web("web process 1", data, env, urls)]
        started.extend(webs)
        workers = []
        for index in range(CLUSTER_WORKERS):
            command = [sys.executable, "-m", "server.cli", "worker", *urls, "--data", str(data)]
            command += ["--processes", "1"]  # two workers of one process: one per core here
            worker = spawn(f"worker {index + 1}", [*command, *(worker_args or [])], env)
            started.append(worker)
            workers.append(worker)
        for index in range(1, CLUSTER_WEBS):
            web = start_web(f"web process {index + 1}", data, env, urls, login=False)
            started.append(web)
            webs.append(web)
        time.sleep(WORKER_START_S)
        for worker in workers:
            if worker.process.poll() is not None:
                raise BenchError(f"{worker.name} exited at start:\n{worker.tail()}")
        lab = Lab(mode, None, webs, workers, [redis], database)
        settle(lab)
        yield lab
    finally:
        for lab_process in reversed(started):  # webs first, so runs stop before the workers
            stop(lab_process)
        if database is not None:
            drop_database(database)


def settle(lab: Lab) -> None:
    """Wait until the lab's own start-up work is over (see SETTLED_CORES); print how long.

    The editor's pool starts its pieces one after another (stubs, then each analysis worker,
    each warming up for seconds), so a process that started within a window counts with all
    its CPU, and the lab is settled only after SETTLED_WINDOWS quiet windows in a row: one
    window between two pieces read as settled, and the next worker's warm-up landed in the
    measured passes (a's "CPU per run" 8% instead of 3.4%)."""
    started = time.monotonic()
    roots = [*lab.web_processes(), *(psutil.Process(w.pid) for w in lab.workers)]
    quiet = 0
    while time.monotonic() - started < SETTLE_TIMEOUT_S:
        before = tree_cpu_s(roots)
        time.sleep(SETTLE_WINDOW_S)
        after = tree_cpu_s(roots)
        used_s = sum(after[pid] - before.get(pid, 0.0) for pid in after)
        quiet = quiet + 1 if used_s / SETTLE_WINDOW_S < SETTLED_CORES else 0
        if quiet >= SETTLED_WINDOWS:
            print(f"  the lab settled {time.monotonic() - started:.0f} s after it answered")
            return
    busy = used_s / SETTLE_WINDOW_S
    print(f"  the lab still used {busy:.2f} cores after {SETTLE_TIMEOUT_S:.0f} s; measuring anyway")


def start_redis() -> LabProcess:
    if shutil.which("redis-server") is None:
        raise BenchError("the cluster mode needs redis-server on this machine (apt redis-server)")
    port = free_port()
    command = ["redis-server", "--port", str(port), "--bind", "127.0.0.1", "--save", ""]
    command += ["--appendonly", "no"]
    redis = spawn("redis-server", command, {}, f"redis://127.0.0.1:{port}/0")
    deadline = time.monotonic() + REDIS_START_TIMEOUT_S
    while time.monotonic() < deadline:
        with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), 1) as s:
            s.sendall(b"PING\r\n")
            if s.recv(16).startswith(b"+PONG"):
                return redis
        time.sleep(0.1)
    stop(redis)
    raise BenchError(f"redis-server did not answer in {REDIS_START_TIMEOUT_S:g} s:\n{redis.tail()}")


def create_database() -> str:
    import psycopg

    name = f"robodojo_bench_{os.getpid()}_{secrets.token_hex(3)}"
    try:
        with psycopg.connect(f"{POSTGRES_URL}/postgres", autocommit=True) as connection:
            connection.execute(f'CREATE DATABASE "{name}"')
    except psycopg.Error as error:
        raise BenchError(
            f"the cluster mode needs PostgreSQL at {POSTGRES_URL} (trust auth): {error}"
        ) from None
    return name


def drop_database(name: str) -> None:
    import psycopg

    try:
        with psycopg.connect(f"{POSTGRES_URL}/postgres", autocommit=True) as connection:
            connection.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
    except psycopg.Error as error:
        print(f"bench: could not drop the database {name}: {error}", file=sys.stderr)


def pss_mib(processes: list[psutil.Process]) -> float:
    """Proportional set size [MiB] of these processes and everything below them (sandboxes
    included; shared libraries split fairly, so a sum over many processes is honest)."""
    seen: set[int] = set()
    total_kib = 0
    pending = [process.pid for process in processes]
    while pending:
        pid = pending.pop()
        if pid in seen:
            continue
        seen.add(pid)
        try:
            with open(f"/proc/{pid}/smaps_rollup") as f:
                total_kib += sum(int(line.split()[1]) for line in f if line.startswith("Pss:"))
            pending.extend(child.pid for child in psutil.Process(pid).children())
        except (OSError, psutil.Error):
            continue
    return total_kib / 1024


def redis_counters(redis: LabProcess) -> dict[str, float]:
    """Commands, bytes in and out, and CPU seconds of the redis-server so far."""
    port = int(redis.url.rsplit(":", 1)[1].split("/")[0])
    text = b""
    with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), 2) as sock:
        sock.sendall(b"INFO stats\r\n")
        reply = b""
        while b"\r\n" not in reply or len(reply) < _bulk_length(reply):
            chunk = sock.recv(65536)
            if not chunk:
                break
            reply += chunk
        text = reply.split(b"\r\n", 1)[-1]
    fields = dict(
        line.split(":", 1) for line in text.decode(errors="replace").splitlines() if ":" in line
    )
    counters = {}
    for name in ("total_commands_processed", "total_net_input_bytes", "total_net_output_bytes"):
        if name in fields:
            counters[f"redis {name}"] = float(fields[name])
    with contextlib.suppress(psutil.Error):
        cpu = psutil.Process(redis.pid).cpu_times()
        counters["redis cpu_s"] = cpu.user + cpu.system
    return counters


def postgres_counters(database: str) -> dict[str, float]:
    """Transactions and rows written in the lab's database so far (pg_stat_database)."""
    import psycopg

    query = (
        "SELECT xact_commit, tup_inserted, tup_updated, tup_deleted FROM pg_stat_database "
        "WHERE datname = %s"
    )
    try:
        with psycopg.connect(f"{POSTGRES_URL}/postgres", autocommit=True) as connection:
            found = connection.execute(query, (database,)).fetchone()
    except psycopg.Error:
        return {}
    if found is None:
        return {}
    names = ("transactions", "rows_inserted", "rows_updated", "rows_deleted")
    return {f"postgres {name}": float(value) for name, value in zip(names, found, strict=True)}


def _bulk_length(reply: bytes) -> int:
    """Bytes of a whole RESP bulk string reply ($<n>\\r\\n<n bytes>\\r\\n) once its header is in."""
    header, _, _ = reply.partition(b"\r\n")
    return len(header) + 2 + int(header[1:] or 0) + 2


def tree_cpu_s(processes: list[psutil.Process]) -> dict[int, float]:
    """CPU seconds (user + system) so far of these processes and everything below them,
    by pid: two readings around a window give the cores a class used (processes that started
    or ended within it are left out, which the steady window makes rare)."""
    seconds: dict[int, float] = {}
    pending = list(processes)
    while pending:
        process = pending.pop()
        with contextlib.suppress(psutil.Error):
            times = process.cpu_times()
            seconds[process.pid] = times.user + times.system
            pending.extend(process.children())
    return seconds
