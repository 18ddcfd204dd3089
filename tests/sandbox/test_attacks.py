"""Student code that attacks the sandbox (codejail's TestMalware, for our walls).

Every attack must be contained with an error a person can read, leave the test process (the
stand-in for the server) unharmed, and leave a node running beside it on time."""

from __future__ import annotations

import contextlib
import dataclasses
import os
import socket
import statistics
import threading
import time

import pytest

from sandbox import cgroups
from sandbox.limits import DEFAULT_LIMITS
from sandbox.protocol import Exited, Outcome, Yield
from tests.sandbox.conftest import crowbot_info, run_script


@pytest.fixture(scope="module")
def launcher(warm_and_cold_launcher):
    """Every attack runs twice: in a node from the warm pool and in one started cold."""
    return warm_and_cold_launcher


def finish(launcher, code: str, name: str = "attack") -> Exited:
    reply, node = run_script(launcher, code, name)
    try:
        if isinstance(reply, Yield):  # it slept: it survived the attack; end it
            reply = node.shutdown("test over")
        assert isinstance(reply, Exited)
        return reply
    finally:
        node.close()


def error_text(exited: Exited) -> str:
    assert exited.error is not None, exited
    return f"{exited.error.type}: {exited.error.message}"


class Bystander:
    """A well-behaved node stepping at full speed in a thread while an attack runs."""

    def __init__(self, launcher) -> None:
        self.node = launcher.start("bystander")
        reply = self.node.load(
            "def step(obs):\n    return (0.1, 0.0)\n", "bystander.py", "step", crowbot_info()
        )
        assert isinstance(reply, Yield), reply
        self.round_trips: list[float] = []
        self.replies: list[object] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run)

    def _run(self) -> None:
        t = 0.0
        while not self._stop.is_set():
            t += 0.1
            start = time.perf_counter()
            self.replies.append(self.node.wake(t, []))
            self.round_trips.append(time.perf_counter() - start)

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self.node.close()
        assert all(isinstance(r, Yield) for r in self.replies), "the bystander node was hurt"
        assert len(self.round_trips) > 50
        # Generous: the machine is shared; the point is "still steps", not a benchmark.
        assert statistics.median(self.round_trips) < 0.005


def test_fork_bomb_is_refused(launcher):
    with Bystander(launcher):
        exited = finish(launcher, "import os\nwhile True:\n    os.fork()\n")
    assert exited.outcome is Outcome.ERROR
    assert "PermissionError" in error_text(exited)
    assert exited.error.line == 3


@pytest.mark.slow
def test_memory_bomb_hits_the_address_space_cap(launcher):
    with Bystander(launcher):
        exited = finish(launcher, "hog = []\nwhile True:\n    hog.append(bytearray(50_000_000))\n")
    assert exited.outcome in (Outcome.ERROR, Outcome.CRASHED)
    if exited.outcome is Outcome.ERROR:
        assert exited.error.type == "MemoryError"


@pytest.mark.slow
def test_busy_loop_is_killed_at_its_step_budget(launcher):
    with Bystander(launcher):
        started = time.monotonic()
        exited = finish(launcher, "while True:\n    pass\n", "spinner")
    assert exited.outcome is Outcome.KILLED
    assert exited.reason == "node spinner exceeded its 4 s first step budget at t=0.000 s"
    assert time.monotonic() - started < 10


def test_busy_loop_inside_a_step_is_killed_with_the_time(launcher):
    reply, node = run_script(
        launcher, "def step(obs):\n    if obs.time > 0.25:\n        while True:\n            pass\n"
    )
    try:
        assert isinstance(reply, Yield)
        replies = [node.wake(0.1 * k, []) for k in range(1, 4)]
        assert isinstance(replies[-1], Exited)
        assert replies[-1].reason == "node attack exceeded its 1 s step budget at t=0.300 s"
    finally:
        node.close()


@pytest.mark.slow
def test_sigterm_ignoring_node_is_still_killed(launcher):
    code = "import signal\nsignal.signal(signal.SIGTERM, signal.SIG_IGN)\nwhile True:\n    pass\n"
    exited = finish(launcher, code)
    assert exited.outcome is Outcome.KILLED


def test_deep_recursion_is_contained(launcher):
    exited = finish(launcher, "def dive(n):\n    return dive(n + 1)\n\ndive(0)\n")
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "RecursionError"
    assert exited.error.line == 2


