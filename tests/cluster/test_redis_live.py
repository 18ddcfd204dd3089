"""Live traffic and commands through a private Redis: batches reach a web process in order and
once, a viewer that starts mid-run gets what Redis keeps, commands reach the worker holding the
run and come back answered, garbage on the channels is ignored, and a Redis restart is
survived (listeners reconnect; commands while it is down get a sentence, never a hang)."""

from __future__ import annotations

import logging
import math
import threading
import time

import pytest
import redis

from server.runs.commands import Button, Pause, Stop
from server.workers.queue import redis_client
from server.workers.redis_channels import ChannelListener
from server.workers.redis_live import (
    CommandListener,
    LiveSubscriber,
    RedisOutlet,
    command_channel,
    latest_key,
    live_channel,
    publish_end,
    read_snapshot,
    run_key,
    send_command,
)
from server.workers.seams import ExecutorUnavailableError
from server.workers.wire import CommandAnswer, CommandRequest, LiveBatch, RunStatus, Sample
from tests.waiting import wait_until

pytestmark = pytest.mark.slow


def status(run_id: str, state: str = "running", time_s: float = 1.0) -> RunStatus:
    return RunStatus(
        run_id=run_id,
        state=state,
        reason="",
        time_s=time_s,
        ros_version=1,
        node_periods={"controller": {"p50_ms": 10.0}},
        sandbox_processes=1,
        logs={"controller": ["hello"]},
        graph={"nodes": [], "topics": []},
        lights=None,
        worker="host:1",
        wall_s=time.time(),
    )


def sample(topic: str, value: int) -> Sample:
    return Sample(topic, "std_msgs/Int32", value * 1_000_000, value.to_bytes(4, "little"),
                  time.time())  # fmt: skip


class Applied:
    """What a web process's mirror was given, in order."""

    def __init__(self) -> None:
        self.batches: list[LiveBatch] = []
        self.lock = threading.Lock()

    def __call__(self, batch: LiveBatch) -> None:
        with self.lock:
            self.batches.append(batch)

    def events(self) -> list[dict]:
        with self.lock:
            return [event for batch in self.batches for event in batch.events]

    def samples(self, topic: str) -> list[bytes]:
        with self.lock:
            return [s.data for b in self.batches for s in b.samples if s.topic == topic]


@pytest.fixture
def client(private_redis):
    made = redis_client(private_redis.url)
    yield made
    made.close()


@pytest.fixture
def subscriber(client):
    applied = Applied()
    made = LiveSubscriber(client, applied)
    made.applied = applied  # type: ignore[attr-defined]
    made.start()
    yield made
    made.stop()


def test_batches_reach_a_watcher_in_order_once_and_it_stops_after_the_final(client, subscriber):
    outlet = RedisOutlet(client)
    assert subscriber.watch("run1", wait_s=30.0)
    for n in range(1, 21):
        line = {"type": "log", "node": "c", "line": f"line {n}"}
        outlet.publish(LiveBatch("run1", samples=(sample("Distance", n),), events=(line,)))
    outlet.publish(LiveBatch("run1", events=({"type": "state", "state": "finished"},),
                             status=status("run1", "finished"), final=True))  # fmt: skip
    applied = subscriber.applied
    wait_until(lambda: any(b.final for b in applied.batches), 10, "the final batch arrived")
    lines = [e["line"] for e in applied.events() if e["type"] == "log"]
    assert lines == [f"line {n}" for n in range(1, 21)]
    assert applied.samples("Distance") == [n.to_bytes(4, "little") for n in range(1, 21)]
    wait_until(lambda: client.pubsub_numsub(live_channel("run1"))[0][1] == 0, 10,
               "it stopped listening")  # fmt: skip
    assert "run1" not in subscriber.watching()
    outlet.publish(LiveBatch("run1", events=({"type": "log", "line": "after the end"},)))
    time.sleep(0.2)  # nothing may arrive: this wait is the behaviour under test
    assert "after the end" not in str(applied.events())


