"""A run's live traffic and commands between workers and web processes, through Redis (issue 16).

Keys and channels (all under "robodojo:"), per run:

    live:<run_id>       PUBLISH {"seq", "batch"}: every LiveBatch, as the worker's host makes it
    run:<run_id>        hash {seq, status, final}: the newest status and the newest batch's seq
    latest:<run_id>     hash topic -> the newest sample: a viewer that starts mid-run sees it
    events:<run_id>     stream of {seq, events, final}: the recent events (capped)
    cmd:<run_id>        PUBLISH a CommandRequest; only the worker holding the run subscribes
    answer:<request_id> LPUSH the CommandAnswer (expires); the web process BLPOPs it

A worker's publisher round (every run's batch) goes in one MULTI/EXEC, so a web process reading
the three keys (also in one MULTI) sees the run as of one batch, and skips published batches it
already has by their seq.
Everything expires: a worker that died leaves nothing behind for long.

    outlet = RedisOutlet(client)                 # worker: RunHost(..., outlet=outlet)
    answer = send_command(client, run_id, Pause())   # web: None when no worker holds the run
"""

from __future__ import annotations

import logging
import threading
import time
import uuid
from collections.abc import Callable, Sequence
from typing import Any

import redis

from server.runs.commands import RunCommand
from server.workers.redis_channels import ChannelListener
from server.workers.seams import ExecutorUnavailableError
from server.workers.wire import (
    CommandAnswer,
    CommandRequest,
    LiveBatch,
    WireError,
    answer_from_json,
    answer_to_json,
    batch_from_json,
    batch_to_json,
    dumps,
    loads,
    request_from_json,
    request_to_json,
)

log = logging.getLogger("robodojo.workers.live")

PREFIX = "robodojo:"

# Limits of the live traffic, each with why.
LIVE_TTL_S = 30  # [s] a running run's keys, renewed by every batch: a dead worker's vanish
KEEP_AFTER_END_S = 300  # [s] an ended run's keys: a viewer reconnecting after a blip sees the end
EVENT_BATCHES_KEPT = 1000  # stream entries (batches with events) kept for late viewers
ANSWER_TTL_S = 30  # [s] an answer nobody popped (its asker gave up) disappears
COMMAND_ANSWER_TIMEOUT_S = 3.0  # [s] a worker that holds the run answers in milliseconds
END_SEQ = 2**53  # the seq of an end published by a reaper: newer than anything the worker sent
HOLD_WAIT_S = 2.0  # [s] longest wait for Redis to confirm a subscription
LOG_EVERY_S = 30.0  # [s] at most one "Redis is away" line per this long per outlet


def live_channel(run_id: str) -> str:
    return f"{PREFIX}live:{run_id}"


def command_channel(run_id: str) -> str:
    return f"{PREFIX}cmd:{run_id}"


def run_key(run_id: str) -> str:
    return f"{PREFIX}run:{run_id}"


def latest_key(run_id: str) -> str:
    return f"{PREFIX}latest:{run_id}"


def events_key(run_id: str) -> str:
    return f"{PREFIX}events:{run_id}"


def answer_key(request_id: str) -> str:
    return f"{PREFIX}answer:{request_id}"


def run_id_of(channel: bytes | str, prefix: str) -> str:
    text = channel.decode() if isinstance(channel, bytes) else channel
    return text[len(prefix) :]


