"""RunTelemetry and Viewer: rate limits, latest value wins, bounded memory, run-thread wake-ups.

Messages come from a real thread, as from a run's worker; viewers consume on an asyncio loop
started with asyncio.run inside each test.
"""

from __future__ import annotations

import asyncio
import dataclasses
import itertools
import json
import math
import threading
import time
from types import SimpleNamespace

import pytest
from mcap.reader import make_reader

from sandbox import bwrap
from sandbox.launcher import Launcher
from sandbox.limits import DEFAULT_LIMITS
from sandbox.msgs import get_message_class
from sandbox.protocol import Clock
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState
from server.service import telemetry as telemetry_module
from server.service.telemetry import (
    EVENTS_KEPT,
    MAX_RATE_HZ,
    MAX_SUBSCRIPTIONS,
    RATE_BURST,
    RunTelemetry,
    SubscriptionError,
    TelemetryRegistry,
    UnknownRunError,
    Viewer,
    latency_summary,
)

INT32 = "std_msgs/Int32"
Int32 = get_message_class(INT32)
Float64 = get_message_class("std_msgs/Float64")


def int32(value: int) -> bytes:
    return Int32(data=value).serialize()


def finish(telemetry: RunTelemetry, time_s: float = 1.0) -> None:
    """The end of a run's lifecycle, as Run._move reports it."""
    for state in (RunState.STARTING, RunState.RUNNING, RunState.STOPPING):
        telemetry.on_state(state, "", time_s)
    telemetry.on_state(RunState.FINISHED, "finished: duration reached", time_s)


def feed_thread(telemetry: RunTelemetry, count: int, period_s: float, topic: str = "count"):
    """A run thread publishing 0..count-1 on `topic`, then ending the run."""

    def publish() -> None:
        start = time.monotonic()
        for i in range(count):
            telemetry.on_message(topic, INT32, i * 1_000_000, int32(i))
            # Paced against the start, so sleep overshoot does not stretch the run.
            delay = start + (i + 1) * period_s - time.monotonic()
            if delay > 0:
                time.sleep(delay)
        finish(telemetry)

    return threading.Thread(target=publish, name="run-thread", daemon=True)


async def drain(viewer: Viewer, limit_s: float = 10.0) -> list[tuple[float, dict]]:
    """Every frame until the viewer finishes, each with the monotonic time it was returned."""
    received = []
    deadline = time.monotonic() + limit_s
    while not viewer.finished:
        assert time.monotonic() < deadline, "the viewer never finished"
        for frame in await viewer.next_frames(timeout_s=1.0):
            json.dumps(frame, allow_nan=False)  # every frame is strict JSON
            received.append((time.monotonic(), frame))
    return received


def telemetry_frames(received: list[tuple[float, dict]]) -> list[tuple[float, dict]]:
    return [(t, frame) for t, frame in received if frame["type"] == "telemetry"]


def check_every_message_accounted_for(frames: list[dict], count: int) -> None:
    """Each frame plus the samples it says were overwritten: exactly the messages sent."""
    values = [frame["msg"]["data"] for frame in frames]
    assert values == sorted(set(values)), "frames out of order or repeated"
    assert values[-1] == count - 1, "the last value must always arrive"
    assert sum(frame["dropped"] for frame in frames) + len(frames) == count
    previous = -1
    for frame in frames:  # each dropped count is exactly the gap to the previous frame
        assert frame["dropped"] == frame["msg"]["data"] - previous - 1
        previous = frame["msg"]["data"]


