"""The web service under load: N realtime runs, M websocket viewers, a steady status poll.

Starts `robodojo serve` on a free loopback port with a fresh data folder, one student per run,
N realtime CrowBot runs turning in place (so none ends early on a wall), M viewers spread over
the runs, each subscribed to Distance (20 Hz) at --rate, and polls GET /api/runs/{id} at
--http-rate requests a second in all, open loop (a slow answer does not delay the next
request). After --warmup seconds it measures for --duration seconds and prints, each as p50,
p99 and max:

- HTTP latency of the run-status route: request sent -> answer read, at the client;
- delivery, end to end: the run handing a message to the live telemetry (RunTelemetry
  .on_message) -> the client reading its frame off the socket. Both sides read the same
  CLOCK_MONOTONIC (one machine), so this is a direct measurement, not an estimate;
- delivery, server side: on_message -> frame handed to the websocket writer (RunTelemetry's own
  record; it misses the socket and the client);
- lag behind the robot clock: (arrival - frame time_s) minus the smallest such offset the viewer
  saw; it adds the simulation's own lateness to the delivery and needs no server help;
- the interval between consecutive frames at a viewer, against the period 1/rate;
- frames received against expected, samples the server overwrote before sending (`dropped`);
- server resident memory (psutil on the server process, every --sample-every s): first, last,
  max and the least-squares slope in MiB per minute; the sandboxes' memory beside it;
- machine CPU, load average, the server's and this client's CPU, and the client's own event-loop
  lag (a high value means the client, not the server, is slow).

The first two delivery numbers need bench-only additions that live in this file, not in
server/: the server is started through `serve_with_probe`, which stamps each telemetry frame
with its on_message time and adds GET /bench/delivery-latencies (instructor only). With
--no-probe the plain `python -m server.cli serve` runs and only the client-side numbers appear.
--tracemalloc lists where the server's Python heap grew during the window (it slows the server
several times over, so use a small load and ignore that run's latencies).

Reading the delivery numbers: a viewer's rate limit keeps a schedule (server/service/
telemetry.py), so a topic published at the viewer's own rate goes out as it arrives; before that
change, each frame waited up to a period and delivery spread evenly over 0-50 ms at 20 Hz.

Usage: python bench/bench_api.py [--runs 20] [--viewers 100] [--rate 20] [--duration 60]
       [--warmup 10] [--http-rate 10] [--no-probe | --tracemalloc]
Targets (the issue): 20 runs and 100 viewers at 20 Hz with p99 delivery under 50 ms, and no
memory growth over 10 minutes (--duration 600).
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import math
import os
import sys
import tempfile
import time
from array import array
from dataclasses import dataclass, field
from pathlib import Path

import httpx
import psutil
from _common import (
    HTTP_TIMEOUT_S,
    MAX_HTTP_IN_FLIGHT,
    MIB,
    BenchError,
    HttpStats,
    LabProcess,
    MemorySample,
    Window,
    bearer,
    free_port,
    loop_lag,
    p99_ms,
    percentile,
    poll_status,
    row,
    sample_memory,
    sample_memory_every,
    slope,
    spawn,
    stop,
    stop_on_sigterm,
    wait_until_up,
)
from websockets.asyncio.client import connect
from websockets.exceptions import WebSocketException

ROBOT, WORLD, TOPIC = "crowbot", "wall_approach", "Distance"
# Turns in place at the control rate: the robot never reaches a wall, so a run lasts its duration.
CONTROLLER = """\
RATE_HZ = 20


def step(obs):
    return {"Control": (0.0, 0.5)}
