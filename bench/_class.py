"""Simulated students of a lab, over HTTP and websockets only (what a browser does): each is
made by the instructor, talks to one of the lab's web processes, starts realtime CrowBot runs,
watches one with a live view, presses the robot's button now and then and reads its run.

    students = await make_students(webs, admin, 100, "a1")     # spread over the web processes
    runs = await start_runs(students, rate_hz=10, duration_s=600)
    await wait_running(runs, timeout_s=300)
    viewer = ViewerStats(); asyncio.create_task(watch(run, 20, window, viewer, 5.0))
    await stop_runs(runs); records = await wait_ended(runs, timeout_s=120)

Delivery end to end: each telemetry frame carries `wall_s`, time.time() when the run produced
the sample (on the worker), and the viewer reads time.time() when the frame is off the socket:
one machine, one clock, so the difference is a direct measurement.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import math
import random
import time
from array import array
from dataclasses import dataclass, field

import httpx
from _common import BenchError, Window, bearer
from websockets.asyncio.client import connect
from websockets.exceptions import WebSocketException

ROBOT, WORLD, TOPIC = "crowbot", "wall_approach", "Distance"
# Turns in place at the control rate: the robot never reaches a wall, so a run lasts as asked.
CONTROLLER = """\
RATE_HZ = {rate_hz:g}


def step(obs):
    return {{"Control": (0.0, 0.5)}}
"""
END_STATES = ("finished", "failed", "interrupted")
STOPPED_REASON = "stopped by"  # an interrupted run's reason when we stopped it
STATE_POLL_S = 1.0  # [s] between rounds of GET /api/runs/{id} while waiting for states
READY_TIMEOUT_S = 60.0  # [s] a viewer connected and its subscription acknowledged
START_CONCURRENCY = 8  # run starts in flight at once: a class clicking "Run" together
RETRY_AFTER_S = 1.0  # [s] a start refused for a moment (429) is tried again after this


@dataclass
class Web:
    """One web process as students reach it: its address and a client bound to it."""

    url: str
    client: httpx.AsyncClient

    @property
    def ws_url(self) -> str:
        return self.url.replace("http://", "ws://")


@dataclass
class Student:
    name: str
    token: str
    web: Web


@dataclass
class StudentRun:
    run_id: str
    student: Student
    started_s: float  # [s] time.monotonic() when POST /api/runs answered
    live_period_p99_s: float = math.nan  # newest wakes' p99 (nodes_live), read while running
    live_period_count: int = 0
    record: dict = field(default_factory=dict)  # GET /api/runs/{id} after its end

    @property
    def state(self) -> str:
        return self.record.get("state", "")

    def whole_period_p99_s(self, node: str = "controller") -> float:
        period = self.record.get("nodes", {}).get(node, {}).get("period", {})
        return period.get("p99_s", math.nan)


async def make_students(webs: list[Web], admin_token: str, count: int, tag: str) -> list[Student]:
    """`count` students made by the instructor on the first web process (one database), each
    then talking to web process i mod len(webs)."""
    students = []
    for index in range(count):
        name = f"bench-{tag}-{index}"
        answer = await webs[0].client.post(
            "/api/admin/users", headers=bearer(admin_token), json={"name": name, "role": "student"}
        )
        if answer.status_code != 201:
            raise BenchError(f"creating student {name} failed: {answer.status_code} {answer.text}")
        students.append(Student(name, answer.json()["token"], webs[index % len(webs)]))
    return students


async def start_run(student: Student, rate_hz: float, duration_s: float) -> StudentRun:
    body = {
        "robot": ROBOT,
        "world": WORLD,
        "clock": "realtime",
        "duration": duration_s,
        "nodes": [{"name": "controller", "code": CONTROLLER.format(rate_hz=rate_hz)}],
    }
    for _ in range(int(READY_TIMEOUT_S / RETRY_AFTER_S)):
        answer = await student.web.client.post(
            "/api/runs", json=body, headers=bearer(student.token)
        )
        if answer.status_code == 201:
            return StudentRun(answer.json()["id"], student, time.monotonic())
        if answer.status_code != 429:  # 429: the student's previous run is still ending
            break
        await asyncio.sleep(RETRY_AFTER_S)
    raise BenchError(
        f"{student.name} could not start a run: {answer.status_code} {answer.text[:300]}"
    )


async def start_runs(
    students: list[Student], rate_hz: float, duration_s: float
) -> list[StudentRun]:
    gate = asyncio.Semaphore(START_CONCURRENCY)

    async def one(student: Student) -> StudentRun:
        async with gate:
            return await start_run(student, rate_hz, duration_s)

    return list(await asyncio.gather(*(one(student) for student in students)))


async def get_run(run: StudentRun) -> dict:
    answer = await run.student.web.client.get(
        f"/api/runs/{run.run_id}", headers=bearer(run.student.token)
    )
    answer.raise_for_status()
    return answer.json()


async def wait_running(runs: list[StudentRun], timeout_s: float) -> float:
    """Until every run is running; returns how long that took [s]. A run that ended at start
    or was not running in time is an error that says which and why."""
    started = time.monotonic()
    waiting = list(runs)
    while waiting:
        if time.monotonic() - started > timeout_s:
            raise BenchError(
                f"{len(waiting)} of {len(runs)} runs were not running after {timeout_s:g} s "
                "(the workers' capacity, or a machine too loaded)"
            )
        still = []
        for run in waiting:
            record = await get_run(run)
            if record["state"] in END_STATES:
                raise BenchError(
                    f"run {run.run_id} ended at start ({record['state']}): {record.get('reason')}"
                )
            if record["state"] != "running":
                still.append(run)
        waiting = still
        if waiting:
            await asyncio.sleep(STATE_POLL_S)
    return time.monotonic() - started


async def read_live_periods(runs: list[StudentRun], node: str = "controller") -> None:
    """Each run's period over its newest wakes (RunStatus.node_periods, the newest 1000)."""
    for run in runs:
        with contextlib.suppress(httpx.HTTPError):
            period = (await get_run(run)).get("nodes_live", {}).get(node, {}).get("period", {})
            run.live_period_p99_s = period.get("p99_s", math.nan)
            run.live_period_count = period.get("count", 0)