# ------------------------------------------------------------------------------ worker side
class RedisOutlet:
    """A worker's LiveOutlet: each round's batches published and kept (newest status, newest
    sample per topic, recent events) in one MULTI/EXEC, one round trip for every run of the
    worker. Never raises: a batch JSON refuses is left out and logged; while Redis is away
    batches are dropped (the run goes on; its end is in the database) and that is logged now
    and then."""

    def __init__(self, client: redis.Redis) -> None:
        self.client = client
        self._seqs: dict[str, int] = {}
        self._lock = threading.Lock()
        self._last_complaint = 0.0
        self.dropped = 0  # batches lost while Redis was away

    def publish(self, batch: LiveBatch) -> None:
        self.publish_round([batch])

    def publish_round(self, batches: Sequence[LiveBatch]) -> None:
        pipe = self.client.pipeline(transaction=True)
        queued = 0
        for batch in batches:
            with self._lock:
                seq = self._seqs.get(batch.run_id, 0) + 1
                if batch.final:
                    self._seqs.pop(batch.run_id, None)
                else:
                    self._seqs[batch.run_id] = seq
            try:
                queue_batch(pipe, batch, seq)
            except ValueError as error:  # a NaN: this batch cannot go, the others can
                log.error(
                    "run %s: a live batch is not JSON and was dropped: %s", batch.run_id, error
                )
                continue
            queued += 1
        if not queued:
            return
        try:
            pipe.execute()
        except redis.RedisError as error:
            self.dropped += queued
            now = time.monotonic()
            if now - self._last_complaint > LOG_EVERY_S:
                self._last_complaint = now
                log.warning(
                    "live traffic of %d runs not sent: Redis is away (%s); runs go on, viewers "
                    "catch up when it is back",
                    queued,
                    error,
                )


def write_batch(client: redis.Redis, batch: LiveBatch, seq: int) -> None:
    """Publish one batch and keep what a late viewer needs, in one MULTI/EXEC."""
    pipe = client.pipeline(transaction=True)
    queue_batch(pipe, batch, seq)
    pipe.execute()


def queue_batch(pipe: redis.client.Pipeline, batch: LiveBatch, seq: int) -> None:
    """Queue on `pipe` one batch's publication and what a late viewer needs of it. Raises
    ValueError (and queues nothing) when the batch is not JSON (a NaN)."""
    run_id = batch.run_id
    ttl = KEEP_AFTER_END_S if batch.final else LIVE_TTL_S
    data = batch_to_json(batch)
    published = dumps({"seq": seq, "batch": data})  # first: a NaN anywhere refuses it here
    fields: dict[str, Any] = {"seq": seq}
    if data["status"] is not None:
        fields["status"] = dumps(data["status"])
    if batch.final:
        fields["final"] = 1
    # [topic, type, time_ns, base64, wall_s, skipped] each
    latest = {s[0]: dumps(s) for s in data["samples"]}
    pipe.publish(live_channel(run_id), published)
    pipe.hset(run_key(run_id), mapping=fields)
    if latest:
        pipe.hset(latest_key(run_id), mapping=latest)
    if batch.events or batch.final:
        entry = {"seq": seq, "events": dumps({"e": list(batch.events)}), "final": int(batch.final)}
        pipe.xadd(events_key(run_id), entry, maxlen=EVENT_BATCHES_KEPT, approximate=True)
    for key in (run_key(run_id), latest_key(run_id), events_key(run_id)):
        pipe.expire(key, ttl)  # renewed while the run sends; a dead worker's keys vanish


def publish_end(client: redis.Redis, run_id: str, state: str, reason: str) -> None:
    """Tell every viewer of a run that it ended, from wherever its end was decided (the reaper
    of a worker that was lost): a final batch newer than anything its worker sent."""
    event = {"type": "state", "state": state, "reason": reason, "time_s": 0.0}
    write_batch(client, LiveBatch(run_id, events=(event,), final=True), END_SEQ)


def answer(client: redis.Redis, request_id: str, reply: CommandAnswer) -> None:
    pipe = client.pipeline(transaction=False)
    pipe.lpush(answer_key(request_id), dumps(answer_to_json(reply)))
    pipe.expire(answer_key(request_id), ANSWER_TTL_S)
    pipe.execute()