"""
SERVE_WITH_PROBE = "--serve-with-probe"  # argv[1] of the server process this script starts
STAMP_KEY = "bench_received_mono_s"  # [s] monotonic time of on_message, added to each frame
PROBE_ROUTE = "/bench/delivery-latencies"
MEMORY_ROUTE = "/bench/memory-growth"  # with --tracemalloc: top allocation sites since a reset
TRACEMALLOC = "--tracemalloc"  # also an argument of the server process
TOP_GROWTH_LINES = 12  # allocation sites listed by --tracemalloc

RUNS_RUNNING_TIMEOUT_S = 180.0  # [s] N cold sandbox starts one after another under load
VIEWERS_READY_TIMEOUT_S = 60.0  # [s] every viewer connected and its subscription acknowledged
RUN_MARGIN_S = 60.0  # [s] runs last this much past the measurement, so none ends inside it
TRACEMALLOC_TIMEOUT_S = 300.0  # [s] a heap snapshot of a loaded server, compared
PROBE_EVERY_S = 2.0  # [s] RunTelemetry keeps 10,000 latencies per run: read well before that
PROGRESS_EVERY_S = 60.0  # [s] one progress line this often during long measurements


# --------------------------------------------------------------------------- the server process
def serve_with_probe(argv: list[str]) -> int:
    """`robodojo serve` with additions for this benchmark only: each telemetry frame carries
    the monotonic time its sample reached RunTelemetry.on_message (STAMP_KEY), PROBE_ROUTE
    hands out (and clears) the server-side delivery latencies of every live run, and with
    --tracemalloc, MEMORY_ROUTE lists where the server's Python heap grew since a reset."""
    import tracemalloc

    from fastapi import Depends

    import server.api.app as app_module
    from server import cli
    from server.api.auth import instructor
    from server.service.telemetry import Viewer

    plain_frame = Viewer._telemetry_frame

    def stamped_frame(topic, sample, subscription):
        frame = plain_frame(topic, sample, subscription)
        frame[STAMP_KEY] = sample.received_s
        return frame

    Viewer._telemetry_frame = staticmethod(stamped_frame)
    plain_create_app = app_module.create_app

    def create_app(settings=None, launcher=None):
        app = plain_create_app(settings, launcher)

        # async: on the loop that also runs Viewer._collect, so no sample is read twice. No
        # annotations: they would be looked up in this module, where Caller is not imported.
        @app.get(PROBE_ROUTE, include_in_schema=False)
        async def delivery_latencies(_=Depends(instructor)):
            mirrors = app.state.runs.executor.mirrors
            latencies: list[float] = []
            for run_id in mirrors.run_ids():
                telemetry = mirrors.feed(run_id)
                if telemetry is None:
                    continue
                latencies.extend(telemetry._latencies_s)
                telemetry._latencies_s.clear()
            return {"latencies_s": latencies}

        baseline: list[tracemalloc.Snapshot] = []

        @app.get(MEMORY_ROUTE, include_in_schema=False)
        def memory_growth(reset: bool = False, _=Depends(instructor)):
            if not tracemalloc.is_tracing():
                return {"top": [], "note": "start the server with --tracemalloc"}
            snapshot = tracemalloc.take_snapshot()
            if reset or not baseline:
                baseline[:] = [snapshot]
                return {"top": []}
            top = snapshot.compare_to(baseline[0], "lineno")[:TOP_GROWTH_LINES]
            return {
                "top": [
                    {
                        "where": str(stat.traceback),
                        "kib": stat.size_diff / 1024,
                        "blocks": stat.count_diff,
                    }
                    for stat in top
                ]
            }

        return app

    app_module.create_app = create_app  # cmd_serve imports it by name when it runs
    if TRACEMALLOC in argv:
        argv = [arg for arg in argv if arg != TRACEMALLOC]
        tracemalloc.start()  # here, not PYTHONTRACEMALLOC: the sandboxes must not inherit it
    return cli.main(["serve", *argv])


def start_server(
    data: Path, env_extra: dict[str, str], probe: bool, trace_memory: bool = False
) -> LabProcess:
    """The same start as tests/api/conftest.py's start_server, with the probe's command."""
    port = free_port()
    serve = (
        [str(Path(__file__).resolve()), SERVE_WITH_PROBE]
        if probe
        else ["-m", "server.cli", "serve"]
    )
    command = [sys.executable, *serve, "--port", str(port), "--data", str(data)]
    if trace_memory:
        command.append(TRACEMALLOC)
    server = spawn("the server", command, env_extra, f"http://127.0.0.1:{port}")
    try:
        wait_until_up(server)
    except BaseException:  # Ctrl-C included: never leave a server behind
        stop(server)
        raise
    return server


# ------------------------------------------------------------------------------------ measuring
@dataclass
class ViewerStats:
    settled: asyncio.Event = field(default_factory=asyncio.Event)  # subscribed, or gave up
    subscribed: bool = False
    frames: int = 0
    dropped: int = 0  # samples the server overwrote before this viewer was sent one
    end_to_end_s: array = field(default_factory=lambda: array("d"))
    offsets_s: array = field(default_factory=lambda: array("d"))  # arrival - time_s
    min_offset_s: float = math.inf  # over every frame, warm-up included
    intervals_s: array = field(default_factory=lambda: array("d"))
    last_arrival_s: float | None = None
    ended: str | None = None  # the run's end state and reason, if it ended while watched
    error: str | None = None


