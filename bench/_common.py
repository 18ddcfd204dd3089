"""What the service benchmarks share (bench_api.py, bench_cluster.py): lab processes started on
free loopback ports and stopped, the instructor's login read off their output, an open-loop
status poll, memory samples, and the figures (percentiles, least-squares slopes) they print.

Import it first (`from _common import ...`: a script's own folder is on sys.path): it puts
this checkout ahead of the installed package, so a benchmark measures the code beside it.
"""

from __future__ import annotations

import asyncio
import collections
import itertools
import math
import os
import re
import signal
import socket
import statistics
import subprocess
import sys
import threading
import time
from array import array
from dataclasses import dataclass, field
from pathlib import Path

import httpx
import psutil

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

LOGIN_LINE = re.compile(r"log in as the instructor at \S+/login\?token=(\S+)")
START_TIMEOUT_S = 180.0  # [s] a cold web process on a loaded 2-core machine, traced (--tracemalloc)
STOP_TIMEOUT_S = 30.0  # [s] SIGTERM, then SIGKILL: a lab process stops its runs first
HTTP_TIMEOUT_S = 10.0  # [s] a status answer slower than this counts as an error
MAX_HTTP_IN_FLIGHT = 64  # open-loop requests pending at once; more are counted as skipped
OUTPUT_LINES_KEPT = 60  # a process's last lines, shown when it fails
LOOP_TICK_S = 0.1  # [s] period of the client event-loop lag probe
MIB = 2**20


class BenchError(RuntimeError):
    """The benchmark cannot go on; the message says why."""


# ------------------------------------------------------------------------------ processes
@dataclass
class LabProcess:
    """A process this benchmark started (a web process, a worker, Redis), with its last lines
    of output and, for a web process, its address and the instructor's login token."""

    name: str
    process: subprocess.Popen
    url: str = ""
    admin_token: str = ""
    output: collections.deque = field(
        default_factory=lambda: collections.deque(maxlen=OUTPUT_LINES_KEPT)
    )

    def tail(self) -> str:
        return "\n".join(self.output)

    @property
    def pid(self) -> int:
        return self.process.pid


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def spawn(name: str, command: list[str], env_extra: dict[str, str], url: str = "") -> LabProcess:
    """Start `command` from this checkout with its output read in the background."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1", "PYTHONPATH": str(ROOT), **env_extra}
    # A session of its own, as under systemd or in a container: with the kernel's autogroup
    # scheduler a session shares the CPU as one, so a lab in the client's session would be
    # weighed together with the simulated students.
    process = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
        cwd=ROOT,
        start_new_session=True,
    )
    lab_process = LabProcess(name, process, url)

    def pump() -> None:
        assert process.stdout is not None
        try:
            for line in process.stdout:
                lab_process.output.append(line.rstrip("\n"))
                match = LOGIN_LINE.search(line)
                if match:
                    lab_process.admin_token = match.group(1)
        except (ValueError, OSError):  # closed by stop()
            return

    threading.Thread(target=pump, daemon=True).start()
    return lab_process


def wait_until_up(web: LabProcess, timeout_s: float = START_TIMEOUT_S, login: bool = True) -> None:
    """Until the web process answers /api/health and (`login`) has printed its login line:
    only the first web process on a database prints one, when it makes the instructor."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if web.process.poll() is not None:
            raise BenchError(f"{web.name} exited at start:\n{web.tail()}")
        try:
            if httpx.get(f"{web.url}/api/health", timeout=1.0).status_code == 200:
                break
        except httpx.TransportError:
            pass
        time.sleep(0.1)
    else:
        raise BenchError(f"{web.name} did not answer in {timeout_s:g} s:\n{web.tail()}")
    time.sleep(0.2)  # the login line is printed before uvicorn answers; let the pump read it
    if login and not web.admin_token:
        raise BenchError(f"{web.name} printed no instructor login URL:\n{web.tail()}")