@contextlib.contextmanager
def patient(launcher):
    """A launcher like `launcher` with the lab's own first-step budget (10 s), not the tests'
    short one, for an attack whose containment is under test, not its speed: on a loaded
    machine a node filling its memory cap takes seconds of wall time to get there (seen: a
    recursion 10**7 deep killed by the 4 s budget before it crashed)."""
    limits = dataclasses.replace(
        launcher.limits, first_step_budget_s=DEFAULT_LIMITS.first_step_budget_s
    )
    made = type(launcher)(limits=limits, pool_size=launcher.pool_size)
    try:
        yield made
    finally:
        made.close()


def test_c_stack_overflow_crashes_only_the_node(launcher):
    code = (
        "import sys\nsys.setrecursionlimit(10**7)\ndef dive(n):\n    return dive(n + 1)\ndive(0)\n"
    )
    with patient(launcher) as lab_budget, Bystander(lab_budget):
        exited = finish(lab_budget, code)
    assert exited.outcome in (Outcome.CRASHED, Outcome.ERROR), exited


def test_print_flood_is_truncated_with_a_note(launcher):
    reply, node = run_script(launcher, "for i in range(60_000):\n    print('x' * 100, i)\n")
    try:
        assert isinstance(reply, Exited) and reply.outcome is Outcome.FINISHED, reply
        lines = node.logs.take()
    finally:
        node.close()
    assert node.logs.kept_bytes <= 1024 * 1024
    assert lines[-1].startswith("[log truncated:")
    assert 5_000 < len(lines) < 20_000


def test_huge_file_is_stopped_at_the_file_size_cap(launcher):
    exited = finish(launcher, "with open('big.bin', 'wb') as f:\n    f.write(b'x' * 40_000_000)\n")
    assert exited.outcome is Outcome.ERROR
    assert "File too large" in error_text(exited) or "No space" in error_text(exited)


def test_many_files_fill_only_the_scratch_tmpfs(launcher):
    code = (
        "for i in range(100):\n"
        "    with open(f'part{i}.bin', 'wb') as f:\n"
        "        f.write(b'x' * 8_000_000)\n"
    )
    exited = finish(launcher, code)
    assert exited.outcome is Outcome.ERROR
    assert "No space left on device" in error_text(exited)


@pytest.mark.parametrize("path", ["/etc/shadow", "/etc/passwd", "/root/.bashrc"])
def test_host_files_do_not_exist_inside(launcher, path):
    exited = finish(launcher, f"open({path!r}).read()\n")
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type in ("FileNotFoundError", "PermissionError")


def test_server_data_and_source_are_invisible(launcher, tmp_path):
    database = tmp_path / "robodojo.sqlite"
    database.write_bytes(b"SQLite format 3\x00 secret grades")
    source = os.path.abspath("server/sim/simulation.py")
    for path in (str(database), source):
        exited = finish(launcher, f"print(open({path!r}, 'rb').read())\n")
        assert exited.outcome is Outcome.ERROR
        assert exited.error.type == "FileNotFoundError"


def test_another_nodes_scratch_directory_is_private(launcher):
    keeper = (
        "open('secret.txt', 'w').write('42')\nimport rospy\nrospy.init_node('w')\nrospy.spin()\n"
    )
    writer, writer_node = run_script(launcher, keeper, "writer")
    try:
        assert isinstance(writer, Yield)  # spinning, its scratch directory alive
        code = "import os\nprint(sorted(os.listdir('.')))\nopen('secret.txt').read()\n"
        exited = finish(launcher, code, "reader")
        assert exited.outcome is Outcome.ERROR and exited.error.type == "FileNotFoundError"
        # Nor through another process's root: the reader sees no other node's pids.
        probe = "import os\npids = sorted(p for p in os.listdir('/proc') if p.isdigit())\n"
        probe += "assert pids == ['1', '2'], pids\n"  # bwrap's init and this node: no one else
        exited = finish(launcher, probe, "prober")
        assert exited.outcome is Outcome.FINISHED, exited
    finally:
        writer_node.close()


@pytest.mark.parametrize(
    "path", ["/usr/evil.py", "/opt/robodojo/sandbox/host.py", "/etc/evil", "/evil"]
)
def test_writing_outside_scratch_fails(launcher, path):
    exited = finish(launcher, f"open({path!r}, 'w').write('pwned')\n")
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type in ("OSError", "PermissionError", "FileNotFoundError")
    assert not os.path.exists(path) or path.startswith("/opt/robodojo")


def test_no_network_not_even_loopback(launcher):
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    server.settimeout(0.2)
    port = server.getsockname()[1]
    try:
        code = f"import socket\nsocket.create_connection(('127.0.0.1', {port}), timeout=1)\n"
        exited = finish(launcher, code)
        assert exited.outcome is Outcome.ERROR
        assert exited.error.type == "PermissionError"
        with pytest.raises(TimeoutError):
            server.accept()  # nothing ever arrived
    finally:
        server.close()


