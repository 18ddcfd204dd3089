"""The bench in a cluster (issue 16, hardware): the worker that holds the robots' connections.

A real robot connects to one host. `robodojo worker --rosserial-port 11411` on that host makes
a *bench worker*: it holds a HardwareHub (server/service/hardware.py: robots connect to it as
they connect to `robodojo serve`, admitted by their inventory address), takes the Dramatiq queue
`robot.<name>` of every robot it holds (server/workers/queue.py routes a hardware run's job
there), and runs those runs on the robot's own link. The web processes hold no hub; they see the
bench through Redis (server/workers/remote_bench.py):

    robodojo:benches                 set of bench worker ids (stale ids are dropped by readers)
    robodojo:bench:<worker_id>       JSON snapshot, rewritten every SNAPSHOT_PERIOD_S with a TTL:
                                     each robot's health, problems, port, listen error
    robodojo:bench-ask:<worker_id>   PUBLISH a BenchRequest (a robot queue's operation)
    robodojo:answer:<request_id>     LPUSH the BenchAnswer (as commands' answers, redis_live.py)

Where the fair queue's truth lives: HERE, on the bench worker, as today in the one web process.
Why: a RobotQueue is pure and consistent under one lock and one monotonic clock; its tick (an
offered turn passing on, a run past its slot) must stop runs, and the runs on a robot run here;
and a bench worker that is gone has no robot either, so a queue that outlived it would offer
turns nobody can take. A queue in Redis or the database would need optimistic updates of the
whole list and an elected ticker for what one thread does here. The cost: the queue is lost
when the bench worker restarts (as it was when `serve` restarted), and a web process asks the
bench for each operation (a Redis round trip, ~1 ms on a LAN).
"""

from __future__ import annotations

import json
import logging
import threading
import time
import uuid
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import redis

from server.hardware.queue import Place, QueueError
from server.workers.redis_channels import ChannelListener
from server.workers.redis_live import ANSWER_TTL_S, answer_key

log = logging.getLogger("robodojo.workers.bench")

BENCHES_KEY = "robodojo:benches"
# Limits and rhythms of the bench's traffic, each with why.
SNAPSHOT_PERIOD_S = 1.0  # [s] how often the bench rewrites its robots' health
SNAPSHOT_TTL_S = 3  # [s] three missed snapshots: the bench is gone, its robots "not connected"
ASK_TIMEOUT_S = 3.0  # [s] a bench answers a queue operation in milliseconds; this is a dead one
MAX_REQUEST_BYTES = 4096  # a queue operation is a few names and numbers

# The RobotQueue operations a web process may ask for, with their arguments' types. The clock is
# the bench's: a web process's monotonic time means nothing here, so no `now_s` travels.
QUEUE_OPERATIONS: dict[str, dict[str, type]] = {
    "join": {"user_id": str},
    "leave": {"user_id": str},
    "start": {"user_id": str, "run_id": str},
    "finish": {"run_id": str},
    "move": {"user_id": str, "position": int},
    "skip": {"user_id": str},
    "set_in_service": {"in_service": bool},
    "describe": {},
    "position": {"user_id": str},
    "estimated_wait_s": {"user_id": str},
}


def snapshot_key(worker_id: str) -> str:
    return f"robodojo:bench:{worker_id}"


def ask_channel(worker_id: str) -> str:
    return f"robodojo:bench-ask:{worker_id}"


class BenchWireError(ValueError):
    """A bench message that is not one; the message says what is wrong with it."""


@dataclass(frozen=True, slots=True)
class BenchRequest:
    request_id: str
    robot: str
    op: str
    args: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class BenchAnswer:
    request_id: str
    value: Any = None  # JSON: a place as a dict, a description, a position, a wait
    queue_error: str | None = None  # the queue refused: the sentence (QueueError) as is
    error: str | None = None  # anything else that went wrong on the bench, as a sentence


def new_request(robot: str, op: str, **args: Any) -> BenchRequest:
    return BenchRequest(uuid.uuid4().hex, robot, op, args)


def request_to_json(request: BenchRequest) -> str:
    return json.dumps(asdict(request))


def request_from_json(raw: bytes) -> BenchRequest:
    if len(raw) > MAX_REQUEST_BYTES:
        raise BenchWireError(f"a bench request of {len(raw)} bytes is over {MAX_REQUEST_BYTES}")
    try:
        data = json.loads(raw)
    except ValueError as error:
        raise BenchWireError(f"a bench request is not JSON ({error})") from None
    if not isinstance(data, dict):
        raise BenchWireError("a bench request is not an object")
    op, robot, request_id, args = data.get("op"), data.get("robot"), data.get("request_id"), (
        data.get("args")
    )  # fmt: skip
    if not isinstance(request_id, str) or not isinstance(robot, str) or not robot:
        raise BenchWireError("a bench request lacks its request_id or robot")
    wanted = QUEUE_OPERATIONS.get(op) if isinstance(op, str) else None
    if wanted is None:
        raise BenchWireError(f"{op!r} is no queue operation")
    if not isinstance(args, dict) or set(args) != set(wanted):
        raise BenchWireError(f"{op} takes {sorted(wanted)}")
    for name, kind in wanted.items():
        value = args[name]
        if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
            raise BenchWireError(f"{op}: {name} must be a {kind.__name__}")
    return BenchRequest(request_id, robot, op, args)


