"""The bench as a cluster's web process sees it (issue 16, hardware): `RemoteBench` stands where
`robodojo serve` alone holds a HardwareHub (app.state.hardware), with what the routes and the
run service call of it, so they are the same in both modes:

    bench = RemoteBench(settings)          # chosen by bench_for(store, settings) when redis_url
    bench.health("crowbot-1")              # RobotHealth from the bench worker's snapshot
    bench.link("crowbot-1")                # a presence (not None) while it is connected there
    bench.queue("crowbot-1").join(user_id, now_s)  # asked of the bench worker over Redis

Health comes from the bench workers' snapshots (server/workers/bench.py), which expire: a bench
worker that vanished reads as "not connected" within SNAPSHOT_TTL_S. Queue operations go to the
bench worker holding the robot (else the first bench worker up) and come back with the same
answers and the same refusals (QueueError, the same sentences). A robot's run is stopped at the
end of its slot by the bench worker itself (it holds the run), so `listen` is a no-op here.
"""

from __future__ import annotations

import json
import logging
import threading
import time
from dataclasses import dataclass
from typing import Any

import redis

from server.hardware.health import STALE_AFTER_S, HealthState, RobotHealth, assess
from server.hardware.queue import QueueError, SlotState
from server.workers import queue as run_queue
from server.workers.bench import (
    ASK_TIMEOUT_S,
    BENCHES_KEY,
    BenchWireError,
    answer_from_json,
    ask_channel,
    new_request,
    request_to_json,
    snapshot_key,
)
from server.workers.redis_live import answer_key
from server.workers.seams import ExecutorUnavailableError

log = logging.getLogger("robodojo.workers.bench")

SNAPSHOTS_FRESH_S = 0.5  # [s] a web process reads the snapshots at most this often per request
NO_BENCH = (
    "no bench worker is running: start `robodojo worker --rosserial-port 11411` on the machine "
    "the robots connect to"
)


class BenchUnavailableError(ExecutorUnavailableError):
    """The bench worker cannot be reached (gone, or Redis is away); the API answers 503."""


def bench_for(store, settings):
    """What a web process holds as `app.state.hardware`: the robots' hub itself when it is the
    lab's only process, the bench workers' view through Redis in a cluster."""
    if settings.redis_url:
        return RemoteBench(settings)
    from server.service.hardware import HardwareHub

    return HardwareHub(store, settings)


@dataclass(frozen=True, slots=True)
class RemotePlace:
    """A place in a robot's queue as the bench answered it (server/hardware/queue.py Place)."""

    user_id: str
    state: SlotState
    offered_until_s: float | None  # the bench's clock: only whether it is set means anything
    run_id: str | None


@dataclass(frozen=True, slots=True)
class RemoteLink:
    """A robot connected to a bench worker: the run service only checks that there is one."""

    name: str
    worker: str
    connected: bool = True


class RemoteQueue:
    """A robot's fair queue on its bench worker, with RobotQueue's methods the web side calls.
    The `now_s` arguments are ignored: the bench's clock is the queue's."""

    def __init__(self, bench: RemoteBench, robot: str) -> None:
        self.bench = bench
        self.robot = robot
        self.slot_s = bench.settings.hardware_slot_s
        self.start_within_s = bench.settings.hardware_start_within_s

    def join(self, user_id: str, now_s: float = 0.0) -> RemotePlace:
        value = self.bench.ask(self.robot, "join", user_id=user_id)
        self.start_within_s = value.get("start_within_s", self.start_within_s)
        return _place(value)

    def leave(self, user_id: str, now_s: float = 0.0) -> None:
        self.bench.ask(self.robot, "leave", user_id=user_id)

    def start(self, user_id: str, run_id: str, now_s: float = 0.0) -> RemotePlace:
        return _place(self.bench.ask(self.robot, "start", user_id=user_id, run_id=run_id))

    def finish(self, run_id: str, now_s: float = 0.0) -> None:
        self.bench.ask(self.robot, "finish", run_id=run_id)

    def move(self, user_id: str, position: int, now_s: float = 0.0) -> None:
        self.bench.ask(self.robot, "move", user_id=user_id, position=position)

    def skip(self, user_id: str, now_s: float = 0.0) -> None:
        self.bench.ask(self.robot, "skip", user_id=user_id)

    def set_in_service(self, in_service: bool, now_s: float = 0.0) -> None:
        self.bench.ask(self.robot, "set_in_service", in_service=in_service)

    def tick(self, now_s: float = 0.0) -> list[str]:
        return []  # the bench ticks its queues itself

    # Reads: with no bench reachable the robot has no queue to show (it is not connected
    # either); the page shows it empty instead of failing.
    def describe(self, now_s: float = 0.0) -> dict:
        try:
            return self.bench.ask(self.robot, "describe")
        except BenchUnavailableError as error:
            return {
                "robot": self.robot,
                "in_service": True,
                "slot_s": self.slot_s,
                "start_within_s": self.start_within_s,
                "passed_on": 0,
                "places": [],
                "unavailable": str(error),
            }

    def position(self, user_id: str) -> int | None:
        try:
            return self.bench.ask(self.robot, "position", user_id=user_id)
        except BenchUnavailableError:
            return None

    def estimated_wait_s(self, user_id: str, now_s: float = 0.0) -> float:
        return float(self.bench.ask(self.robot, "estimated_wait_s", user_id=user_id))


def _place(value: dict) -> RemotePlace:
    return RemotePlace(
        value["user_id"], SlotState(value["state"]), value.get("offered_until_s"),
        value.get("run_id"),
    )  # fmt: skip