def test_killing_the_parent_is_impossible(launcher):
    with Bystander(launcher):
        exited = finish(
            launcher, "import os, signal\nos.kill(os.getppid(), signal.SIGKILL)\nos.kill(1, 9)\n"
        )
    # Inside its pid namespace the parent is bwrap's init, which ignores the signal: the node
    # ends normally, and the Bystander above proved the server side kept stepping.
    assert exited.outcome is Outcome.FINISHED, exited


def test_ctypes_raw_syscalls_are_filtered(launcher):
    code = (
        "import ctypes\n"
        "libc = ctypes.CDLL(None, use_errno=True)\n"
        "assert libc.syscall(57) == -1, 'raw fork succeeded'\n"  # fork
        "assert libc.syscall(41, 2, 1, 0) == -1, 'raw socket succeeded'\n"  # socket
        "assert libc.syscall(101, 0, 0, 0, 0) == -1, 'ptrace succeeded'\n"  # ptrace
        "print('all refused')\n"
    )
    reply, node = run_script(launcher, code)
    try:
        assert isinstance(reply, Exited) and reply.outcome is Outcome.FINISHED, reply
        assert "all refused" in node.logs.take()
    finally:
        node.close()


def test_ctypes_segfault_crashes_only_the_node(launcher):
    with Bystander(launcher):
        exited = finish(launcher, "import ctypes\nctypes.string_at(0)\n")
    assert exited.outcome is Outcome.CRASHED
    assert "signal 11" in exited.reason


@pytest.mark.parametrize(
    "code",
    [
        "import subprocess\nsubprocess.run(['ls', '/'])\n",
        "import os\nos.execv('/usr/bin/ls', ['ls'])\n",
        "import multiprocessing\nmultiprocessing.Process(target=print).start()\n",
    ],
)
def test_no_new_processes_or_programs(launcher, code):
    exited = finish(launcher, code)
    assert exited.outcome is Outcome.ERROR
    assert "Operation not permitted" in error_text(exited)


def test_os_system_runs_nothing(launcher):
    _, node = run_script(launcher, "import os\nprint('status', os.system('echo pwned'))\n")
    try:
        lines = node.logs.take()
    finally:
        node.close()
    assert "pwned" not in lines
    assert any(line.startswith("status") and line != "status 0" for line in lines)


def test_importing_the_server_fails(launcher):
    exited = finish(launcher, "import server.sim\n")
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "ModuleNotFoundError"


def test_identity_inside_is_nobody_without_capabilities(launcher):
    code = (
        "import os\n"
        "status = open('/proc/self/status').read()\n"
        "assert os.getuid() == 65534 and os.getgid() == 65534, (os.getuid(), os.getgid())\n"
        "assert 'CapEff:\\t0000000000000000' in status\n"
        "assert 'NoNewPrivs:\\t1' in status\n"
        "assert 'Seccomp:\\t2' in status\n"
        "assert os.environ.get('PATH') is None or 'robodojo' not in os.environ['PATH']\n"
    )
    exited = finish(launcher, code)
    assert exited.outcome is Outcome.FINISHED, exited


@pytest.mark.parametrize(
    ("code", "error_type", "line"),
    [
        ("x = 1\nif x = 2:\n    pass\n", "SyntaxError", 2),
        ("import math\nimport robot_magic\n", "ModuleNotFoundError", 2),
    ],
)
def test_broken_code_comes_back_readable(launcher, code, error_type, line):
    exited = finish(launcher, code)
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == error_type
    assert exited.error.line == line
    assert "attack.py" in exited.error.traceback
    assert "/opt/robodojo" not in exited.error.traceback


def test_a_node_runs_below_the_lab_s_priority_and_cannot_raise_it(launcher):
    # The realtime scheduler and the web process come first on a busy machine (limits.nice);
    # a student cannot take that back.
    code = (
        "import os\n"
        "nice = int(open('/proc/self/stat').read().rsplit(')', 1)[1].split()[16])\n"
        "try:\n"
        "    os.setpriority(os.PRIO_PROCESS, 0, 0)\n"
        "    tried = 'allowed'\n"
        "except OSError as error:\n"
        "    tried = type(error).__name__\n"
        "raise RuntimeError(f'nice={nice} back to 0: {tried}')\n"
    )
    assert DEFAULT_LIMITS.nice > 0
    exited = finish(launcher, code)
    assert error_text(exited) == (
        f"RuntimeError: nice={DEFAULT_LIMITS.nice} back to 0: PermissionError"
    )