def answer_from_json(raw: bytes) -> BenchAnswer:
    try:
        data = json.loads(raw)
        return BenchAnswer(**data)
    except (ValueError, TypeError) as error:
        raise BenchWireError(f"a bench answer is not one ({error})") from None


def place_dict(place: Place) -> dict:
    return asdict(place) | {"state": str(place.state)}


class BenchDesk:
    """The bench worker's side: publishes its robots' health and answers queue operations for
    the robots it holds, on its own threads. `hub` is the HardwareHub; `on_robot(name)` is
    called for each robot it sees (the worker declares the robot's Dramatiq queue)."""

    def __init__(
        self,
        client: redis.Redis,
        hub,
        worker_id: str,
        on_robot: Callable[[str], None] = lambda name: None,
    ) -> None:
        self.client = client
        self.hub = hub
        self.worker_id = worker_id
        self.on_robot = on_robot
        self._seen: set[str] = set()
        self._lock = threading.Lock()  # one queue operation at a time (RobotQueue is not locked)
        self._stop = threading.Event()
        self.listener = ChannelListener(client, self._on_request, name="bench")
        self._thread = threading.Thread(target=self._publish_loop, name="bench", daemon=True)

    def start(self) -> None:
        self.listener.start()
        self.listener.add(ask_channel(self.worker_id), wait_s=2.0)
        self.publish()
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        self.listener.stop()
        try:  # the web processes read "not connected" at once instead of after the TTL
            self.client.delete(snapshot_key(self.worker_id))
            self.client.srem(BENCHES_KEY, self.worker_id)
        except redis.RedisError:
            pass

    # ------------------------------------------------------------------------------ snapshots
    def snapshot(self) -> dict:
        robots = {}
        for name in self.hub.robots():
            health = self.hub.health(name)
            robots[name] = health.as_dict() | {"wall_s": time.time()}
            if name not in self._seen and health.state != "disconnected":
                self._seen.add(name)
                try:
                    self.on_robot(name)
                except Exception:
                    log.exception("bench: could not take the queue of %s", name)
        return {
            "worker": self.worker_id,
            "port": self.hub.port,
            "listen_error": self.hub.listen_error,
            "robots": robots,
            "problems": self.hub.problems(),
            "wall_s": time.time(),
        }

    def publish(self) -> None:
        data = json.dumps(self.snapshot())
        pipe = self.client.pipeline(transaction=True)
        pipe.set(snapshot_key(self.worker_id), data, ex=SNAPSHOT_TTL_S)
        pipe.sadd(BENCHES_KEY, self.worker_id)
        pipe.execute()

    def _publish_loop(self) -> None:
        while not self._stop.wait(SNAPSHOT_PERIOD_S):
            try:
                self.publish()
            except redis.RedisError as error:  # the robots go on; web processes see them again
                log.debug("bench: snapshot not written (%s)", error)
            except Exception:
                log.exception("bench: snapshot failed")

    # ------------------------------------------------------------------------------ queues
    def _on_request(self, channel: str, raw: bytes) -> None:
        try:
            request = request_from_json(raw)
        except BenchWireError as error:
            log.warning("bench: a request was not understood and is ignored: %s", error)
            return
        reply = self.handle(request)
        pipe = self.client.pipeline(transaction=False)
        pipe.lpush(answer_key(request.request_id), json.dumps(asdict(reply)))
        pipe.expire(answer_key(request.request_id), ANSWER_TTL_S)
        try:
            pipe.execute()
        except redis.RedisError as error:
            log.warning("bench: an answer was lost (%s)", error)

    def handle(self, request: BenchRequest) -> BenchAnswer:
        queue, now, args = self.hub.queue(request.robot), time.monotonic(), request.args
        try:
            with self._lock:
                match request.op:
                    case "join":
                        place = queue.join(args["user_id"], now)
                        value = place_dict(place) | {"start_within_s": queue.start_within_s}
                    case "leave":
                        value = queue.leave(args["user_id"], now)
                    case "start":
                        value = place_dict(queue.start(args["user_id"], args["run_id"], now))
                    case "finish":
                        value = queue.finish(args["run_id"], now)
                    case "move":
                        value = queue.move(args["user_id"], args["position"], now)
                    case "skip":
                        value = queue.skip(args["user_id"], now)
                    case "set_in_service":
                        value = queue.set_in_service(args["in_service"], now)
                    case "describe":
                        value = queue.describe(now)
                    case "position":
                        value = queue.position(args["user_id"])
                    case "estimated_wait_s":
                        value = queue.estimated_wait_s(args["user_id"], now)
        except QueueError as error:
            return BenchAnswer(request.request_id, queue_error=str(error))
        except Exception as error:
            log.exception("bench: %s on %s failed", request.op, request.robot)
            sentence = f"the bench could not {request.op} on {request.robot}: {error}"
            return BenchAnswer(request.request_id, error=sentence)
        return BenchAnswer(request.request_id, value)
