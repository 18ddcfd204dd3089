"""Run engine throughput: one long lockstep run, many realtime runs at once, memory per run.

Prints
- the wall time of a 60 s lockstep CrowBot run with a 10 Hz step-API controller, node start from
  the warm pool included (median and p99 over --repeats runs);
- for each control rate tried, 20 realtime CrowBot runs at once (--concurrent): the worst run's
  period p99 and how it compares with the period (target: within 10%), and the highest rate that
  kept every run within it;
- memory per run: resident memory of a node's sandbox (proportional set size, shared libraries
  split fairly) and what the server process grew by per run.

With --workers N (issue 16) the realtime runs go through the lab's run service and executor
instead, as `robodojo serve --workers N` runs them: N worker processes (one per core is the
default), or 0 for the web process's own threads; it prints each rate's worst whole-run p99 and
the worst p99 of each run's newest loop periods read live near its end (steady), and, on
worker processes, the CPU a run costs them and its sandbox per second of run (mid-run, no web
process or viewer beside it): what sizing a worker core starts from.

Usage: python bench/bench_runs.py [--repeats 5] [--concurrent 20] [--rates 20,50,100]
       python bench/bench_runs.py --workers 2 --rates 100     (and --workers 0 to compare)
Targets (issue 4): the 60 s lockstep run in under 2 s; 20 realtime runs at 100 Hz with period
p99 under 11 ms on this 2-core machine.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import tempfile
import threading
import time
from pathlib import Path

import psutil
from _common import describe_machine, percentile

from sandbox.launcher import Launcher
from sandbox.protocol import Clock
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState

CONTROLLER = """
RATE_HZ = {rate}
SUBSCRIBE = ["Distance"]

def step(obs):
    if obs.Distance is None or obs.Distance.data == 0:
        return (0.0, 0.0)
    return (0.4 * (obs.Distance.data / 100 - 0.2), 0.0)
