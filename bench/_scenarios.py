"""The scenarios of bench_cluster.py, each one pass in a lab already started: a class of
realtime runs (with or without live viewers, commands and a status poll) and runs replacing
each other under a memory watch. Each returns its figures as a dict and prints them with the
matching report_ function."""

from __future__ import annotations

import argparse
import asyncio
import math
import os
import statistics
import time
from array import array

import _heap
import psutil
from _class import (
    StudentRun,
    ViewerStats,
    Web,
    lost,
    make_students,
    read_live_periods,
    start_run,
    start_runs,
    stop_runs,
    wait_ended,
    wait_running,
    wait_viewers,
    watch,
)
from _common import (
    HTTP_TIMEOUT_S,
    MIB,
    HttpStats,
    Window,
    bearer,
    loop_lag,
    machine_shares,
    percentile,
    poll_status,
    row,
    slope,
)
from _lab import Lab, pss_mib, tree_cpu_s

RUN_DURATION_S = 1800.0  # [s] asked of every run of a and b: they end by our stop, not by time
RUNNING_TIMEOUT_S = 300.0  # [s] a hundred cold sandbox starts on a loaded 2-core machine
END_TIMEOUT_S = 120.0  # [s] every run ended after our stop; later counts as lost
LIVE_WAKES = 1000  # wakes in a run's live period summary (server/runs/metrics.py RECENT_SAMPLES)
REFILL_TIMEOUT_S = 120.0  # [s] the warm sandbox pools full again after a burst of starts
PERIOD_TOLERANCE = 1.1  # a period p99 within 10% of the period holds the rate
MEMORY_SAMPLE_S = 5.0  # [s] between resident-memory samples in scenario c
ENV = {  # the lab's limits raised for a class of a hundred (ROBODOJO_ settings)
    "ROBODOJO_MAX_RUNS_TOTAL": "400",
    "ROBODOJO_MAX_RUNS_PER_STUDENT": "2",
    "ROBODOJO_MAX_RUN_DURATION_S": str(int(RUN_DURATION_S) + 60),
    # A worker process's capacity (default 8): the sweep, not this limit, finds what one holds.
    "ROBODOJO_RUNS_PER_PROCESS": "240",
    "ROBODOJO_ROSSERIAL_PORT": "-1",  # no robots here; several web processes would clash on it
}


def ms(seconds: float) -> float:
    return seconds * 1e3