# ------------------------------------------------------------------------------ web side
def read_snapshot(client: redis.Redis, run_id: str, after_seq: int) -> tuple[LiveBatch | None, int]:
    """What a web process that starts watching mid-run (or after a Redis blip) needs: the
    newest status, the newest sample of every topic and the events after `after_seq`, as one
    batch, with the seq it is current to. (None, after_seq) when Redis has nothing of the run
    (not started yet, or its keys expired)."""
    pipe = client.pipeline(transaction=True)
    pipe.hgetall(run_key(run_id))
    pipe.hgetall(latest_key(run_id))
    pipe.xrange(events_key(run_id))
    meta, latest, entries = pipe.execute()
    if not meta:
        return None, after_seq
    seq = int(meta.get(b"seq", 0))
    events: list[dict] = []
    final = bool(int(meta.get(b"final", 0)))
    for _id, fields in entries:
        entry_seq = int(fields.get(b"seq", 0))
        if entry_seq <= after_seq:
            continue
        events.extend(loads(fields.get(b"events", b'{"e": []}')).get("e", []))
    samples = [_sample(topic, raw) for topic, raw in latest.items()]
    status = meta.get(b"status")
    data = {
        "run_id": run_id,
        "samples": [s for s in samples if s is not None],
        "events": events,
        "status": loads(status) if status else None,
        "final": final,
    }
    try:
        return batch_from_json(data), max(seq, after_seq)
    except WireError as error:
        log.warning("run %s: its live snapshot in Redis is unreadable: %s", run_id, error)
        return None, after_seq


def _sample(topic: bytes, raw: bytes) -> list | None:
    try:
        sample = loads(raw)
    except WireError:
        return None
    if not isinstance(sample, list) or len(sample) != 6:
        return None
    sample[0] = topic.decode(errors="replace")  # the hash's field names the topic
    return sample


def parse_published(raw: bytes) -> tuple[int, LiveBatch]:
    """A message on a run's live channel: (seq, batch); WireError when it is not one."""
    data = loads(raw)
    if not isinstance(data, dict) or not isinstance(data.get("seq"), int):
        raise WireError("a live message lacks its seq")
    return data["seq"], batch_from_json(data.get("batch"))


def send_command(
    client: redis.Redis,
    run_id: str,
    command: RunCommand,
    timeout_s: float = COMMAND_ANSWER_TIMEOUT_S,
) -> CommandAnswer | None:
    """Deliver a command to whichever worker holds the run and wait for its answer. None when
    no worker holds it (not started yet, or over); ExecutorUnavailableError when Redis is away
    or the worker did not answer in time."""
    request = CommandRequest(uuid.uuid4().hex, run_id, command)
    try:
        receivers = client.publish(command_channel(run_id), dumps(request_to_json(request)))
        if receivers == 0:
            return None
        reply = client.blpop([answer_key(request.request_id)], timeout=timeout_s)
    except redis.RedisError as error:
        raise ExecutorUnavailableError(
            f"the command could not reach the run: the lab's message service (Redis) is away "
            f"({error}); try again in a moment"
        ) from None
    if reply is None:
        raise ExecutorUnavailableError(
            f"the worker running this run did not answer within {timeout_s:g} s; try again"
        )
    return answer_from_json(loads(reply[1]))


# ------------------------------------------------------------------------------ listeners
class CommandListener:
    """A worker's ear for commands: subscribed to `cmd:<run_id>` for each run it holds, it
    answers each request with `handle(request)` (RunHost.command) on its own thread."""

    def __init__(self, client: redis.Redis, handle: Callable[[CommandRequest], CommandAnswer]):
        self.client = client
        self.handle = handle
        self.listener = ChannelListener(client, self._on_message, name="commands")

    def start(self) -> None:
        self.listener.start()

    def stop(self) -> None:
        self.listener.stop()

    def hold(self, run_id: str, wait_s: float = HOLD_WAIT_S) -> bool:
        """Listen for the run's commands; True once Redis confirmed (False: Redis is away, the
        run goes on and commands reach it when Redis is back)."""
        return self.listener.add(command_channel(run_id), wait_s=wait_s)

    def release(self, run_id: str) -> None:
        self.listener.remove(command_channel(run_id))

    def _on_message(self, channel: str, raw: bytes) -> None:
        try:
            request = request_from_json(loads(raw))
        except WireError as error:
            log.warning("a command on %s was not understood and is ignored: %s", channel, error)
            return
        if request.run_id != run_id_of(channel, command_channel("")):
            log.warning("a command for run %s came on %s; ignored", request.run_id, channel)
            return
        reply = self.handle(request)
        try:
            answer(self.client, request.request_id, reply)
        except redis.RedisError as error:
            log.warning("run %s: a command's answer was lost (%s)", request.run_id, error)