def test_rate_limit_respected_and_dropped_counts_add_up() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r1")
        viewer = telemetry.viewer()
        viewer.subscribe("count", max_rate_hz=10)
        thread = feed_thread(telemetry, count=200, period_s=0.0025)  # 400 Hz for 0.5 s
        started = time.monotonic()
        thread.start()
        received = await drain(viewer)
        elapsed_s = time.monotonic() - started
        thread.join()
        frames = telemetry_frames(received)
        # 10 Hz over ~0.5 s: 5-6 frames, plus the last value, flushed when the run ends.
        assert 5 <= len(frames) <= 7
        assert len(frames) <= elapsed_s * 10 + 2
        gaps = [b - a for (a, _), (b, _) in itertools.pairwise(frames[:-1])]
        # [s] never faster than 10 Hz over any stretch: a late frame's successor may come half
        # a period early (RATE_BURST), never more; so any two gaps in a row add up to >= 0.15.
        assert min(gaps) >= (1 - RATE_BURST) * 0.1 - 0.005
        assert min(a + b for a, b in itertools.pairwise(gaps)) >= 0.195 - 0.1 * RATE_BURST
        check_every_message_accounted_for([frame for _, frame in frames], 200)
        assert received[-1][1]["type"] == "state" and received[-1][1]["state"] == "finished"

    asyncio.run(main())


def test_two_viewers_with_different_rates() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r2")
        slow, fast = telemetry.viewer(), telemetry.viewer()
        slow.subscribe("count", max_rate_hz=5)
        fast.subscribe("count", max_rate_hz=50)
        thread = feed_thread(telemetry, count=600, period_s=0.001)  # ~1 kHz for 0.6 s
        thread.start()
        slow_received, fast_received = await asyncio.gather(drain(slow), drain(fast))
        thread.join()
        slow_frames = [frame for _, frame in telemetry_frames(slow_received)]
        fast_frames = [frame for _, frame in telemetry_frames(fast_received)]
        assert 3 <= len(slow_frames) <= 6
        assert 20 <= len(fast_frames) <= 45
        check_every_message_accounted_for(slow_frames, 600)
        check_every_message_accounted_for(fast_frames, 600)
        summary = telemetry.delivery_latency_summary()
        assert summary["count"] == len(slow_frames) + len(fast_frames)
        assert 0 <= summary["p50_s"] <= summary["p99_s"] <= summary["max_s"] < 1.0
        assert len(fast.latencies_s) == len(fast_frames)

    asyncio.run(main())


def test_latest_value_wins_and_only_it_is_kept() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r3")
        viewer = telemetry.viewer()
        viewer.subscribe("count", max_rate_hz=60)
        for i in range(999):
            telemetry.on_message("count", INT32, i, int32(i))
        telemetry.on_message("count", INT32, 999, int32(999), produced_wall_s=1234.5)
        assert len(telemetry._latest) == 1  # one sample per topic, however many arrive
        frames = await viewer.next_frames(timeout_s=1.0)
        sample = [frame for frame in frames if frame["type"] == "telemetry"]
        assert sample == [
            {
                "type": "telemetry",
                "topic": "count",
                "msg_type": INT32,
                "time_s": 999e-9,
                "msg": {"data": 999},
                "dropped": 999,
                "wall_s": 1234.5,  # a mirror's production time, passed through
            }
        ]

    asyncio.run(main())


def test_a_frame_carries_when_the_run_produced_its_sample() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r3b")
        viewer = telemetry.viewer()
        viewer.subscribe("count", max_rate_hz=60)
        before_s = time.time()
        telemetry.on_message("count", INT32, 0, int32(0))
        after_s = time.time()
        frames = await viewer.next_frames(timeout_s=1.0)
        (frame,) = [frame for frame in frames if frame["type"] == "telemetry"]
        assert before_s <= frame["wall_s"] <= after_s, "stamped when the run handed it over"

    asyncio.run(main())


def test_late_subscriber_gets_the_current_value_without_past_drops() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r4")
        for i in range(10):
            telemetry.on_message("count", INT32, i, int32(i))
        viewer = telemetry.viewer()
        viewer.subscribe("count", max_rate_hz=5)
        frames = await viewer.next_frames(timeout_s=1.0)
        (frame,) = [frame for frame in frames if frame["type"] == "telemetry"]
        assert frame["msg"] == {"data": 9} and frame["dropped"] == 0

    asyncio.run(main())