def stop(lab_process: LabProcess, timeout_s: float = STOP_TIMEOUT_S) -> None:
    """SIGTERM (a web process stops its runs, then the sandboxes), SIGKILL if that hangs."""
    process = lab_process.process
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout_s)
        except subprocess.TimeoutExpired:
            print(f"bench: {lab_process.name} did not stop in {timeout_s:g} s; killing it")
            process.kill()
            process.wait()
    if process.stdout is not None:
        process.stdout.close()


def stop_on_sigterm() -> None:
    """SIGTERM ends a benchmark as Ctrl-C does: through the finally that stops its processes."""

    def interrupt(signum: int, frame) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, interrupt)


# ------------------------------------------------------------------------------ measuring
def bearer(token: str) -> dict[str, str]:
    return {"Authorization": f"Bearer {token}"}


@dataclass
class Window:
    """The measurement interval [start, end) in time.monotonic() seconds; inf until known."""

    start: float = math.inf
    end: float = math.inf

    def __contains__(self, moment: float) -> bool:
        return self.start <= moment < self.end


@dataclass
class HttpStats:
    latencies_s: array = field(default_factory=lambda: array("d"))
    errors: collections.Counter = field(default_factory=collections.Counter)
    skipped: int = 0  # not sent: MAX_HTTP_IN_FLIGHT requests were already waiting


async def poll_status(
    targets: list[tuple[httpx.AsyncClient, str, str]],
    rate_hz: float,
    window: Window,
    stats: HttpStats,
) -> None:
    """GET /api/runs/{id} round robin over (client, run id, token) at a fixed schedule (open
    loop: a slow answer does not delay the next request) until the window ends; then waits
    for the requests still out, so slow answers are counted."""

    async def one(client: httpx.AsyncClient, run_id: str, token: str) -> None:
        sent = time.monotonic()
        try:
            answer = await client.get(f"/api/runs/{run_id}", headers=bearer(token))
            outcome = answer.status_code
        except httpx.HTTPError as error:
            outcome = type(error).__name__
        if sent in window:
            if outcome == 200:
                stats.latencies_s.append(time.monotonic() - sent)
            else:
                stats.errors[outcome] += 1

    pending: set[asyncio.Task] = set()
    next_at = time.monotonic()
    try:
        for k in itertools.count():
            next_at += 1.0 / rate_hz
            await asyncio.sleep(max(0.0, next_at - time.monotonic()))
            if next_at >= window.end:
                break
            if len(pending) >= MAX_HTTP_IN_FLIGHT:
                if next_at in window:
                    stats.skipped += 1
                continue
            task = asyncio.create_task(one(*targets[k % len(targets)]))
            pending.add(task)
            task.add_done_callback(pending.discard)
        if pending:
            await asyncio.wait(pending, timeout=HTTP_TIMEOUT_S + 1.0)
    finally:
        for task in pending:
            task.cancel()


async def loop_lag(into: array, window: Window) -> None:
    """How late this client's own event loop wakes: its share of every latency measured."""
    while True:
        due = time.monotonic() + LOOP_TICK_S
        await asyncio.sleep(LOOP_TICK_S)
        now = time.monotonic()
        if now in window:
            into.append(now - due)


@dataclass
class MemorySample:
    at_s: float  # [s] time.monotonic()
    server_rss: int  # [B] the process itself
    sandboxes_rss: int  # [B] every process below it


def sample_memory(process: psutil.Process) -> MemorySample:
    children = 0
    for child in process.children(recursive=True):
        try:
            children += child.memory_info().rss
        except psutil.Error:
            continue
    return MemorySample(time.monotonic(), process.memory_info().rss, children)


async def sample_memory_every(
    process: psutil.Process, every_s: float, into: list[MemorySample], window: Window
) -> None:
    while True:
        sample = sample_memory(process)
        if sample.at_s in window:
            into.append(sample)
        await asyncio.sleep(every_s)


