"""The bench in a cluster, its two halves on a private Redis: a bench worker's desk (a real
HardwareHub that the CrowBot firmware double connects to over rosserial) and a web process's
RemoteBench. The web side sees the robot's health, asks the queue for places and turns with the
same answers and refusals as the hub's own queue, sees a vanished bench as "not connected", and
garbage on the bench's channel is ignored."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator

import pytest

from server.api.settings import Settings
from server.hardware.queue import QueueError, RobotQueue
from server.service.hardware import HardwareHub
from server.store import robots as inventory
from server.store.db import Store
from server.workers.bench import (
    BENCHES_KEY,
    SNAPSHOT_TTL_S,
    BenchDesk,
    BenchWireError,
    ask_channel,
    request_from_json,
)
from server.workers.queue import redis_client
from server.workers.remote_bench import BenchUnavailableError, RemoteBench
from tests.hardware.crowbot_firmware import CrowBotFirmware
from tests.waiting import wait_until

pytestmark = pytest.mark.slow


class Bench:
    def __init__(self, store: Store, settings: Settings) -> None:
        self.client = redis_client(settings.redis_url)
        self.hub = HardwareHub(store, settings)
        self.taken: list[str] = []
        self.desk = BenchDesk(self.client, self.hub, "bench-host:1", self.taken.append)

    def start(self) -> Bench:
        self.hub.start()
        self.desk.start()
        return self

    def stop(self) -> None:
        self.desk.stop()
        self.hub.stop()
        self.client.close()


@pytest.fixture
def lab(private_redis, tmp_path) -> Iterator[tuple[Bench, RemoteBench, CrowBotFirmware]]:
    settings = Settings(
        data=tmp_path, redis_url=private_redis.url, rosserial_port=0, rosserial_host="127.0.0.1"
    )
    store = Store.open(f"sqlite:///{tmp_path / 'robodojo.db'}")
    with store.session() as db:
        inventory.add(db, name="crowbot-1", kind="crowbot", transport="rosserial",
                      address="127.0.0.1", baud=None, limits={}, watchdog_s=0.5)  # fmt: skip
    bench = Bench(store, settings).start()
    remote = RemoteBench(settings)
    firmware = CrowBotFirmware("127.0.0.1", bench.hub.port).start()
    assert firmware.wait_until(lambda: firmware.configured, 10), "the firmware did not negotiate"
    yield bench, remote, firmware
    firmware.stop()
    remote.stop()
    bench.stop()
    store.close()


def fresh(remote: RemoteBench) -> RemoteBench:
    remote._read_s = 0.0  # read the snapshots now, not from the half-second cache
    return remote


def test_the_web_side_sees_the_robot_connected_with_its_health(lab):
    bench, remote, _ = lab
    wait_until(
        lambda: fresh(remote).health("crowbot-1").sentence == "connected",
        10,
        "the web side saw crowbot-1 connected",
        poll_s=0.1,
    )
    health = remote.health("crowbot-1").as_dict()
    assert health["state"] == "connected" and health["last_heard_s_ago"] < 3.0
    assert remote.link("crowbot-1") is not None and remote.link("crowbot-2") is None
    assert remote.health("crowbot-2").sentence == "not connected"
    assert remote.port == bench.hub.port and remote.listen_error == ""
    assert remote.problems() == {}
    assert bench.taken == ["crowbot-1"]  # the bench took the robot's run queue


def test_the_queue_answers_as_the_hubs_own_queue_does(lab):
    bench, remote, _ = lab
    wait_until(lambda: fresh(remote).link("crowbot-1") is not None, 10, "crowbot-1 connected")
    queue = remote.queue("crowbot-1")
    first = queue.join("ada", 0.0)
    assert (first.state, first.user_id) == ("offered", "ada") and first.offered_until_s
    assert queue.join("ada", 0.0).state == "offered"  # asking again keeps the place
    assert str(queue.join("bob", 0.0).state) == "waiting"
    assert queue.position("bob") == 2 and queue.position("cleo") is None
    assert queue.estimated_wait_s("bob") == pytest.approx(300.0)

    local = RobotQueue("crowbot-1")  # the same refusal, word for word, as a lone server's
    local.join("ada", 0.0)
    local.join("bob", 0.0)
    with pytest.raises(QueueError) as expected:
        local.start("bob", "run-b", 0.0)
    with pytest.raises(QueueError) as refused:
        queue.start("bob", "run-b", 0.0)
    assert str(refused.value) == str(expected.value)
    with pytest.raises(QueueError, match="not in the queue for crowbot-1; join it first"):
        queue.start("cleo", "run-c", 0.0)
    with pytest.raises(QueueError, match="only a student who is waiting can be moved"):
        queue.move("ada", 1, 0.0)

    assert queue.start("ada", "run-a", 0.0).state == "running"
    assert bench.hub.queue("crowbot-1").places[0].run_id == "run-a"  # the truth is the bench's
    queue.finish("run-a", 0.0)
    described = queue.describe(0.0)
    assert [(p["user_id"], p["state"]) for p in described["places"]] == [("bob", "offered")]
    queue.set_in_service(False, 0.0)
    assert queue.describe(0.0)["places"][0]["state"] == "waiting"  # nobody lost a place
    queue.set_in_service(True, 0.0)
    queue.skip("bob", 0.0)
    assert queue.describe(0.0)["places"] == []


def test_a_bench_that_vanished_reads_as_not_connected(lab):
    bench, remote, _ = lab
    wait_until(lambda: fresh(remote).link("crowbot-1") is not None, 10, "crowbot-1 connected")
    bench.desk._stop.set()  # the bench worker dies: its snapshots stop, nobody answers
    bench.desk.listener.stop()
    wait_until(
        lambda: fresh(remote).health("crowbot-1").sentence == "not connected",
        SNAPSHOT_TTL_S + 5,
        "the vanished bench's robot read as not connected",
        poll_s=0.2,
    )
    assert remote.link("crowbot-1") is None
    assert "no bench worker is running" in remote.listen_error
    with pytest.raises(BenchUnavailableError, match="no bench worker is running"):
        remote.queue("crowbot-1").join("ada", 0.0)
    described = remote.queue("crowbot-1").describe(0.0)  # the page shows an empty queue
    assert described["places"] == [] and "no bench worker" in described["unavailable"]
    assert remote.queue("crowbot-1").position("ada") is None


def test_a_bench_that_does_not_answer_is_a_sentence_within_seconds(lab):
    bench, remote, _ = lab
    wait_until(lambda: fresh(remote).link("crowbot-1") is not None, 10, "crowbot-1 connected")
    bench.desk.listener.stop()  # alive (snapshots go on) but deaf
    began = time.monotonic()
    with pytest.raises(BenchUnavailableError, match="did not answer"):
        remote.queue("crowbot-1").join("ada", 0.0)
    assert time.monotonic() - began < 10


def test_garbage_on_the_bench_channel_is_ignored(lab):
    bench, remote, _ = lab
    wait_until(lambda: fresh(remote).link("crowbot-1") is not None, 10, "crowbot-1 connected")
    client = redis_client(remote.settings.redis_url)
    channel = ask_channel("bench-host:1")
    for raw in (
        b"not json",
        b"[]",
        json.dumps({"request_id": "r", "robot": "crowbot-1", "op": "__init__", "args": {}}),
        json.dumps({"request_id": "r", "robot": "crowbot-1", "op": "join", "args": {}}),
        json.dumps(
            {
                "request_id": "r",
                "robot": "crowbot-1",
                "op": "move",
                "args": {"user_id": "x", "position": True},
            }
        ),
        json.dumps(
            {"request_id": "r", "robot": "crowbot-1", "op": "join", "args": {"user_id": "x" * 5000}}
        ),
    ):
        client.publish(channel, raw)
    assert client.blpop(["robodojo:answer:r"], timeout=1) is None  # none of them answered
    assert bench.hub.queue("crowbot-1").places == []  # nor changed the queue
    assert remote.queue("crowbot-1").join("ada", 0.0).state == "offered"  # the desk goes on
    assert client.sismember(BENCHES_KEY, "bench-host:1")
    client.close()
    with pytest.raises(BenchWireError, match="is no queue operation"):
        request_from_json(b'{"request_id": "r", "robot": "c", "op": "tick", "args": {}}')
