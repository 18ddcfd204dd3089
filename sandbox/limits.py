"""Every limit a sandboxed node runs under, in one table, each with the reason for its value.

The launcher applies the process limits (rlimits, tmpfs size, step budget); the node host applies
the artifact caps when it collects files, and the parent again as it receives them
(sandbox/artifact_intake.py: the collector runs in the student's process, which can replace it);
the parent applies the log caps while it drains the node's output. Change a value here and every
layer follows.
"""

from __future__ import annotations

from dataclasses import dataclass

MiB = 1024 * 1024


@dataclass(frozen=True, slots=True)
class Limits:
    # Address space. numpy + matplotlib + scikit-fuzzy map ~600 MiB of virtual memory (mostly
    # untouched library mappings); 1.5 GiB leaves room for real arrays but stops a memory bomb
    # long before it hurts the server or another run.
    address_space_bytes: int = 1536 * MiB
    # Memory the node may really use (resident pages, its tmpfs files included), enforced by a
    # memory cgroup where the machine has one; the rlimit above cannot see tmpfs or page cache.
    memory_bytes: int = 768 * MiB
    # Threads and processes together (pids cgroup): the interpreter and BLAS need a handful.
    max_pids: int = 32
    # CPU bandwidth ("quota period" in microseconds: cgroup v2 cpu.max, or cgroup v1's
    # cpu.cfs_quota_us and cpu.cfs_period_us): one core's worth, so a spinning node, however
    # many threads it starts, cannot take both cores of a 2-core lab machine from the server
    # and the others. A host with neither controller has only cpu_seconds below and max_pids
    # (sandbox/cgroups.py says which one is in force; the server logs it at start).
    cpu_quota_us: int = 100_000
    cpu_period_us: int = 100_000
    # Scheduling niceness of a node process (the lab's own processes run at 0). When the machine
    # is busy, the realtime scheduler that wakes every run and the web process serving the class
    # get a core before students' code does; a node still gets its share (~1/3 of a nice-0
    # process's at 5). The warm pool's refills, ~1 s of imports each, yield the same way.
    nice: int = 5
    # CPU seconds for the node's whole life: a run of several minutes at a few percent CPU fits
    # easily; a spinning node is killed by the step budget long before this.
    cpu_seconds: int = 900
    # Open files: the interpreter, imports and a few figures; blocks descriptor exhaustion.
    open_files: int = 128
    # Largest single file the node may write [bytes]: a figure or a CSV, not a disk filler.
    file_size_bytes: int = 16 * MiB
    # Scratch directory (the node's working directory) is a tmpfs of this size; other nodes and
    # the host never see it.
    scratch_bytes: int = 64 * MiB
    # Wall-clock time a node may compute between being woken and sleeping again. A controller
    # that needs more than this per period is broken (or `while True: pass`).
    step_budget_s: float = 2.0
    # The first wake runs module-level code and setup(), which may import and precompute.
    first_step_budget_s: float = 10.0
    # How long an idle warm process may take to start and import numpy/matplotlib/skfuzzy.
    startup_budget_s: float = 30.0
    # The end budget: once a node has ended its part (signal_shutdown(), its script returned, or
    # the run asked it to stop), time to run on_shutdown hooks, draw and save figures and send
    # its files. Two 2400x1200 PNGs, as the CrowBot paper's scripts save, take ~2 s on a quiet
    # 2-core machine and several times that under load; 30 s is generous and still bounded.
    shutdown_budget_s: float = 30.0
    # Artifacts collected from the scratch directory at the end of a run, and checked again by
    # the server as they arrive: figures, CSV logs and a map or two, not a disk filler. A run's
    # files count in its student's disk budget only once it has ended, so these bound what one
    # run can add past the budget.
    artifact_file_bytes: int = 8 * MiB
    artifact_total_bytes: int = 24 * MiB
    artifact_count: int = 32
    # An artifact's name (its path in the scratch directory): far past any a node saves, short
    # enough for a log line and a listing.
    artifact_name_chars: int = 1024
    # Log stream: what one node may print over a run; beyond it lines are dropped with a note.
    log_total_bytes: int = 1 * MiB
    log_line_bytes: int = 4096


DEFAULT_LIMITS = Limits()