def test_rate_limited_change_is_sent_when_allowed_not_forgotten() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r5")
        viewer = telemetry.viewer()
        viewer.subscribe("count", max_rate_hz=5)  # one frame per 0.2 s
        telemetry.on_message("count", INT32, 0, int32(0))
        first = await viewer.next_frames(timeout_s=1.0)
        assert [f["msg"] for f in first if f["type"] == "telemetry"] == [{"data": 0}]
        sent_s = time.monotonic()
        telemetry.on_message("count", INT32, 1, int32(1))  # nothing else will ever arrive
        second = await viewer.next_frames(timeout_s=2.0)
        waited_s = time.monotonic() - sent_s
        assert [f["msg"] for f in second] == [{"data": 1}]
        # [s] held back by the rate (a first frame is "late", so its successor may come
        # RATE_BURST of a period early), then sent unprompted
        assert (1 - RATE_BURST) * 0.2 - 0.02 <= waited_s <= 0.6

    asyncio.run(main())


def test_unsubscribed_and_unknown_topics() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r6")
        viewer = telemetry.viewer()
        viewer.subscribe("not_yet", max_rate_hz=10)  # may appear later
        telemetry.on_message("other", INT32, 0, int32(1))
        frames = await viewer.next_frames(timeout_s=0.2)
        assert frames == [{"type": "topic", "topic": "other", "msg_type": INT32}]
        assert await viewer.next_frames(timeout_s=0.05) == []
        telemetry.on_message("not_yet", INT32, 0, int32(2))
        frames = await viewer.next_frames(timeout_s=0.2)
        assert [f["msg"] for f in frames if f["type"] == "telemetry"] == [{"data": 2}]
        viewer.unsubscribe("not_yet")
        telemetry.on_message("not_yet", INT32, 0, int32(3))
        assert await viewer.next_frames(timeout_s=0.05) == []

    asyncio.run(main())


def test_a_topic_named_as_rostopic_prints_it_is_the_bus_topic() -> None:
    """`rostopic list` prints "/scan"; the bus names root topics "scan" (sandbox/names.py). A
    viewer subscribing "/scan" used to be acked and then sent nothing."""

    async def main() -> None:
        telemetry = RunTelemetry("r6b")
        telemetry.on_message("scan", INT32, 0, int32(7))
        telemetry.on_message("ultrasonic/range_0", INT32, 0, int32(8))
        viewer = telemetry.viewer()
        viewer.subscribe("/scan", max_rate_hz=10)
        viewer.subscribe("//ultrasonic//range_0/", max_rate_hz=10)
        assert viewer.subscriptions == {"scan": 10, "ultrasonic/range_0": 10}
        frames = await viewer.next_frames(timeout_s=1.0)
        sent = {f["topic"]: f["msg"] for f in frames if f["type"] == "telemetry"}
        assert sent == {"scan": {"data": 7}, "ultrasonic/range_0": {"data": 8}}
        viewer.subscribe("scan", max_rate_hz=2)  # the same subscription, a new rate
        assert viewer.subscriptions == {"scan": 2, "ultrasonic/range_0": 10}
        viewer.unsubscribe("/scan")
        assert viewer.subscriptions == {"ultrasonic/range_0": 10}
        for nothing in ("/", "///"):
            with pytest.raises(SubscriptionError, match="names no topic"):
                viewer.subscribe(nothing, 10)

    asyncio.run(main())


