"""Heap tracing for a bench lab's processes (bench/_heap.py, `bench_cluster.py --tracemalloc`).

Python imports this at start-up when bench/_heap_site is on PYTHONPATH, which only the bench's
lab processes have (the sandboxes run `python -I -S` with a cleared environment: never here).
With ROBODOJO_BENCH_HEAP_DIR set it starts tracemalloc at once, so every allocation of the
process is traced, and on SIGUSR2 writes a snapshot to <dir>/<pid>-<n>.tracemalloc (n = 1, 2, ...;
written under a temporary name, then renamed, so a reader never sees half a file). A process
forked from this one (the worker processes, forked by multiprocessing's forkserver) keeps both.
"""

import os

HEAP_DIR = os.environ.get("ROBODOJO_BENCH_HEAP_DIR")
FRAMES = 12  # frames kept per allocation: enough to reach RoboDojo's line from a library's

if HEAP_DIR:
    import signal
    import tracemalloc

    tracemalloc.start(FRAMES)
    _dumped = {}  # pid -> snapshots written (a forked child starts its own count)

    def _dump_snapshot(_signum, _frame):
        pid = os.getpid()
        _dumped[pid] = _dumped.get(pid, 0) + 1
        path = os.path.join(HEAP_DIR, f"{pid}-{_dumped[pid]}.tracemalloc")
        tracemalloc.take_snapshot().dump(path + ".part")
        os.replace(path + ".part", path)

    signal.signal(signal.SIGUSR2, _dump_snapshot)