def test_a_round_of_many_runs_goes_in_one_transaction_and_a_bad_batch_stays_out(
    client, subscriber, caplog
):
    outlet = RedisOutlet(client)
    for run_id in ("runA", "runB", "runC"):
        assert subscriber.watch(run_id, wait_s=30.0)
    bad = LiveBatch("runB", events=({"type": "log", "line": "x", "gain": math.nan},))
    with caplog.at_level(logging.ERROR, logger="robodojo.workers.live"):
        outlet.publish_round([
            LiveBatch("runA", samples=(sample("Distance", 1),)),
            bad,
            LiveBatch("runC", samples=(sample("Distance", 3),), status=status("runC")),
        ])  # fmt: skip
    applied = subscriber.applied
    wait_until(lambda: {b.run_id for b in applied.batches} >= {"runA", "runC"}, 10,
               "the good batches arrived")  # fmt: skip
    assert "run runB: a live batch is not JSON" in caplog.text
    assert not client.exists(run_key("runB"))  # nothing of it was kept either
    assert client.hget(run_key("runC"), "seq") == b"1"
    assert client.ttl(latest_key("runA")) > 0  # everything expires, as for a lone batch
    # The run whose batch was refused goes on: its next batch is published and applied.
    outlet.publish(LiveBatch("runB", events=({"type": "log", "line": "fine again"},)))
    wait_until(lambda: "fine again" in str(applied.events()), 10, "runB's next batch arrived")


def test_a_viewer_starting_mid_run_gets_the_newest_of_everything_then_the_rest(client, subscriber):
    outlet = RedisOutlet(client)
    one = {"type": "log", "line": "one"}
    outlet.publish(LiveBatch("run2", samples=(sample("Distance", 1), sample("Light", 7)),
                             events=(one,), status=status("run2")))  # fmt: skip
    outlet.publish(LiveBatch("run2", samples=(sample("Distance", 2),),
                             events=({"type": "log", "line": "two"},)))  # fmt: skip
    assert subscriber.watch("run2", wait_s=30.0)
    applied = subscriber.applied
    wait_until(lambda: applied.batches, 10, "the snapshot was applied")
    first = applied.batches[0]
    assert {s.topic: s.data for s in first.samples} == {
        "Distance": (2).to_bytes(4, "little"),
        "Light": (7).to_bytes(4, "little"),
    }
    assert [e["line"] for e in first.events] == ["one", "two"]
    assert first.status is not None and first.status.state == "running"
    outlet.publish(LiveBatch("run2", events=({"type": "log", "line": "three"},)))
    wait_until(lambda: len(applied.events()) == 3, 10, "the next batch arrived once")
    assert [e["line"] for e in applied.events()] == ["one", "two", "three"]


def test_snapshot_of_a_run_redis_knows_nothing_of_is_none(client):
    assert read_snapshot(client, "never-ran", 0) == (None, 0)


def test_a_reaped_run_ends_for_its_viewers_even_after_its_worker_vanished(client, subscriber):
    outlet = RedisOutlet(client)
    outlet.publish(LiveBatch("run3", events=({"type": "log", "line": "working"},)))
    assert subscriber.watch("run3", wait_s=30.0)
    publish_end(client, "run3", "failed", "failed: worker lost")
    applied = subscriber.applied
    wait_until(lambda: any(b.final for b in applied.batches), 10, "the end reached the viewer")
    assert applied.events()[-1]["reason"] == "failed: worker lost"
    # And a viewer arriving later still sees how it ended.
    late = Applied()
    other = LiveSubscriber(client, late)
    other.start()
    try:
        assert other.watch("run3", wait_s=30.0)
        # Its catch-up may come as more than one batch (what Redis kept, then the end); what
        # matters is that the end reaches it, last.
        wait_until(lambda: any(b.final for b in late.batches), 10, "the late viewer got the end")
        assert late.batches[-1].final and late.events()[-1]["state"] == "failed"
    finally:
        other.stop()


def test_a_subscription_dropped_by_its_own_catch_up_still_counts_as_confirmed(client):
    # A late viewer's catch-up finds the run over and stops listening at once, on the listener's
    # thread, before the viewer's `add` has looked: the viewer must still hear True, every time
    # (it used to race the unsubscription and time out now and then).
    def drop(channel: str) -> None:
        listener.remove(channel)

    listener = ChannelListener(client, handle=lambda channel, data: None, name="test",
                               on_subscribed=drop)  # fmt: skip
    listener.start()
    try:
        answers = [listener.add(f"robodojo:test:{n}", wait_s=10.0) for n in range(40)]
        assert answers == [True] * 40
        assert listener.wanted() == set()
    finally:
        listener.stop()


def test_a_listener_outlives_a_fault_that_is_not_redis_s_and_confirms_again(
    client, monkeypatch, caplog
):
    # A fault inside the client library (or ours) used to end the listener's thread for good:
    # every later subscription of that process then waited in vain.
    real = redis.client.PubSub.get_message
    faults = [ValueError("a reply the client could not parse")]

    def get_message(self, *args, **kwargs):
        if faults:
            raise faults.pop()
        return real(self, *args, **kwargs)

    monkeypatch.setattr(redis.client.PubSub, "get_message", get_message)
    listener = ChannelListener(client, handle=lambda channel, data: None, name="test")
    with caplog.at_level(logging.ERROR, logger="robodojo.workers.channels"):
        listener.start()
        try:
            assert listener.add("robodojo:test:after-a-fault", wait_s=10.0)
            assert not faults
        finally:
            listener.stop()
    assert "test: the listener failed; starting it again" in caplog.text


