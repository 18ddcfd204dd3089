"""Every limit the editor's analysis runs under, in one table, each with the reason for its value.

The size of a file the editor analyses is the lab's own per-file code limit
(`Settings.max_code_bytes_per_file`): a file the lab would refuse to save is refused here too.

Three layers apply them: the gate (gate.py) decides who is analysed when; the host in the
editor's sandbox (host.py) gives each request a process with its own time, CPU, memory and
file limits; the sandbox's cgroup (sandbox_host.py, where the machine has cgroups) caps the
host and its requests together.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

MiB = 1024 * 1024


@dataclass(frozen=True, slots=True)
class EditorLimits:
    # --- each request, in a process forked for it alone ---------------------------------
    # Time a request may take [s], from its process's start to its answer; past it the process
    # is killed and the student reads why. A warm completion takes tens of milliseconds; jedi's
    # first look at a library no warm-up covered takes seconds (and is learnt for the next
    # request, host.py); a 26-line list-doubling chain would take forever (issue 33, finding 5).
    analysis_budget_s: float = 4.0  # our checks, completion, hover
    # ruff check: ~10 ms on a 300-line file, ~100 ms on the largest file the lab saves.
    ruff_budget_s: float = 3.0
    # ruff format of the largest file takes well under a second.
    format_budget_s: float = 5.0
    # Memory a request's process may map beyond what it inherits from the host [bytes]
    # (RLIMIT_AS): jedi on a 300-line controller adds ~20-40 MiB; hostile text (the doubling
    # chain, 10,000 nested brackets) fails with MemoryError and a sentence instead of taking
    # the machine's memory.
    request_memory_bytes: int = 512 * MiB
    # ruff's whole address space [bytes]: the largest file the lab saves needs under 64 MiB;
    # 250,000 open brackets wanted 580 MiB each, six at once 2.7 GiB (issue 33, finding 6),
    # and now stop at this cap ("ran out of its memory").
    ruff_memory_bytes: int = 256 * MiB
    # Open files of a request's process: jedi reads one module at a time.
    request_open_files: int = 64
    # A student's analysis process answers their next requests too (request.py: a completion
    # in ~65 ms instead of ~112 ms), this many students' at once, the least recently served let
    # go first; each holds ~30-100 MiB of its own copies of the host's pages and caches.
    sessions: int = 4
    # ... until the student has sent nothing for this long [s] (thinking, reading the run) ...
    session_idle_s: float = 60.0
    # ... or has been answered this many times (jedi's caches of edited texts grow) ...
    session_requests: int = 500
    # ... or has used this much CPU in all (RLIMIT_CPU's hard limit; each request still has
    # its own CPU seconds, below) [s].
    session_cpu_seconds: int = 600
    # What ruff check may send back [bytes]: a file of garbage gets megabytes of findings (a
    # 200 KB f-string: 14 MB); the first 256 KiB hold more than max_diagnostics below.
    ruff_check_output_bytes: int = 256 * 1024
    # Any other answer [bytes]: a formatted file is about as large as the file (at most 256
    # KiB); completions and diagnostics are capped in number below.
    answer_bytes: int = 4 * MiB

    # --- who is analysed when (gate.py) --------------------------------------------------
    # Requests analysed at once (Settings.editor_workers; 0 turns the editor's help off). The
    # machine has 2 cores and runs students' nodes; each student has at most one request
    # analysed at a time, so one student's hostile file holds one of these, for its budget.
    concurrent_requests: int = 2
    # Requests waiting for their turn, all students together; one more is answered 429. A
    # student's newer request of the same kind (a completion after a completion) takes the
    # place of the older one, which is answered 429: the newest text is the one that matters.
    queue_length: int = 8
    # How long a request waits for its turn [s] before it is answered 429.
    queue_wait_s: float = 4.0
    # ... and for the host of a starting server [s].
    first_analysis_timeout_s: float = 20.0

    # --- the host (host.py) and its sandbox (sandbox_host.py) -------------------------------
    # The host loads jedi and reads rospy, rclpy, the message stubs, numpy, matplotlib, scipy
    # and scikit-fuzzy before it takes requests [s]: ~10 s with jedi's disk cache, ~40 s
    # without on a loaded 2-core machine.
    host_start_timeout_s: float = 180.0
    # A warm-up text of ours, analysed after the host is ready in a process of its own whose
    # parses the host learns (host.py): jedi's first look at matplotlib.pyplot or
    # scipy.signal takes 5-10 s on a loaded machine [s].
    warm_up_budget_s: float = 120.0
    # Time the server gives the host past a job's budget before it takes it for stuck and
    # starts another [s] (the host kills requests itself; this is for a host that stopped).
    host_grace_s: float = 5.0
    # The host's own address space [bytes]: warm, it maps ~200-250 MiB (~120-180 MiB
    # resident: jedi's caches of the warm-up and of what it learns). Past this it fails and is
    # replaced.
    host_address_space_bytes: int = 2048 * MiB
    # Library modules the host parses for later requests (host.py); a lab's students import a
    # few dozen besides the warm-up's.
    learned_modules: int = 2000
    # The sandbox's memory, where a memory cgroup exists [bytes]: 135 MiB idle (host, twin,
    # spares; proportional set sizes), ~540 MiB with 4 students' processes warm, and room for
    # the requests at once at their caps (a lint runs ruff and our checks together).
    sandbox_memory_bytes: int = 2048 * MiB
    # Threads and processes of the sandbox together (pids cgroup): bwrap, the host, the
    # request processes (one thread each; ruff a few).
    sandbox_pids: int = 64
    # No CPU cgroup for the sandbox: in one, all its processes together weighed as much as one
    # process of the machine's (cgroup v1 cpu.shares), and a completion took 2-3 times as long
    # on a loaded machine. A request's CPU is its RLIMIT_CPU (cpu_seconds below), and with one
    # request per student at a time, hostile files hold at most concurrent_requests cores,
    # each for its budget.

    # --- what an answer holds -------------------------------------------------------------
    # Completions returned at most (CodeMirror filters further as the student types; jedi has
    # already kept only those that start with what is typed).
    max_completions: int = 150
    # Completions that get their docstring besides messages' fields and obs' topics (whose
    # docstrings are one line of our stubs): a library function's costs jedi an inference,
    # 20-60 ms for scikit-fuzzy's classes on a loaded machine. Hover gives them on demand.
    documented_completions: int = 0
    # Diagnostics returned at most: a file of garbage yields thousands; the first ones matter.
    max_diagnostics: int = 200
    # A hover's text at most [characters].
    max_hover_chars: int = 2000

    def budget_s(self, op: str) -> float:
        """The time budget of a job of this op (server/editor/frames.py `Op`) [s]."""
        return {"ruff_check": self.ruff_budget_s, "ruff_format": self.format_budget_s}.get(
            op, self.analysis_budget_s
        )

    def cpu_seconds(self, budget_s: float) -> int:
        """RLIMIT_CPU for a request of this time budget: the budget again, as the kernel
        counts CPU time, should the host not kill it in time (ruff's threads count together)."""
        return max(1, math.ceil(budget_s))


LIMITS = EditorLimits()