# ------------------------------------------------------------------------------ a and b
async def class_pass(
    lab: Lab,
    webs: list[Web],
    args: argparse.Namespace,
    count: int,
    rate_hz: float,
    tag: str,
    with_class: bool,
) -> dict:
    """`count` runs at `rate_hz` (students named after `tag`); `with_class`: a live viewer
    each, button presses and the status poll (scenario b), else the runs alone (a, sweep)."""
    idle_pss = await asyncio.to_thread(pss_mib, lab.web_processes() + lab.worker_processes())
    full_pool = await warm_pool(webs[0], lab.admin_token)  # a settled lab's pools are full
    students = await make_students(webs, lab.admin_token, count, tag)
    runs = await start_runs(students, rate_hz, RUN_DURATION_S)
    ramp_s = await wait_running(runs, RUNNING_TIMEOUT_S)
    # The burst of starts emptied the warm pools; refilling them (a spawn imports numpy,
    # matplotlib, scikit-fuzzy and rclpy: ~1 s of CPU each) is start-up work, so the measured
    # wakes come after it. The whole-run figures keep the start-up in.
    refill_s = await wait_refilled(webs[0], lab.admin_token, full_pool, REFILL_TIMEOUT_S)
    measure_s = args.measure if with_class else max(5.0, LIVE_WAKES / rate_hz / 2)
    # The newest LIVE_WAKES wakes must all come after the last run started.
    warmup_s = max(args.warmup, LIVE_WAKES / rate_hz - measure_s)
    window = Window()
    viewers = [ViewerStats() for _ in runs] if with_class else []
    tasks = [
        asyncio.create_task(watch(run, args.viewer_rate, window, stats, args.command_every))
        for run, stats in zip(runs, viewers, strict=False)
    ]
    http, loop_lags = HttpStats(), array("d")
    try:
        if viewers:
            await wait_viewers(viewers)
            targets = [(run.student.web.client, run.run_id, run.student.token) for run in runs]
            tasks.append(asyncio.create_task(poll_status(targets, args.http_rate, window, http)))
        tasks.append(asyncio.create_task(loop_lag(loop_lags, window)))
        print(f"  {count} running after {ramp_s:.0f} s; pools refilled {refill_s:.0f} s later; "
              f"warm-up {warmup_s:.0f} s", flush=True)  # fmt: skip
        await asyncio.sleep(warmup_s)
        # Reading /proc for hundreds of processes and asking PostgreSQL take a while under
        # load: in a thread, so this client's loop (viewers, acks, the poll) is not held.
        counters_before = await asyncio.to_thread(lab.service_counters)
        lab_processes = lab.web_processes() + lab.worker_processes()
        cpu_before = await asyncio.to_thread(tree_cpu_s, lab_processes)
        busy_before = psutil.cpu_times()
        window.start = time.monotonic()
        await asyncio.sleep(measure_s)
        window.end = time.monotonic()
        busy, steal = machine_shares(busy_before)
        cpu_after = await asyncio.to_thread(tree_cpu_s, lab_processes)
        used_s = sum(cpu_after[pid] - cpu_before[pid] for pid in cpu_after if pid in cpu_before)
        cores_per_run = used_s / (window.end - window.start) / count
        web_pids = [process.pid for process in lab.web_processes()]
        web_s = sum(cpu_after[pid] - cpu_before[pid] for pid in web_pids if pid in cpu_before)
        web_cores = web_s / (window.end - window.start)  # the web processes alone
        counters = await asyncio.to_thread(lab.service_counters)
        services = {
            name: (counters[name] - counters_before.get(name, 0.0)) / (window.end - window.start)
            for name in counters
        }
        pss_during = await asyncio.to_thread(pss_mib, lab_processes)
        await read_live_periods(runs)
        await asyncio.sleep(min(HTTP_TIMEOUT_S, 2.0))  # answers and acks still on their way
    finally:
        for task in tasks:
            task.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)
        await stop_runs(runs)
    await wait_ended(runs, END_TIMEOUT_S)
    return _pass_figures(runs, viewers, http, loop_lags, rate_hz, ramp_s, measure_s, busy) | {
        "machine_steal_percent": steal,
        "memory_per_run_mib": (pss_during - idle_pss) / count,
        "cores_per_run": cores_per_run,  # web, workers and sandboxes, over the window
        "web_cores": web_cores,  # the web processes themselves (no children), all together
        "services_per_s": services,  # Redis and PostgreSQL counters' growth a second
    }


async def warm_pool(web: Web, admin_token: str) -> int:
    """Warm sandboxes waiting in the lab's pools, as its admin status counts them (the worker
    processes of this machine; a cluster's remote workers are not counted there: 0)."""
    answer = await web.client.get("/api/admin/status", headers=bearer(admin_token))
    answer.raise_for_status()
    return int(answer.json().get("runs", {}).get("warm_pool", 0))


async def wait_refilled(web: Web, admin_token: str, full: int, timeout_s: float) -> float:
    """Seconds until the warm pools hold `full` again (or `timeout_s`, said)."""
    started = time.monotonic()
    while await warm_pool(web, admin_token) < full:
        if time.monotonic() - started > timeout_s:
            print(f"  the warm pools were not full again within {timeout_s:g} s", flush=True)
            break
        await asyncio.sleep(0.5)
    return time.monotonic() - started


def _pass_figures(
    runs: list[StudentRun],
    viewers: list[ViewerStats],
    http: HttpStats,
    loop_lags: array,
    rate_hz: float,
    ramp_s: float,
    measure_s: float,
    busy: float,
) -> dict:
    steady = [run.live_period_p99_s for run in runs if not math.isnan(run.live_period_p99_s)]
    whole = [run.whole_period_p99_s() for run in runs]
    whole = [value for value in whole if not math.isnan(value)]
    figures = {
        "runs": len(runs),
        "rate_hz": rate_hz,
        "ramp_s": ramp_s,
        "measured_s": measure_s,
        "steady_p99_ms": [ms(value) for value in steady],
        "whole_p99_ms": [ms(value) for value in whole],
        "lost": lost(runs, stopped_by_us=True),
        "machine_busy_percent": busy,
        "load_1min": os.getloadavg()[0],
        "client_loop_lag_p99_ms": ms(percentile(loop_lags, 0.99)) if loop_lags else math.nan,
    }
    if viewers:
        delivery = [x for v in viewers for x in v.delivery_s]
        commands = [x for v in viewers for x in v.commands_s]
        frames = sum(v.frames for v in viewers)
        figures |= {
            "delivery_s": delivery,
            "commands_s": commands,
            "http_s": list(http.latencies_s),
            "http_errors": dict(http.errors) | {"skipped": http.skipped},
            "command_errors": sum(v.command_errors for v in viewers),
            "frames": frames,
            "dropped": sum(v.dropped for v in viewers),
            "viewer_errors": [v.error or v.ended for v in viewers if v.error or v.ended],
        }
    return figures