"""


def spec(rate_hz: float, duration_s: float, clock: Clock) -> RunSpec:
    node = NodeSpec("controller", CONTROLLER.format(rate=rate_hz), "controller.py")
    return RunSpec("crowbot", "wall_approach", (node,), clock=clock, duration_s=duration_s)


def wait_for_pool(launcher: Launcher, count: int) -> None:
    while len(launcher._pool) < count:
        time.sleep(0.05)


def bench_lockstep(repeats: int, out: Path) -> None:
    launcher = Launcher(pool_size=1)
    walls = []
    for attempt in range(repeats):
        wait_for_pool(launcher, 1)
        started = time.perf_counter()
        result = Run(spec(10, 60.0, Clock.LOCKSTEP), launcher, out / f"lock{attempt}").execute()
        walls.append(time.perf_counter() - started)
        assert result.state is RunState.FINISHED, result.reason
    launcher.close()
    print(
        f"60 s lockstep CrowBot run, 10 Hz controller: wall p50 {statistics.median(walls):.3f} s"
        f"   p99 {percentile(walls, 0.99):.3f} s   (n={repeats}, node start from the pool)"
    )


def _pss_kib(pid: int) -> int:
    """Proportional set size of a process and all its descendants [KiB]."""
    total = 0
    pending = [pid]
    while pending:
        current = pending.pop()
        try:
            with open(f"/proc/{current}/smaps_rollup") as f:
                for line in f:
                    if line.startswith("Pss:"):
                        total += int(line.split()[1])
            for task in os.listdir(f"/proc/{current}/task"):
                with open(f"/proc/{current}/task/{task}/children") as f:
                    pending.extend(int(child) for child in f.read().split())
        except OSError:
            continue
    return total


def _rss_kib() -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


def bench_concurrent(rate_hz: float, count: int, duration_s: float, out: Path) -> tuple[bool, dict]:
    launcher = Launcher(pool_size=count)
    wait_for_pool(launcher, count)
    rss_before = _rss_kib()
    runs = [
        Run(spec(rate_hz, duration_s, Clock.REALTIME), launcher, out / f"rt{rate_hz}-{i}")
        for i in range(count)
    ]
    results = [None] * count
    threads = [
        threading.Thread(target=lambda i=i: results.__setitem__(i, runs[i].execute()))
        for i in range(count)
    ]
    for thread in threads:
        thread.start()
    time.sleep(duration_s / 2)
    node_pss = [
        _pss_kib(slot.process.pid)
        for run in runs
        for slot in run.slots.values()
        if slot.process is not None
    ]
    rss_during = _rss_kib()
    for thread in threads:
        thread.join()
    launcher.close()
    period_s = 1.0 / rate_hz
    failed = [r.reason for r in results if r.state is not RunState.FINISHED]
    # Whole-run p99 includes the first second, while the other runs are still starting (their
    # node loads and set-up hold the interpreter for tens of ms); steady p99 leaves it out.
    whole = [r.nodes["controller"]["period"]["p99_s"] for r in results if r.nodes]
    steady = []
    for run in runs:
        settled = run.slots["controller"].metrics.period.values[int(rate_hz) :]
        if settled:
            steady.append(percentile(settled, 0.99))
    worst_whole = max(whole) if whole else float("nan")
    worst_steady = max(steady) if steady else float("nan")
    ok = not failed and worst_steady <= 1.1 * period_s
    print(
        f"{count} realtime runs at {rate_hz:g} Hz (period {period_s * 1e3:.1f} ms, limit "
        f"{1.1 * period_s * 1e3:.1f} ms): steady p99 worst {worst_steady * 1e3:.2f} ms, median "
        f"{statistics.median(steady) * 1e3 if steady else float('nan'):.2f} ms; whole-run p99 "
        f"worst {worst_whole * 1e3:.2f} ms"
        f"{'  FAILED: ' + failed[0] if failed else ''}  -> {'ok' if ok else 'over'}"
    )
    memory = {
        "node_pss_mib": statistics.median(node_pss) / 1024 if node_pss else float("nan"),
        "server_per_run_mib": (rss_during - rss_before) / 1024 / count,
    }
    return ok, memory


def bench_executor(
    rate_hz: float, count: int, duration_s: float, out: Path, workers: int
) -> tuple[bool, float, float]:
    """`count` realtime runs through RunService and the executor `workers` chooses; (ok, worst
    steady p99, worst whole-run p99) [s]."""
    from server.api.settings import Settings
    from server.service.runs import RunRequest, RunService
    from server.store import accounts
    from server.store import runs as run_store
    from server.store.db import Store

    per_process = count if workers == 0 else -(-count // workers)
    settings = Settings(
        data=out / f"lab-{workers}-{rate_hz:g}",
        workers=workers,
        max_runs_total=count,
        max_runs_per_student=count,
        sandbox_pool=per_process,
        rosserial_port=-1,
    )
    settings.data.mkdir(parents=True)
    store = Store.open(settings.store_url)
    launcher = Launcher(pool_size=count if workers == 0 else 0)
    service = RunService(store, settings, launcher)
    if workers == 0:
        wait_for_pool(launcher, count)
    else:
        assert service.executor.wait_ready(timeout_s=300.0, warm=True), "workers not warm"
    node = NodeSpec("controller", CONTROLLER.format(rate=rate_hz), "controller.py")
    request = RunRequest("crowbot", "wall_approach", None, (node,), Clock.REALTIME, duration_s, 0)
    with store.session() as db:
        user_id = accounts.create_user(db, "bench", accounts.Role.STUDENT).user.id
    run_ids = [service.start(user_id, request).id for _ in range(count)]
    # CPU per run-second in the middle of the runs (start-up and end left out), the worker
    # processes and their sandboxes apart: what a run costs a worker core, no web process or
    # viewer beside it (bench_cluster.py measures those too).
    time.sleep(duration_s * 0.3)
    processes = [psutil.Process(pid) for pid in service.executor.children_pids()] if workers else []
    before, started = _cpu_s(processes), time.monotonic()
    time.sleep(duration_s * 0.5)
    after, window_s = _cpu_s(processes), time.monotonic() - started
    time.sleep(duration_s * 0.1)
    steady = []
    for run_id in run_ids:  # the newest loop periods, read live as the page reads them
        live = service.live(run_id)
        recent = live.node_periods.get("controller", {}) if live is not None else {}
        if recent.get("p99_s") is not None:
            steady.append(recent["p99_s"])
    deadline = time.monotonic() + duration_s + 60.0
    while any(service.is_running(run_id) for run_id in run_ids) and time.monotonic() < deadline:
        time.sleep(0.1)
    with store.session() as db:
        records = [run_store.get(db, run_id) for run_id in run_ids]
        failed = [r.reason for r in records if r.state != str(RunState.FINISHED)]
        whole = [r.nodes["controller"]["period"]["p99_s"] for r in records if r.nodes]
    service.shutdown()
    launcher.close()
    store.close()
    period_s = 1.0 / rate_hz
    worst_steady = max(steady) if steady else float("nan")
    worst_whole = max(whole) if whole else float("nan")
    ok = not failed and worst_steady <= 1.1 * period_s
    mode = "in the web process" if workers == 0 else f"on {workers} worker processes"
    print(
        f"{count} realtime runs at {rate_hz:g} Hz {mode} (limit {1.1 * period_s * 1e3:.1f} ms): "
        f"steady p99 worst {worst_steady * 1e3:.2f} ms, median "
        f"{statistics.median(steady) * 1e3 if steady else float('nan'):.2f} ms; whole-run p99 "
        f"worst {worst_whole * 1e3:.2f} ms, median "
        f"{statistics.median(whole) * 1e3 if whole else float('nan'):.2f} ms"
        f"{'  FAILED: ' + failed[0] if failed else ''}  -> {'ok' if ok else 'over'}"
    )
    if workers:
        used = _cpu_used_s(before, after)
        per_run = {part: seconds / window_s / count for part, seconds in used.items()}
        print(
            f"  CPU per run over {window_s:.0f} s mid-run: worker processes "
            f"{per_run['worker'] * 1e3:.2f} ms per run-second ({per_run['worker'] * 100:.2f}% of "
            f"a core), sandboxes {per_run['sandboxes'] * 1e3:.2f} ms per run-second"
        )
    return ok, worst_steady, worst_whole


def _cpu_s(processes: list[psutil.Process]) -> dict[str, float | dict[int, float]]:
    """CPU seconds (user + system) so far of the worker processes, and of each of their
    descendants (the sandboxes) by pid."""
    worker_s, sandboxes = 0.0, {}
    for worker in processes:
        with contextlib.suppress(psutil.Error):
            times = worker.cpu_times()
            worker_s += times.user + times.system
            for child in worker.children(recursive=True):
                with contextlib.suppress(psutil.Error):
                    child_times = child.cpu_times()
                    sandboxes[child.pid] = child_times.user + child_times.system
    return {"worker": worker_s, "sandboxes": sandboxes}


def _cpu_used_s(before: dict, after: dict) -> dict[str, float]:
    """CPU seconds between two `_cpu_s` snapshots. A sandbox counts only if it was there at both:
    one spawned in between (a warm pool's refill, ~1 s of imports) is start-up, not running."""
    kept = after["sandboxes"].keys() & before["sandboxes"].keys()
    return {
        "worker": after["worker"] - before["worker"],
        "sandboxes": sum(after["sandboxes"][pid] - before["sandboxes"][pid] for pid in kept),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--concurrent", type=int, default=20)
    parser.add_argument("--rates", default="20,50,100")
    parser.add_argument("--duration", type=float, default=10.0, help="realtime run length [s]")
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        help="realtime runs through the run service on N worker processes (0: in its threads)",
    )
    args = parser.parse_args()
    print(describe_machine())  # figures of different hours compare only at a similar speed
    with tempfile.TemporaryDirectory(prefix="robodojo-bench-") as tmp:
        out = Path(tmp)
        if args.workers is not None:
            for rate in (float(r) for r in args.rates.split(",")):
                bench_executor(rate, args.concurrent, args.duration, out, args.workers)
            return
        bench_lockstep(args.repeats, out)
        best = None
        memory = None
        for rate in (float(r) for r in args.rates.split(",")):
            ok, memory = bench_concurrent(rate, args.concurrent, args.duration, out)
            if ok:
                best = rate
        print(f"highest rate with every run's steady period p99 within 10%: {best or 'none'} Hz")
        if memory:
            print(
                f"memory per run: node sandbox PSS {memory['node_pss_mib']:.1f} MiB, "
                f"server growth {memory['server_per_run_mib']:.2f} MiB"
            )


if __name__ == "__main__":
    main()