def test_subscription_requests_are_checked() -> None:
    async def main() -> None:
        viewer = RunTelemetry("r7").viewer()
        for rate in (0, -1, MAX_RATE_HZ + 1, math.nan, math.inf, True, "10", None):
            with pytest.raises(SubscriptionError, match="max_rate_hz"):
                viewer.subscribe("scan", rate)
        for topic in ("", 5, None, "a b", "line\nbreak", "x" * 1000):
            with pytest.raises(SubscriptionError, match="topic"):
                viewer.subscribe(topic, 10)
        viewer.subscribe("scan", MAX_RATE_HZ)
        viewer.subscribe("scan", 2)  # again: a new rate
        assert viewer.subscriptions == {"scan": 2}
        with pytest.raises(SubscriptionError, match="subscribed topics: scan"):
            viewer.unsubscribe("odom")
        for i in range(MAX_SUBSCRIPTIONS - 1):
            viewer.subscribe(f"t{i}", 1)
        with pytest.raises(SubscriptionError, match="at most"):
            viewer.subscribe("one_too_many", 1)

    asyncio.run(main())


def test_viewer_needs_a_running_loop() -> None:
    with pytest.raises(RuntimeError, match="asyncio loop"):
        RunTelemetry("r8").viewer()


def test_events_are_bounded_and_a_slow_viewer_is_told_what_it_missed() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r9")
        viewer = telemetry.viewer()
        for i in range(EVENTS_KEPT + 3000):
            telemetry.on_logs("student", [f"line {i}"])
        assert len(telemetry._events) == EVENTS_KEPT
        frames = await viewer.next_frames(timeout_s=1.0)
        assert frames[0] == {"type": "dropped", "what": "events", "count": 3000}
        assert len(frames) == 1 + EVENTS_KEPT
        assert frames[1] == {"type": "log", "node": "student", "line": "line 3000"}
        assert frames[-1]["line"] == f"line {EVENTS_KEPT + 2999}"
        # One huge batch: only the lines the ring can hold are stored, the rest counted.
        telemetry.on_logs("student", [f"burst {i}" for i in range(10 * EVENTS_KEPT)])
        frames = await viewer.next_frames(timeout_s=1.0)
        assert frames[0] == {"type": "dropped", "what": "events", "count": 9 * EVENTS_KEPT}
        assert frames[-1]["line"] == f"burst {10 * EVENTS_KEPT - 1}"
        # A viewer arriving now gets the ring's history and is not told of older drops.
        late = telemetry.viewer()
        frames = await late.next_frames(timeout_s=1.0)
        assert len(frames) == EVENTS_KEPT and frames[0]["type"] == "log"

    asyncio.run(main())


def test_end_of_run_finishes_the_viewer_after_everything_is_sent() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r10")
        viewer = telemetry.viewer()
        viewer.subscribe("count", max_rate_hz=4)
        telemetry.on_message("count", INT32, 0, int32(0))
        assert not viewer.finished
        await viewer.next_frames(timeout_s=1.0)
        telemetry.on_message("count", INT32, 1, int32(1))  # held back by the rate (0.25 s)
        telemetry.on_logs("student", ["bye"])
        finish(telemetry, time_s=2.5)
        started = time.monotonic()
        received = await drain(viewer)
        assert time.monotonic() - started < 0.2, "an ended run flushes, it does not wait"
        kinds = [frame["type"] for _, frame in received]
        assert kinds == ["telemetry", "log"] + 4 * ["state"], "the last sample, then the end"
        assert received[0][1]["msg"] == {"data": 1}
        states = [frame["state"] for _, frame in received if frame["type"] == "state"]
        assert states == ["starting", "running", "stopping", "finished"]
        assert received[-1][1] == {
            "type": "state",
            "state": "finished",
            "reason": "finished: duration reached",
            "time_s": 2.5,
        }
        assert viewer.finished
        assert await viewer.next_frames(timeout_s=5.0) == []  # at once, no waiting
        # A viewer opened after the end gets the history, then finishes too.
        late = telemetry.viewer()
        late.subscribe("count", max_rate_hz=10)
        late_frames = [frame for _, frame in await drain(late)]
        assert {"type": "log", "node": "student", "line": "bye"} in late_frames
        assert late.finished

    asyncio.run(main())