def report_pass(name: str, figures: dict) -> None:
    period_ms = 1e3 / figures["rate_hz"]
    limit_ms = PERIOD_TOLERANCE * period_ms
    steady, whole = figures["steady_p99_ms"], figures["whole_p99_ms"]
    print(
        f"{name}: {figures['runs']} realtime runs at {figures['rate_hz']:g} Hz (period "
        f"{period_ms:.1f} ms, limit {limit_ms:.1f} ms), all running after {figures['ramp_s']:.0f}"
        f" s, measured {figures['measured_s']:.0f} s; machine {figures['machine_busy_percent']:.0f}"
        f"% busy (steal {figures.get('machine_steal_percent', math.nan):.1f}%), load "
        f"{figures['load_1min']:.1f}"
    )
    print(f"  {'[ms]':<56} {'p50':>8} {'p99':>8} {'max':>8} {'n':>9}")
    row("  period p99 per run, steady (newest 1000 wakes)", [x / 1e3 for x in steady])
    row("  period p99 per run, whole run (start-up included)", [x / 1e3 for x in whole])
    if "delivery_s" in figures:
        row("  telemetry delivery: production on the worker -> read", figures["delivery_s"])
        row("  button on the live socket: sent -> ack read", figures["commands_s"])
        note = ", ".join(f"{k} {n}" for k, n in figures["http_errors"].items() if n) or "none"
        row("  HTTP GET /api/runs/{id}: sent -> answer read", figures["http_s"], f"errors {note}")
        print(
            f"  frames {figures['frames']}, dropped {figures['dropped']}, command errors "
            f"{figures['command_errors']}, viewer problems {len(figures['viewer_errors'])}"
            + (f" (e.g. {figures['viewer_errors'][0]})" if figures["viewer_errors"] else "")
        )
    print(
        f"  runs lost {len(figures['lost'])}"
        + (f" (e.g. {figures['lost'][0]})" if figures["lost"] else "")
        + f"; memory per run {figures['memory_per_run_mib']:.1f} MiB (PSS, sandboxes included);"
        f" CPU per run {100 * figures['cores_per_run']:.1f}% of a core (web processes "
        f"{figures['web_cores']:.2f} cores in all);"
        f" client loop lag p99 {figures['client_loop_lag_p99_ms']:.0f} ms"
    )
    if figures["services_per_s"]:
        per_run = ", ".join(
            f"{name} {value / figures['runs']:.3g}"
            for name, value in figures["services_per_s"].items()
        )
        print(f"  a second per run: {per_run}")


def headline(figures: dict) -> dict[str, float]:
    """The figures a target is set on, each a single number for this pass."""
    heads = {
        "worst steady period p99 [ms]": max(figures["steady_p99_ms"], default=math.nan),
        "median steady period p99 [ms]": _median(figures["steady_p99_ms"]),
        "worst whole-run period p99 [ms]": max(figures["whole_p99_ms"], default=math.nan),
        "runs lost": float(len(figures["lost"])),
        "CPU per run [% of a core]": 100 * figures["cores_per_run"],
        "web processes [cores]": figures["web_cores"],
        "memory per run [MiB PSS]": figures["memory_per_run_mib"],
    }
    for key, label in (
        ("delivery_s", "delivery"),
        ("commands_s", "commands"),
        ("http_s", "HTTP GET"),
    ):
        if key in figures:
            values = figures[key]
            heads[f"{label} p50 [ms]"] = ms(percentile(values, 0.5)) if values else math.nan
            heads[f"{label} p99 [ms]"] = ms(percentile(values, 0.99)) if values else math.nan
    return heads


def _median(values: list[float]) -> float:
    return statistics.median(values) if values else math.nan