@pytest.mark.slow
def test_touched_memory_is_capped_by_the_cgroup_or_the_rlimit(launcher):
    code = (
        "import numpy as np\nhog = []\nfor _ in range(100):\n    hog.append(np.ones(20_000_000))\n"
    )
    # A warm node pressing on its cgroup's cap reclaims its libraries' page cache for seconds
    # before the kernel kills it (seen: the 4 s budget fired first), and the cap is under test.
    with patient(launcher) as lab_budget, Bystander(lab_budget):
        exited = finish(lab_budget, code)
    if launcher.cgroups is not None:
        assert exited.outcome is Outcome.CRASHED
        assert "ran out of memory (its cap is 768 MiB)" in exited.reason
    else:
        assert exited.outcome is Outcome.ERROR and exited.error.type == "MemoryError"


def test_spinning_threads_get_one_core_at_most(launcher):
    """Issue 33, finding 10: on cgroup v1 a node with 8 spinning threads took both cores. With
    the v1 cpu controller (or v2's cpu.max) it gets `cpu_quota_us / cpu_period_us` cores: its
    CPU time over a wall-clock window stays within that, and the kernel says it throttled it."""
    window_s = 1.5
    # The kernel's own clock: time.monotonic() in a node is the run's clock (sandbox.vclock),
    # which does not move while the node loads.
    code = (
        "import threading, time\n"
        "def now():\n"
        "    return time.clock_gettime(time.CLOCK_MONOTONIC)\n"
        f"end = now() + {window_s}\n"
        "def spin():\n"
        "    while now() < end:\n"
        "        pass\n"
        "started_wall, started_cpu = now(), time.process_time()\n"
        "threads = [threading.Thread(target=spin) for _ in range(8)]\n"
        "for t in threads: t.start()\n"
        "for t in threads: t.join()\n"
        "wall, cpu = now() - started_wall, time.process_time() - started_cpu\n"
        "raise RuntimeError(f'wall={wall:.3f} cpu={cpu:.3f}')\n"
    )
    # Whether this machine offers a CPU controller, not whether our detection found it: on a
    # machine that has one, a launcher that does not use it fails here.
    v1_cpu = os.path.join(cgroups.V1_ROOT, "cpu")
    v2_cpu = "cpu" in getattr(launcher.cgroups, "controllers", [])
    if launcher.cgroups is None or not (os.access(v1_cpu, os.W_OK) or v2_cpu):
        pytest.skip(f"no cgroup cpu controller here ({launcher.cgroups!r}): RLIMIT_CPU only")
    reply, node = run_script(launcher, code, "spinner")
    try:
        throttled = _throttled_periods(node.cgroup)
        assert _cpu_quota(node.cgroup) == (
            DEFAULT_LIMITS.cpu_quota_us,
            DEFAULT_LIMITS.cpu_period_us,
        )
        if isinstance(reply, Yield):
            reply = node.shutdown("test over")
    finally:
        node.close()
    message = error_text(reply)
    wall, cpu = (float(part.split("=")[1]) for part in message.split(": ", 1)[1].split())
    cores = DEFAULT_LIMITS.cpu_quota_us / DEFAULT_LIMITS.cpu_period_us
    # One period's worth of slack: the quota is refilled per period, the window cuts one.
    assert cpu <= cores * wall + DEFAULT_LIMITS.cpu_period_us / 1e6, message
    # Where the machine left it that much, the node reached its quota and the kernel held it
    # there (on a machine busy with other work it may never reach it: nothing to throttle).
    if cpu >= 0.9 * cores * wall:
        assert throttled > 0, f"the kernel never throttled the spinning node ({message})"


def _cpu_quota(group) -> tuple[int, int] | None:
    """(quota, period) [us] of the node's cpu group: v1's two files or v2's cpu.max."""
    for directory in group.directories:
        quota = os.path.join(directory, "cpu.cfs_quota_us")
        if os.path.exists(quota):
            with open(quota) as q, open(os.path.join(directory, "cpu.cfs_period_us")) as p:
                return int(q.read()), int(p.read())
        cpu_max = os.path.join(directory, "cpu.max")
        if os.path.exists(cpu_max):
            with open(cpu_max) as m:
                quota_text, period_text = m.read().split()
                return int(quota_text), int(period_text)
    return None


def _throttled_periods(group) -> int:
    """nr_throttled from the node's cpu group (v1 cpu.stat or v2 cpu.stat), 0 if none."""
    for directory in group.directories:
        try:
            with open(os.path.join(directory, "cpu.stat")) as stat:
                fields = dict(line.split() for line in stat if line.strip())
        except OSError:
            continue
        if "nr_throttled" in fields:
            return int(fields["nr_throttled"])
    return 0