async def watch(
    ws_url: str, run_id: str, token: str, rate_hz: float, window: Window, stats: ViewerStats
) -> None:
    uri = f"{ws_url}/api/runs/{run_id}/live?token={token}"
    try:
        # No client pings: a pong late under load would close a healthy socket.
        async with connect(uri, open_timeout=VIEWERS_READY_TIMEOUT_S, ping_interval=None) as ws:
            await ws.send(
                json.dumps({"id": 1, "op": "subscribe", "topic": TOPIC, "max_rate_hz": rate_hz})
            )
            async for text in ws:
                arrival = time.monotonic()
                frame = json.loads(text)
                kind = frame.get("type")
                if kind == "telemetry":
                    offset = arrival - frame["time_s"]
                    stats.min_offset_s = min(stats.min_offset_s, offset)
                    if arrival in window:
                        stats.frames += 1
                        stats.dropped += frame.get("dropped", 0)
                        stats.offsets_s.append(offset)
                        if STAMP_KEY in frame:
                            stats.end_to_end_s.append(arrival - frame[STAMP_KEY])
                        if stats.last_arrival_s is not None and stats.last_arrival_s in window:
                            stats.intervals_s.append(arrival - stats.last_arrival_s)
                    stats.last_arrival_s = arrival
                elif kind == "ack" and frame.get("id") == 1:
                    stats.subscribed = True
                    stats.settled.set()
                elif kind == "error":
                    stats.error = f"server refused a command: {frame.get('detail')}"
                    return
                elif kind == "end":
                    stats.ended = f"{frame.get('state')}: {frame.get('reason')}"
                    return
    except (OSError, TimeoutError, WebSocketException) as error:
        stats.error = f"{type(error).__name__}: {error}"
    finally:
        stats.settled.set()


async def collect_server_latencies(
    client: httpx.AsyncClient, admin: dict, window: Window, into: array
) -> None:
    """Read-and-clear the probe's latencies every PROBE_EVERY_S; keep those read in the window
    (the read at the window's start clears what the warm-up left)."""
    while True:
        await asyncio.sleep(PROBE_EVERY_S)
        await read_server_latencies(client, admin, window, into)


async def read_server_latencies(
    client: httpx.AsyncClient, admin: dict, window: Window, into: array
) -> None:
    try:
        answer = await client.get(PROBE_ROUTE, headers=admin)
        answer.raise_for_status()
    except httpx.HTTPError:
        return  # a missed read loses at most PROBE_EVERY_S of samples; the rest still count
    if time.monotonic() > window.start:
        into.extend(answer.json()["latencies_s"])


async def memory_growth(client: httpx.AsyncClient, admin: dict, reset: bool = False) -> list:
    """The server's top heap growth sites since the last reset (a snapshot takes seconds)."""
    answer = await client.get(
        MEMORY_ROUTE, params={"reset": reset}, headers=admin, timeout=TRACEMALLOC_TIMEOUT_S
    )
    answer.raise_for_status()
    return answer.json()["top"]


# ------------------------------------------------------------------------------------- the load
async def start_runs(
    client: httpx.AsyncClient, admin: dict, count: int, run_duration_s: float
) -> list[tuple[str, str]]:
    """One student per run (as in a class); returns (run id, owner's token) once all run."""
    runs = []
    for index in range(count):
        answer = await client.post(
            "/api/admin/users", headers=admin, json={"name": f"bench{index}", "role": "student"}
        )
        if answer.status_code != 201:
            raise BenchError(f"creating a student failed: {answer.status_code} {answer.text}")
        token = answer.json()["token"]
        body = {
            "robot": ROBOT,
            "world": WORLD,
            "clock": "realtime",
            "duration": run_duration_s,
            "nodes": [{"name": "controller", "code": CONTROLLER}],
        }
        answer = await client.post("/api/runs", json=body, headers=bearer(token))
        if answer.status_code != 201:
            raise BenchError(f"starting run {index + 1} failed: {answer.status_code} {answer.text}")
        runs.append((answer.json()["id"], token))
    deadline = time.monotonic() + RUNS_RUNNING_TIMEOUT_S
    waiting = dict(runs)
    while waiting:
        if time.monotonic() > deadline:
            raise BenchError(
                f"{len(waiting)} of {count} runs were not running after "
                f"{RUNS_RUNNING_TIMEOUT_S:g} s; the machine may be too loaded"
            )
        for run_id, token in list(waiting.items()):
            answer = await client.get(f"/api/runs/{run_id}", headers=bearer(token))
            state = answer.json().get("state")
            if state == "running":
                del waiting[run_id]
            elif state in ("finished", "failed", "interrupted"):
                raise BenchError(
                    f"run {run_id} ended at start ({state}): {answer.json().get('reason')}"
                )
        await asyncio.sleep(0.5)
    return runs