@pytest.fixture
def worker_ear(client):
    seen: list[CommandRequest] = []

    def handle(request: CommandRequest) -> CommandAnswer:
        seen.append(request)
        if isinstance(request.command, Pause):
            return CommandAnswer(request.request_id, False, "a realtime run cannot pause")
        return CommandAnswer(request.request_id, True)

    listener = CommandListener(client, handle)
    listener.seen = seen  # type: ignore[attr-defined]
    listener.start()
    yield listener
    listener.stop()


def test_commands_reach_the_worker_holding_the_run_and_come_back_answered(client, worker_ear):
    assert send_command(client, "run4", Stop("by the test")) is None  # nobody holds it yet
    assert worker_ear.hold("run4", wait_s=30.0)
    answer = send_command(client, "run4", Button(pressed=True))
    assert answer is not None and answer.taken
    refused = send_command(client, "run4", Pause())
    assert refused is not None and not refused.taken
    assert refused.refusal == "a realtime run cannot pause"
    assert [type(r.command).__name__ for r in worker_ear.seen] == ["Button", "Pause"]
    worker_ear.release("run4")
    wait_until(lambda: client.pubsub_numsub(command_channel("run4"))[0][1] == 0, 10,
               "the worker stopped listening")  # fmt: skip
    assert send_command(client, "run4", Stop("late")) is None


def test_garbage_on_the_channels_is_ignored_and_the_listeners_go_on(client, worker_ear, subscriber):
    assert worker_ear.hold("run5", wait_s=30.0)
    assert subscriber.watch("run5", wait_s=30.0)
    for junk in (
        b"not json",
        b"[]",
        b'{"request_id": 1}',
        b"\xff\xfe",
        b'{"request_id": "x", "run_id": "other", "command": {"op": "stop"}}',
        b'{"request_id": "x", "run_id": "run5", "command": {"op": "format_disk"}}',
    ):
        client.publish(command_channel("run5"), junk)
        client.publish(live_channel("run5"), junk)  # fmt: skip
    client.publish(live_channel("run5"), b'{"seq": 5, "batch": {"run_id": "someone-else"}}')
    answer = send_command(client, "run5", Stop("still listening"))
    assert answer is not None and answer.taken
    assert [r.run_id for r in worker_ear.seen] == ["run5"]
    RedisOutlet(client).publish(LiveBatch("run5", events=({"type": "log", "line": "ok"},)))
    wait_until(lambda: subscriber.applied.events(), 10, "a real batch still arrived")
    assert [e.get("line") for e in subscriber.applied.events()] == ["ok"]


def test_redis_restarted_listeners_reconnect_and_commands_while_down_get_a_sentence(
    private_redis, client, worker_ear, subscriber
):
    outlet = RedisOutlet(client)
    assert worker_ear.hold("run7", wait_s=30.0)
    assert subscriber.watch("run7", wait_s=30.0)
    outlet.publish(LiveBatch("run7", events=({"type": "log", "line": "before"},)))
    wait_until(lambda: subscriber.applied.events(), 10, "the first batch arrived")

    private_redis.stop()
    started = time.monotonic()
    with pytest.raises(ExecutorUnavailableError, match="Redis"):
        send_command(client, "run7", Stop("while down"))
    assert time.monotonic() - started < 15, "a command while Redis is down must not hang"
    outlet.publish(LiveBatch("run7", events=({"type": "log", "line": "lost"},)))  # no raise
    assert outlet.dropped == 1

    private_redis.start()
    wait_until(lambda: _answers(client, "run7"), 30, "commands reach the worker again")
    outlet.publish(LiveBatch("run7", events=({"type": "log", "line": "after"},)))
    wait_until(lambda: "after" in str(subscriber.applied.events()), 30,
               "live traffic reached the viewer again")  # fmt: skip
    lines = [e["line"] for e in subscriber.applied.events()]
    assert lines == ["before", "after"]  # "lost" was sent while Redis was down


def _answers(client: redis.Redis, run_id: str) -> bool:
    try:
        answer = send_command(client, run_id, Button(pressed=False), timeout_s=1.0)
    except ExecutorUnavailableError:
        return False
    return answer is not None and answer.taken