async def stop_runs(runs: list[StudentRun]) -> None:
    async def one(run: StudentRun) -> None:
        with contextlib.suppress(httpx.HTTPError):
            await run.student.web.client.post(
                f"/api/runs/{run.run_id}/stop", headers=bearer(run.student.token)
            )

    await asyncio.gather(*(one(run) for run in runs))


async def wait_ended(runs: list[StudentRun], timeout_s: float) -> None:
    """Until every run has ended (its record in run.record); those that did not in time keep
    their last record and count as lost."""
    deadline = time.monotonic() + timeout_s
    waiting = list(runs)
    while waiting and time.monotonic() < deadline:
        still = []
        for run in waiting:
            with contextlib.suppress(httpx.HTTPError):
                run.record = await get_run(run)
            if run.state not in END_STATES:
                still.append(run)
        waiting = still
        if waiting:
            await asyncio.sleep(STATE_POLL_S)


def lost(runs: list[StudentRun], stopped_by_us: bool) -> list[str]:
    """Runs that did not end as asked: finished at their duration, or interrupted by our stop."""
    problems = []
    for run in runs:
        reason = run.record.get("reason", "")
        fine = run.state == "finished" or (
            stopped_by_us and run.state == "interrupted" and STOPPED_REASON in reason
        )
        if not fine:
            problems.append(f"{run.run_id[:8]} {run.state or 'no answer'}: {reason}")
    return problems


# ------------------------------------------------------------------------------ a live viewer
@dataclass
class ViewerStats:
    settled: asyncio.Event = field(default_factory=asyncio.Event)  # subscribed, or gave up
    subscribed: bool = False
    frames: int = 0
    dropped: int = 0  # samples the server overwrote before this viewer was sent one
    delivery_s: array = field(default_factory=lambda: array("d"))  # production -> read
    commands_s: array = field(default_factory=lambda: array("d"))  # button sent -> ack read
    command_errors: int = 0
    ended: str | None = None  # the run's end state and reason, if it ended while watched
    error: str | None = None


async def watch(
    run: StudentRun, rate_hz: float, window: Window, stats: ViewerStats, command_every_s: float
) -> None:
    """One student's live view of their run: subscribed to Distance at `rate_hz`, pressing
    and releasing the robot's button every `command_every_s` (0: never) and timing the ack."""
    uri = f"{run.student.web.ws_url}/api/runs/{run.run_id}/live?token={run.student.token}"
    sent: dict[int, float] = {}
    try:
        # No client pings: a pong late under load would close a healthy socket.
        async with connect(uri, open_timeout=READY_TIMEOUT_S, ping_interval=None) as ws:
            await ws.send(
                json.dumps({"id": 0, "op": "subscribe", "topic": TOPIC, "max_rate_hz": rate_hz})
            )
            presser = None
            if command_every_s > 0:
                presser = asyncio.create_task(_press_button(ws, command_every_s, sent))
            try:
                await _read_frames(ws, window, stats, sent)
            finally:
                if presser is not None:
                    presser.cancel()
    except (OSError, TimeoutError, WebSocketException) as error:
        stats.error = f"{type(error).__name__}: {error}"
    finally:
        stats.settled.set()


async def _press_button(ws, every_s: float, sent: dict[int, float]) -> None:
    await asyncio.sleep(random.uniform(0.0, every_s))  # students do not press in step
    request_id = 0
    while True:
        request_id += 1
        sent[request_id] = time.monotonic()
        press = {"id": request_id, "op": "button", "pressed": request_id % 2 == 1}
        await ws.send(json.dumps(press))
        await asyncio.sleep(every_s)


async def _read_frames(ws, window: Window, stats: ViewerStats, sent: dict[int, float]) -> None:
    async for text in ws:
        arrival_mono, arrival_wall = time.monotonic(), time.time()
        frame = json.loads(text)
        kind = frame.get("type")
        if kind == "telemetry":
            if arrival_mono in window:
                stats.frames += 1
                stats.dropped += frame.get("dropped", 0)
                if "wall_s" in frame:
                    stats.delivery_s.append(arrival_wall - frame["wall_s"])
        elif kind in ("ack", "error") and frame.get("id") == 0:
            if kind == "error":
                stats.error = f"the subscription was refused: {frame.get('detail')}"
                return
            stats.subscribed = True
            stats.settled.set()
        elif kind in ("ack", "error") and frame.get("id") in sent:
            sent_s = sent.pop(frame["id"])
            if sent_s in window:
                if kind == "ack":
                    stats.commands_s.append(arrival_mono - sent_s)
                else:
                    stats.command_errors += 1
        elif kind == "end":
            stats.ended = f"{frame.get('state')}: {frame.get('reason')}"
            return


async def wait_viewers(viewers: list[ViewerStats]) -> None:
    settled = asyncio.gather(*(stats.settled.wait() for stats in viewers))
    with contextlib.suppress(TimeoutError):
        await asyncio.wait_for(settled, READY_TIMEOUT_S)
    unready = [stats for stats in viewers if not stats.subscribed]
    if unready:
        first = unready[0].error or unready[0].ended or "no answer"
        raise BenchError(
            f"{len(unready)} of {len(viewers)} viewers were not subscribed after "
            f"{READY_TIMEOUT_S:g} s; first: {first}"
        )
