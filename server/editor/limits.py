"""Every limit the editor's analysis runs under, in one table, each with the reason for its value.

The size of a file the editor analyses is the lab's own per-file code limit
(`Settings.max_code_bytes_per_file`): a file the lab would refuse to save is refused here too.
"""

from __future__ import annotations

from dataclasses import dataclass

MiB = 1024 * 1024


@dataclass(frozen=True, slots=True)
class EditorLimits:
    # ruff on a 300-line file takes ~10 ms; on the largest file the lab saves (256 KiB) ~100 ms.
    # Past this the linter is stuck on something hostile: its diagnostics are dropped with a
    # sentence, the syntax check and our own checks still answer.
    ruff_timeout_s: float = 3.0
    # ruff format of the largest file takes well under a second.
    format_timeout_s: float = 5.0
    # One analysis request (our checks, completion, hover) in a worker process. A warm jedi
    # answers a 300-line controller in tens of milliseconds; past this limit the request is
    # answered with a sentence (nobody waits longer for a completion) ...
    analysis_timeout_s: float = 4.0
    # ... and the worker goes on, unseen, until this limit: jedi's first look at a big library
    # (matplotlib.pyplot, scipy.signal: 5-10 s on a loaded machine) is worth finishing, since
    # the worker keeps what it learnt.
    # Past it the worker is killed and replaced (a thread could not be stopped, a process can).
    analysis_hard_timeout_s: float = 60.0
    # How long a request waits for the first worker of a starting server.
    first_analysis_timeout_s: float = 20.0
    # A worker loads jedi and reads rospy, rclpy, the message stubs and numpy before it takes
    # requests: ~8 s with jedi's disk cache, ~30 s without on a loaded 2-core machine.
    worker_start_timeout_s: float = 180.0
    # Worker processes: the machine has 2 cores and runs students' nodes; two workers answer
    # two students at once, and a third request waits for one of them.
    workers: int = 2
    # How long a request waits for a free worker before it is told to try again.
    queue_wait_s: float = 4.0
    # A worker's address space: jedi's caches for numpy and the message stubs take ~300 MiB;
    # hostile input (a 256 KiB file of nested brackets) fails with MemoryError instead of
    # pushing the machine into swap.
    worker_address_space_bytes: int = 1536 * MiB
    # A worker is replaced after this many requests, so caches of edited files stay bounded.
    worker_max_requests: int = 5000
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


LIMITS = EditorLimits()