class LiveSubscriber:
    """A web process's ear for live traffic: subscribed on demand to the runs someone watches
    here, it hands every batch, in order and once, to `apply` (the web side's mirror). On each
    (re)subscription it first applies what Redis keeps of the run (newest status and samples,
    events since the last it had), so a viewer starting mid-run or after a Redis restart
    misses nothing that is still kept. After a run's final batch it stops listening."""

    def __init__(self, client: redis.Redis, apply: Callable[[LiveBatch], None]) -> None:
        self.client = client
        self.apply = apply
        self._seqs: dict[str, int] = {}  # run -> seq of the newest batch applied
        self._ended: dict[str, float] = {}  # run -> monotonic time its final batch came
        self._lock = threading.Lock()
        self.listener = ChannelListener(
            client, self._on_message, name="live", on_subscribed=self._catch_up
        )

    def start(self) -> None:
        self.listener.start()

    def stop(self) -> None:
        self.listener.stop()

    @property
    def connected(self) -> bool:
        return self.listener.connected

    def watch(self, run_id: str, wait_s: float = HOLD_WAIT_S) -> bool:
        """Start following a run (once; again after it ended is a no-op). True when Redis has
        confirmed and what it keeps of the run was applied."""
        with self._lock:
            self._forget_ended(time.monotonic())
            if run_id in self._ended:
                return True
            self._seqs.setdefault(run_id, 0)
        return self.listener.add(live_channel(run_id), wait_s=wait_s)

    def watching(self) -> list[str]:
        return [run_id_of(c, live_channel("")) for c in self.listener.wanted()]

    def forget(self, run_id: str) -> None:
        """Stop following a run and forget it (its mirror is gone)."""
        self.listener.remove(live_channel(run_id))
        with self._lock:
            self._seqs.pop(run_id, None)
            self._ended.pop(run_id, None)

    def _forget_ended(self, now: float) -> None:  # with self._lock held
        for run_id in [r for r, t in self._ended.items() if now - t > KEEP_AFTER_END_S]:
            del self._ended[run_id]

    def _catch_up(self, channel: str) -> None:  # listener thread, after each subscription
        run_id = run_id_of(channel, live_channel(""))
        with self._lock:
            after = self._seqs.get(run_id, 0)
        batch, seq = read_snapshot(self.client, run_id, after)
        if batch is not None:
            self._take(run_id, seq, batch)

    def _on_message(self, channel: str, raw: bytes) -> None:  # listener thread
        try:
            seq, batch = parse_published(raw)
        except WireError as error:
            log.warning("a live message on %s is unreadable and ignored: %s", channel, error)
            return
        if batch.run_id != run_id_of(channel, live_channel("")):
            return
        self._take(batch.run_id, seq, batch)

    def _take(self, run_id: str, seq: int, batch: LiveBatch) -> None:
        with self._lock:
            if run_id in self._ended or seq <= self._seqs.get(run_id, 0):
                return  # already applied (through the snapshot), or over
            if batch.final:
                self._seqs.pop(run_id, None)
                self._ended[run_id] = time.monotonic()
            else:
                self._seqs[run_id] = seq
        self.apply(batch)
        if batch.final:
            self.listener.remove(live_channel(run_id))