def test_close_unregisters_and_wakes_a_waiting_next_frames() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r11")
        viewer = telemetry.viewer()
        assert telemetry.viewer_count == 1
        waiting = asyncio.create_task(viewer.next_frames(timeout_s=10.0))
        await asyncio.sleep(0.01)
        started = time.monotonic()
        viewer.close()
        assert await waiting == []
        assert time.monotonic() - started < 1.0
        assert telemetry.viewer_count == 0 and viewer.finished
        telemetry.on_logs("student", ["nobody is listening"])  # no wake-up, no error
        viewer.close()  # twice is fine
        with pytest.raises(SubscriptionError, match="closed"):
            viewer.subscribe("count", 1)

    asyncio.run(main())


def test_run_thread_schedules_one_wake_up_per_viewer_not_one_per_message() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r12")
        viewer = telemetry.viewer()
        viewer.subscribe("count", max_rate_hz=60)
        loop = asyncio.get_running_loop()
        scheduled = []

        def counting(callback):
            scheduled.append(callback)
            return loop.call_soon_threadsafe(callback)

        viewer._loop = SimpleNamespace(call_soon_threadsafe=counting)
        thread = threading.Thread(
            target=lambda: [telemetry.on_message("count", INT32, i, int32(i)) for i in range(500)]
        )
        thread.start()
        thread.join()  # the loop is blocked meanwhile: no wake-up can run yet
        assert len(scheduled) == 1
        frames = await viewer.next_frames(timeout_s=1.0)
        assert [f["msg"] for f in frames if f["type"] == "telemetry"] == [{"data": 499}]
        await asyncio.sleep(0)  # the one wake-up runs
        telemetry.on_message("count", INT32, 500, int32(500))  # woken again after it ran
        assert len(scheduled) == 2

    asyncio.run(main())


def test_a_sample_is_decoded_once_for_all_viewers(monkeypatch: pytest.MonkeyPatch) -> None:
    calls = []
    real_decode = telemetry_module.decode

    def counting_decode(type_name: str, data: bytes) -> dict:
        calls.append(type_name)
        return real_decode(type_name, data)

    monkeypatch.setattr(telemetry_module, "decode", counting_decode)

    async def main() -> None:
        telemetry = RunTelemetry("r13")
        viewers = [telemetry.viewer() for _ in range(100)]
        for viewer in viewers:
            viewer.subscribe("value", max_rate_hz=10)
        telemetry.on_message("value", "std_msgs/Float64", 0, Float64(data=math.nan).serialize())
        messages = []
        for viewer in viewers:
            frames = await viewer.next_frames(timeout_s=1.0)
            messages += [f["msg"] for f in frames if f["type"] == "telemetry"]
        assert len(messages) == 100 and messages[0] == {"data": None}
        assert all(message is messages[0] for message in messages)
        assert calls == ["std_msgs/Float64"]

    asyncio.run(main())


def test_undecodable_bytes_give_a_frame_with_the_error() -> None:
    async def main() -> None:
        telemetry = RunTelemetry("r14")
        viewer = telemetry.viewer()
        viewer.subscribe("count", max_rate_hz=10)
        telemetry.on_message("count", INT32, 0, b"\x01")
        frames = await viewer.next_frames(timeout_s=1.0)
        (frame,) = [f for f in frames if f["type"] == "telemetry"]
        assert frame["msg"] is None and "cannot decode std_msgs/Int32" in frame["error"]

    asyncio.run(main())


def test_snapshot() -> None:
    telemetry = RunTelemetry("r15")
    telemetry.on_state(RunState.STARTING, "", 0.0)
    telemetry.on_message("scan", "sensor_msgs/LaserScan", 0, b"")
    telemetry.on_message("count", INT32, 0, int32(1))
    # A service's internal request topic is recorded, not offered to viewers.
    telemetry.on_message("__srv__/enable", "robodojo_msgs/ServiceCall", 0, b"")
    assert telemetry.snapshot() == {
        "type": "snapshot",
        "run_id": "r15",
        "state": "starting",
        "reason": "",
        "time_s": 0.0,
        "topics": {"scan": "sensor_msgs/LaserScan", "count": INT32},
    }