# ------------------------------------------------------------------------------ c: memory
async def memory_pass(lab: Lab, webs: list[Web], args: argparse.Namespace) -> dict:
    """Runs replacing each other for --minutes; every web and worker process's RSS sampled.
    With --tracemalloc (a lab started with _heap.environment), each process also writes a heap
    snapshot after the warm-up and at the window's end; "heap" holds their comparison."""
    students = await make_students(webs, lab.admin_token, args.churn_runs, "c")
    rate_hz = args.b_rate
    done: list[StudentRun] = []
    window = Window()
    until = time.monotonic() + args.churn_run_s + 60 * args.minutes

    async def student_loop(student) -> None:
        while time.monotonic() < until:
            run = await start_run(student, rate_hz, args.churn_run_s)
            await watch(run, args.viewer_rate, window, ViewerStats(), 0.0)  # until its end
            await wait_ended([run], END_TIMEOUT_S)
            done.append(run)

    loops = [asyncio.create_task(student_loop(student)) for student in students]
    processes = {f"web {i + 1}": p for i, p in enumerate(lab.web_processes())}
    try:
        print(f"  warm-up: one round of {args.churn_run_s:g} s runs", flush=True)
        await asyncio.sleep(args.churn_run_s)
        processes |= {f"worker {i + 1}": p for i, p in enumerate(lab.worker_processes())}
        samples: dict[str, list[tuple[float, float]]] = {name: [] for name in processes}
        if args.tracemalloc:
            # Both snapshots must see runs in every stage: on a slow (traced, loaded) lab the
            # first round may still be starting after its nominal length.
            while len(done) < len(students) and time.monotonic() < until:
                await asyncio.sleep(1.0)
            print(f"  heap snapshots after the warm-up ({len(done)} runs ended) ...", flush=True)
            early = await _heap.snapshot_all(processes, args.heap_dir)
        window.start = time.monotonic()
        while time.monotonic() < until:
            for name, process in processes.items():
                try:
                    rss = process.memory_info().rss / MIB
                except psutil.Error:
                    continue  # a worker that ended: its line shows fewer samples
                samples[name].append(((time.monotonic() - window.start) / 60, rss))
            await asyncio.sleep(MEMORY_SAMPLE_S)
            if args.tracemalloc and time.monotonic() > until - args.churn_run_s:
                break  # the late snapshots while runs still replace each other
        window.end = time.monotonic()
        if args.tracemalloc:
            print("  heap snapshots at the end ...", flush=True)
            late = await _heap.snapshot_all(processes, args.heap_dir)
        await asyncio.wait(loops, timeout=args.churn_run_s + END_TIMEOUT_S)
    finally:
        for task in loops:
            task.cancel()
        await asyncio.gather(*loops, return_exceptions=True)
    slopes = {}
    for name, points in samples.items():
        minutes, rss = [p[0] for p in points], [p[1] for p in points]
        half = len(points) // 2
        slopes[name] = {
            "slope_mib_per_min": slope(minutes, rss),
            "second_half_slope": slope(minutes[half:], rss[half:]),
            "start_mib": rss[0] if rss else math.nan,
            "end_mib": rss[-1] if rss else math.nan,
            "samples": len(points),
        }
    heap = {}
    if args.tracemalloc:
        minutes = (window.end - window.start) / 60
        for name in sorted(set(early) & set(late)):
            heap[name] = await asyncio.to_thread(_heap.compare, early[name], late[name], minutes)
            heap[name]["rss_mib"] = (slopes[name]["start_mib"], slopes[name]["end_mib"])
    return {
        "runs_done": len(done),
        "lost": lost(done, stopped_by_us=False),
        "processes": slopes,
        "heap": heap,
    }


def report_memory(name: str, figures: dict, minutes: float) -> None:
    print(
        f"{name}: {figures['runs_done']} runs replaced each other over {minutes:g} min; "
        f"runs lost {len(figures['lost'])}"
        + (f" (e.g. {figures['lost'][0]})" if figures["lost"] else "")
    )
    for process, f in figures["processes"].items():
        verdict = "ok" if abs(f["slope_mib_per_min"]) < 0.5 else "over"
        print(
            f"  {process:<9} RSS {f['start_mib']:7.1f} -> {f['end_mib']:7.1f} MiB, slope "
            f"{f['slope_mib_per_min']:+.3f} MiB/min (second half {f['second_half_slope']:+.3f}; "
            f"{f['samples']} samples) -> {verdict}"
        )
    if figures.get("heap"):
        print("  where the Python heap grew (tracemalloc; the traced processes run slower):")
        for process, heap in figures["heap"].items():
            _heap.report(process, heap, heap["rss_mib"])