# ------------------------------------------------------------------------------ the machine
# One pass of the reference workload: pure-Python integer additions, what the lab's scheduler
# and nodes mostly do. The lab machines of one kind differ by up to 2x in it (a loop of 10 M
# additions took 0.4-1.06 s on them, on a quiet machine), and every latency figure with it.
SPEED_LOOP_ADDITIONS = 2_000_000
SPEED_REPEATS = 7


def machine_speed_ms() -> float:
    """[ms] median time of the reference workload on one core (lower is faster). Printed
    beside a benchmark's figures, so passes on different machines can be compared."""
    times = []
    for _ in range(SPEED_REPEATS):
        started = time.perf_counter()
        total = 0
        for number in range(SPEED_LOOP_ADDITIONS):
            total += number
        times.append(time.perf_counter() - started)
    return statistics.median(times) * 1e3


PING_ROUND_TRIPS = 2000


def pipe_round_trip_us() -> float:
    """[us] median round trip of one byte between this process and a forked child over two
    pipes: the system calls and wake-ups every node step and realtime wake pays, which the
    reference loop does not exercise (two machines of one kind with the same loop time spent
    3.4-3.7% and 5.7-7.0% of a core per 100 Hz run)."""
    to_child_r, to_child_w = os.pipe()
    to_parent_r, to_parent_w = os.pipe()
    child = os.fork()
    if child == 0:  # echo until the parent closes its end
        try:
            os.close(to_child_w)
            os.close(to_parent_r)
            while os.read(to_child_r, 1):
                os.write(to_parent_w, b"!")
        finally:
            os._exit(0)
    os.close(to_child_r)
    os.close(to_parent_w)
    times = []
    for _ in range(PING_ROUND_TRIPS):
        started = time.perf_counter()
        os.write(to_child_w, b"?")
        os.read(to_parent_r, 1)
        times.append(time.perf_counter() - started)
    os.close(to_child_w)
    os.close(to_parent_r)
    os.waitpid(child, 0)
    return statistics.median(times) * 1e6


def machine_shares(before) -> tuple[float, float]:
    """(% of the machine busy, % of it the host took back: steal) since `before`, an earlier
    psutil.cpu_times()."""
    after = psutil.cpu_times()
    idle = (after.idle + after.iowait) - (before.idle + before.iowait)
    total = sum(after) - sum(before)
    if total <= 0:
        return math.nan, math.nan
    steal = getattr(after, "steal", 0.0) - getattr(before, "steal", 0.0)
    return 100.0 * (1.0 - idle / total), 100.0 * steal / total


def describe_machine() -> str:
    """A line naming how fast this machine is now and how much of it the host takes back."""
    before = psutil.cpu_times()
    speed_ms = machine_speed_ms()
    ping_us = pipe_round_trip_us()
    _, steal_percent = machine_shares(before)
    return (
        f"machine: {psutil.cpu_count()} cores; reference loop ({SPEED_LOOP_ADDITIONS:,} "
        f"additions) {speed_ms:.0f} ms median, pipe round trip {ping_us:.1f} us median, steal "
        f"{steal_percent:.1f}% meanwhile"
    )


# ------------------------------------------------------------------------------ figures
def percentile(values, q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def p99_ms(seconds) -> float:
    return percentile(seconds, 0.99) * 1e3 if len(seconds) else math.nan


def row(label: str, seconds, note: str = "", width: int = 58) -> None:
    """One line: label, p50, p99, max [ms] and the count, from durations in seconds."""
    if not len(seconds):
        print(f"{label:<{width}} {'n/a':>8}   {note}")
        return
    ordered = sorted(seconds)
    p50, p99 = percentile(ordered, 0.5) * 1e3, percentile(ordered, 0.99) * 1e3
    figures = f"{p50:8.1f} {p99:8.1f} {ordered[-1] * 1e3:8.1f} {len(ordered):9d}"
    print(f"{label:<{width}} {figures}   {note}")


def slope(minutes: list[float], mib: list[float]) -> float:
    """Least-squares growth [MiB/min]; nan with fewer than two samples."""
    if len(minutes) < 2:
        return math.nan
    return statistics.linear_regression(minutes, mib).slope