def test_registry_keeps_ended_runs_a_while_and_while_watched() -> None:
    registry = TelemetryRegistry(keep_after_end_s=60.0)
    telemetry = registry.create("a")
    assert registry.get("a") is telemetry
    with pytest.raises(ValueError, match="unique"):
        registry.create("a")
    with pytest.raises(UnknownRunError, match="no live telemetry"):
        registry.get("nope")
    finish(telemetry)
    now_s = time.monotonic()
    assert registry.sweep(now_s + 30) == []  # ended, but recently

    async def watch_then_leave() -> None:
        viewer = telemetry.viewer()
        assert registry.sweep(now_s + 3600) == []  # long ended, but someone watches
        viewer.close()

    asyncio.run(watch_then_leave())
    assert registry.sweep(now_s + 3600) == ["a"]
    assert registry.run_ids() == []
    registry.create("b")
    registry.discard("b")
    registry.discard("b")  # twice is fine
    assert registry.run_ids() == []


def test_latency_summary_nearest_rank() -> None:
    assert latency_summary([]) == {"count": 0, "p50_s": None, "p99_s": None, "max_s": None}
    summary = latency_summary([i / 1000 for i in range(1, 101)])
    assert summary == {"count": 100, "p50_s": 0.05, "p99_s": 0.099, "max_s": 0.1}


PRINTING_APPROACH = """
RATE_HZ = 10
SUBSCRIBE = ["Distance"]

def step(obs):
    print("distance", obs.Distance.data if obs.Distance else None)
    return (0.2, 0.0)
"""


@pytest.fixture(scope="module")
def launcher():
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the live run test needs bubblewrap: {problem} (./scripts/test installs it)")
    limits = dataclasses.replace(DEFAULT_LIMITS, step_budget_s=2.0, first_step_budget_s=8.0)
    launcher = Launcher(limits=limits, pool_size=1)
    yield launcher
    launcher.close()


def test_a_real_run_feeds_a_viewer_from_its_worker_thread(tmp_path, launcher) -> None:
    spec = RunSpec(
        robot="crowbot",
        world="wall_approach",
        nodes=(NodeSpec(name="controller", code=PRINTING_APPROACH, filename="controller.py"),),
        clock=Clock.REALTIME,
        duration_s=1.5,
    )
    telemetry = RunTelemetry("live")
    run = Run(spec, launcher, tmp_path / "run", run_id="live", observer=telemetry)

    async def main() -> list[dict]:
        viewer = telemetry.viewer()
        viewer.subscribe("Distance", max_rate_hz=4)
        worker = threading.Thread(target=run.execute, name="run-live")
        worker.start()
        received = await drain(viewer, limit_s=30.0)
        worker.join(timeout=30.0)
        viewer.close()
        return [frame for _, frame in received]

    frames = asyncio.run(main())
    assert run.state is RunState.FINISHED, run.reason
    with open(tmp_path / "run" / "recording.mcap", "rb") as f:
        recorded = sum(
            channel.topic == "/Distance" for _, channel, _ in make_reader(f).iter_messages()
        )
    distance = [frame for frame in frames if frame["type"] == "telemetry"]
    assert 3 <= len(distance) <= 9  # 4 Hz over 1.5 s of run (and start-up), plus the last
    assert sum(frame["dropped"] for frame in distance) + len(distance) == recorded
    assert all(isinstance(frame["msg"]["data"], int) for frame in distance)
    assert any(f["type"] == "log" and f["line"].startswith("distance") for f in frames)
    states = [frame["state"] for frame in frames if frame["type"] == "state"]
    assert states == ["starting", "running", "stopping", "finished"]
    assert telemetry.snapshot()["topics"]["Distance"] == "std_msgs/Int32"