@dataclass
class Results:
    window_s: float
    viewers: list[ViewerStats]
    http: HttpStats
    server_latencies_s: array
    loop_lag_s: array
    memory: list[MemorySample]
    machine_busy_percent: float
    load_average: tuple[float, float, float]
    server_cpu_cores: float
    client_cpu_cores: float
    heap_growth: list[dict]  # --tracemalloc: {where, kib, blocks}, biggest growth first


async def load(server: LabProcess, args: argparse.Namespace, run_duration_s: float) -> Results:
    admin = bearer(server.admin_token)
    limits = httpx.Limits(max_connections=MAX_HTTP_IN_FLIGHT + 4)
    async with httpx.AsyncClient(
        base_url=server.url, timeout=HTTP_TIMEOUT_S, limits=limits
    ) as client:
        print(f"starting {args.runs} realtime runs ...", flush=True)
        runs = await start_runs(client, admin, args.runs, run_duration_s)
        tasks: list[asyncio.Task] = []
        try:
            return await measure(server, client, admin, runs, args, tasks)
        finally:
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)
            for run_id, token in runs:  # stopped here, so the server's shutdown is quick
                with contextlib.suppress(httpx.HTTPError):
                    await client.post(f"/api/runs/{run_id}/stop", headers=bearer(token))


async def measure(
    server: LabProcess,
    client: httpx.AsyncClient,
    admin: dict,
    runs: list[tuple[str, str]],
    args: argparse.Namespace,
    tasks: list[asyncio.Task],
) -> Results:
    """Viewers on, warm-up, the measured window; every task it starts goes into `tasks`."""
    window = Window()
    viewers = [ViewerStats() for _ in range(args.viewers)]
    ws_url = server.url.replace("http://", "ws://")
    print(f"connecting {args.viewers} viewers ...", flush=True)
    for index, stats in enumerate(viewers):
        run_id, token = runs[index % len(runs)]
        tasks.append(asyncio.create_task(watch(ws_url, run_id, token, args.rate, window, stats)))
    settled = asyncio.gather(*(stats.settled.wait() for stats in viewers))
    with contextlib.suppress(TimeoutError):
        await asyncio.wait_for(settled, VIEWERS_READY_TIMEOUT_S)
    unready = [s for s in viewers if not s.subscribed]
    if unready:
        first = unready[0].error or unready[0].ended or "no answer"
        raise BenchError(
            f"{len(unready)} of {args.viewers} viewers were not subscribed after "
            f"{VIEWERS_READY_TIMEOUT_S:g} s; first: {first}"
        )
    http, server_latencies, loop_lags = HttpStats(), array("d"), array("d")
    memory: list[MemorySample] = []
    process, me = psutil.Process(server.process.pid), psutil.Process()
    poller = asyncio.create_task(
        poll_status([(client, *run) for run in runs], args.http_rate, window, http)
    )
    tasks += [
        poller,
        asyncio.create_task(loop_lag(loop_lags, window)),
        asyncio.create_task(sample_memory_every(process, args.sample_every, memory, window)),
    ]
    if not args.no_probe:
        tasks.append(
            asyncio.create_task(collect_server_latencies(client, admin, window, server_latencies))
        )
    print(f"warming up {args.warmup:g} s ...", flush=True)
    await asyncio.sleep(args.warmup)
    if not args.no_probe:  # clears what the warm-up left (window.start is still inf)
        await read_server_latencies(client, admin, window, server_latencies)
    if args.tracemalloc:
        await memory_growth(client, admin, reset=True)
    psutil.cpu_percent(None)
    cpu_start = process.cpu_times(), me.cpu_times()
    window.start = time.monotonic()
    print(f"measuring {args.duration:g} s ...", flush=True)
    until = window.start + args.duration
    http_mark = delivery_mark = 0
    while (left := until - time.monotonic()) > 0:
        await asyncio.sleep(min(left, PROGRESS_EVERY_S))
        if until - time.monotonic() > 1.0:
            # This interval's p99s: a spike from other load and a steady climb look different.
            http_p99 = p99_ms(http.latencies_s[http_mark:])
            delivery_p99 = p99_ms(server_latencies[delivery_mark:])
            http_mark, delivery_mark = len(http.latencies_s), len(server_latencies)
            print(
                f"  {time.monotonic() - window.start:5.0f} s: "
                f"{sum(s.frames for s in viewers)} frames, server RSS "
                f"{process.memory_info().rss / MIB:.1f} MiB, load {os.getloadavg()[0]:.1f}; "
                f"last {PROGRESS_EVERY_S:g} s: HTTP p99 {http_p99:.0f} ms, server-side "
                f"delivery p99 {delivery_p99:.0f} ms",
                flush=True,
            )
    window.end = time.monotonic()
    busy = psutil.cpu_percent(None)
    cpu_end = process.cpu_times(), me.cpu_times()
    memory.append(sample_memory(process))
    if not args.no_probe:
        await read_server_latencies(client, admin, window, server_latencies)
    await asyncio.wait([poller], timeout=HTTP_TIMEOUT_S + 2.0)  # answers still on their way
    growth = await memory_growth(client, admin) if args.tracemalloc else []
    window_s = window.end - window.start

    def cores(start, end) -> float:
        return (end.user + end.system - start.user - start.system) / window_s

    return Results(
        window_s=window_s,
        viewers=viewers,
        http=http,
        server_latencies_s=server_latencies,
        loop_lag_s=loop_lags,
        memory=memory,
        machine_busy_percent=busy,
        load_average=os.getloadavg(),
        server_cpu_cores=cores(cpu_start[0], cpu_end[0]),
        client_cpu_cores=cores(cpu_start[1], cpu_end[1]),
        heap_growth=growth,
    )