class RemoteBench:
    """HardwareHub's face for the routes and the run service, backed by the bench workers."""

    def __init__(self, settings, client: redis.Redis | None = None) -> None:
        self.settings = settings
        self.client = client or run_queue.redis_client(settings.redis_url)
        self._own_client = client is None
        self._lock = threading.Lock()
        self._read_s = 0.0
        self._snapshots: dict[str, dict] = {}

    def start(self) -> None:
        pass  # nothing listens here: the bench worker holds the robots

    def stop(self) -> None:
        if self._own_client:
            self.client.close()

    def listen(self, listener) -> None:
        pass  # a run past its slot is stopped by the bench worker that holds it

    # ------------------------------------------------------------------------------ snapshots
    def snapshots(self) -> dict[str, dict]:
        """The live bench workers' snapshots by worker id (read at most every
        SNAPSHOTS_FRESH_S); {} when none is up or Redis is away."""
        with self._lock:
            if time.monotonic() - self._read_s < SNAPSHOTS_FRESH_S:
                return self._snapshots
        found: dict[str, dict] = {}
        try:
            ids = sorted(m.decode() for m in self.client.smembers(BENCHES_KEY))
            raws = self.client.mget([snapshot_key(i) for i in ids]) if ids else []
            for worker, raw in zip(ids, raws, strict=True):
                if raw is None:  # expired: that bench worker is gone
                    self.client.srem(BENCHES_KEY, worker)
                    continue
                try:
                    found[worker] = json.loads(raw)
                except ValueError:
                    log.warning("bench %s: its snapshot is unreadable", worker)
        except redis.RedisError as error:
            log.warning("the bench's snapshots cannot be read (%s)", error)
        with self._lock:
            self._snapshots, self._read_s = found, time.monotonic()
        return found

    def _holder(self, name: str) -> tuple[str | None, dict | None]:
        """The bench worker holding `name` (connected there, or its queue is there), and the
        robot's entry in its snapshot."""
        snapshots = self.snapshots()
        held = [(w, s["robots"][name]) for w, s in snapshots.items() if name in s.get("robots", {})]
        connected = [(w, r) for w, r in held if r.get("state") != str(HealthState.DISCONNECTED)]
        for worker, robot in connected or held:
            return worker, robot
        return (min(snapshots), None) if snapshots else (None, None)

    def health(self, name: str) -> RobotHealth:
        worker, robot = self._holder(name)
        if worker is None:
            return assess(None, [NO_BENCH])
        if robot is None or robot.get("state") == str(HealthState.DISCONNECTED):
            return assess(None)
        state = HealthState(robot["state"])
        at = robot.get("last_heard_at")
        ago = None if at is None else max(0.0, time.time() - at)
        if state is HealthState.CONNECTED and (ago is None or ago > STALE_AFTER_S):
            state = HealthState.STALE  # between two snapshots the robot fell silent
        return RobotHealth(state, ago, at, tuple(robot.get("problems") or ()))

    def connection_state(self, name: str) -> str:
        return self.health(name).sentence

    def link(self, name: str) -> RemoteLink | None:
        worker, robot = self._holder(name)
        if worker is None or robot is None or robot.get("state") == "disconnected":
            return None
        return RemoteLink(name, worker)

    def problems(self) -> dict[str, list[str]]:
        snapshots = self.snapshots()
        if not snapshots:
            return {"bench": [NO_BENCH]}
        found: dict[str, list[str]] = {}
        for snapshot in snapshots.values():
            for name, problems in (snapshot.get("problems") or {}).items():
                found.setdefault(name, []).extend(problems)
        return found

    @property
    def port(self) -> int | None:
        ports = [s.get("port") for s in self.snapshots().values() if s.get("port") is not None]
        return ports[0] if ports else None

    @property
    def listen_error(self) -> str:
        snapshots = self.snapshots()
        if not snapshots:
            return NO_BENCH
        if any(s.get("port") is not None for s in snapshots.values()):
            return ""
        return "; ".join(s.get("listen_error") or "not listening" for s in snapshots.values())

    def queue(self, name: str) -> RemoteQueue:
        return RemoteQueue(self, name)

    # ------------------------------------------------------------------------------ asking
    def ask(self, robot: str, op: str, **args: Any) -> Any:
        """One queue operation on the bench worker holding `robot`: its value, QueueError with
        the queue's sentence, or BenchUnavailableError when no bench worker answers."""
        worker, _ = self._holder(robot)
        if worker is None:
            raise BenchUnavailableError(f"the robots' queues cannot be reached: {NO_BENCH}")
        request = new_request(robot, op, **args)
        payload = request_to_json(request)
        try:
            receivers = self.client.publish(ask_channel(worker), payload)
            reply = None
            if receivers:
                reply = self.client.blpop([answer_key(request.request_id)], timeout=ASK_TIMEOUT_S)
        except redis.RedisError as error:
            raise BenchUnavailableError(
                f"the robots' queues cannot be reached: the lab's message service (Redis) is "
                f"away ({error}); try again in a moment"
            ) from None
        if reply is None:
            with self._lock:
                self._read_s = 0.0  # read the snapshots again: that bench may be gone
            raise BenchUnavailableError(
                f"the bench worker {worker} did not answer; try again in a moment, and tell your "
                "instructor if it keeps happening"
            )
        try:
            answer = answer_from_json(reply[1])
        except BenchWireError as error:
            raise BenchUnavailableError(f"the bench worker answered nonsense ({error})") from None
        if answer.queue_error is not None:
            raise QueueError(answer.queue_error)
        if answer.error is not None:
            raise BenchUnavailableError(answer.error)
        return answer.value