# ------------------------------------------------------------------------------------ reporting
def report(results: Results, args: argparse.Namespace, source_hz: float) -> None:
    viewers = results.viewers
    window_s = results.window_s
    end_to_end = [x for v in viewers for x in v.end_to_end_s]
    intervals = [x for v in viewers for x in v.intervals_s]
    lags = [offset - v.min_offset_s for v in viewers for offset in v.offsets_s]
    period_ms = 1e3 / min(args.rate, source_hz)
    http = results.http
    errors = ", ".join(f"{k}: {n}" for k, n in http.errors.items()) or "none"
    print()
    print(
        f"{args.runs} realtime runs, {args.viewers} viewers of {TOPIC} at {args.rate:g} Hz, "
        f"GET /api/runs/{{id}} at {args.http_rate:g}/s; measured {window_s:.0f} s after a "
        f"{args.warmup:g} s warm-up"
    )
    print(f"{'[ms]':<58} {'p50':>8} {'p99':>8} {'max':>8} {'n':>9}")
    row(
        "HTTP GET /api/runs/{id}: sent -> answer read",
        http.latencies_s,
        f"errors {errors}, skipped {http.skipped}",
    )
    no_probe = "needs the probe (run without --no-probe)" if args.no_probe else ""
    row("delivery end to end: on_message -> client read", end_to_end, no_probe)
    row(
        "delivery server side: on_message -> websocket writer", results.server_latencies_s, no_probe
    )
    row("lag behind robot clock, beyond the viewer's fastest frame", lags)
    row(f"interval between frames at a viewer (period {period_ms:.0f} ms)", intervals)
    row("client event-loop lag (this script's own delay)", results.loop_lag_s)
    received = sum(v.frames for v in viewers)
    expected = args.viewers * min(args.rate, source_hz) * window_s
    ended = [v.ended for v in viewers if v.ended]
    failed = [v.error for v in viewers if v.error]
    print(
        f"frames: {received} received of ~{expected:.0f} expected ({received / expected:.1%}); "
        f"samples overwritten before sending (dropped): {sum(v.dropped for v in viewers)}; "
        f"viewers whose run ended: {len(ended)}; viewer errors: {len(failed)}"
    )
    for problem in sorted(set(ended + failed))[:3]:
        print(f"  e.g. {problem}")
    memory = results.memory
    if len(memory) >= 2:
        minutes = [(s.at_s - memory[0].at_s) / 60 for s in memory]
        rss = [s.server_rss / MIB for s in memory]
        half = len(memory) // 2
        # The second half's slope apart: growth that levels off (caches, allocator arenas,
        # bounded buffers filling) shows as a first-half rise and a flat second half.
        print(
            f"server RSS [MiB]: start {rss[0]:.1f}, end {rss[-1]:.1f}, max {max(rss):.1f}; "
            f"slope {slope(minutes, rss):+.2f} MiB/min over {window_s / 60:.1f} min, "
            f"{slope(minutes[half:], rss[half:]):+.2f} over its second half ({len(memory)} "
            f"samples); sandboxes {memory[-1].sandboxes_rss / MIB:.0f} MiB in all (RSS summed)"
        )
    if results.heap_growth:
        print("server heap growth over the window by allocation site (tracemalloc):")
        for site in results.heap_growth:
            print(f"  {site['kib']:+10.0f} KiB {site['blocks']:+9d} blocks  {site['where']}")
    load1, load5, _ = results.load_average
    print(
        f"machine: {psutil.cpu_count()} CPUs {results.machine_busy_percent:.0f}% busy, load "
        f"average {load1:.1f} (1 min) {load5:.1f} (5 min); server process "
        f"{results.server_cpu_cores:.2f} cores, this client {results.client_cpu_cores:.2f}"
    )
    delivery = end_to_end or lags
    if delivery:
        p99_ms = percentile(delivery, 0.99) * 1e3
        what = "end to end" if end_to_end else "lag estimate"
        verdict = "ok" if p99_ms < 50 else "over"
        print(f"target p99 delivery < 50 ms ({what}): {p99_ms:.1f} ms -> {verdict}")


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == SERVE_WITH_PROBE:
        raise SystemExit(serve_with_probe(sys.argv[2:]))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20, help="concurrent realtime runs")
    parser.add_argument("--viewers", type=int, default=100, help="websocket viewers in all")
    parser.add_argument("--rate", type=float, default=20.0, help="each viewer's max_rate_hz")
    parser.add_argument("--duration", type=float, default=60.0, help="measured seconds")
    parser.add_argument("--warmup", type=float, default=10.0, help="seconds before measuring")
    parser.add_argument("--http-rate", type=float, default=10.0, help="status GETs per second")
    parser.add_argument("--sample-every", type=float, default=5.0, help="memory sample period")
    parser.add_argument("--no-probe", action="store_true", help="plain server, client numbers")
    parser.add_argument(
        TRACEMALLOC,
        action="store_true",
        help="list where the server's heap grew (slows the server: latencies are not comparable)",
    )
    args = parser.parse_args()
    if args.tracemalloc and args.no_probe:
        parser.error(f"{TRACEMALLOC} needs the probe; leave out --no-probe")
    if args.runs < 1 or args.viewers < 1 or args.rate <= 0 or args.http_rate <= 0:
        parser.error("--runs, --viewers, --rate and --http-rate must be positive")
    from server.sim import get_robot

    source_hz = next(t.rate_hz for t in get_robot(ROBOT).topics() if t.name == TOPIC)
    run_duration_s = RUNS_RUNNING_TIMEOUT_S + VIEWERS_READY_TIMEOUT_S + args.warmup
    run_duration_s += args.duration + RUN_MARGIN_S
    env = {
        "ROBODOJO_MAX_RUNS_TOTAL": str(max(24, args.runs)),
        "ROBODOJO_MAX_RUN_DURATION_S": str(math.ceil(run_duration_s)),
    }
    # SIGTERM ends the benchmark as Ctrl-C does: through the finally that stops the server.
    stop_on_sigterm()
    print(f"machine before: load average {os.getloadavg()[0]:.1f}, {psutil.cpu_count()} CPUs")
    with tempfile.TemporaryDirectory(prefix="robodojo-bench-api-") as data:
        server = None
        try:
            server = start_server(Path(data), env, not args.no_probe, args.tracemalloc)
            results = asyncio.run(load(server, args, run_duration_s))
        except KeyboardInterrupt:
            print("\nbench_api: interrupted; stopping the server", file=sys.stderr)
            raise SystemExit(130) from None
        except (BenchError, httpx.HTTPError) as error:
            tail = f"\nlast server output:\n{server.tail()}" if server else ""
            print(f"bench_api: {error}{tail}", file=sys.stderr)
            raise SystemExit(1) from None
        finally:
            if server is not None:
                stop(server)
    report(results, args, source_hz)


if __name__ == "__main__":
    main()
