"""A real robot in the cluster, end to end on loopback (issue 16, hardware): one web process, one
plain worker and one bench worker (`robodojo worker --rosserial-port 0`) on a private Redis and a
fresh PostgreSQL database; the CrowBot firmware double (tests/hardware/crowbot_firmware.py, real
rosserial on the wire) connects to the bench worker. Through the web process, which holds no
robot: the robot shows connected with its health, the gate refuses untested code, the queue
offers the robot in turn, the run executes on the bench worker with the robot's readings live
on the websocket, the emergency stop reaches the robot at once, and the slot goes to the next
student."""

from __future__ import annotations

import contextlib
import inspect
import json
import re
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from server.workers import choose
from tests.cluster.conftest import REDIS_SERVER, PrivateRedis, free_port
from tests.cluster.lab import Cluster, wait_for_state
from tests.hardware.crowbot_firmware import CrowBotFirmware, FirmwareOptions
from tests.hardware.test_serve_hardware import ROSPY, add_bench_exercise
from tests.waiting import wait_until

pytestmark = pytest.mark.slow
if "QueueExecutor" not in inspect.getsource(choose):  # the cluster's executor, chosen by redis_url
    pytest.skip("serve --redis-url does not queue runs for workers yet", allow_module_level=True)

ENDED = {"finished", "failed", "interrupted"}
START_TIMEOUT_S = 60.0  # [s] a run's nodes start cold on a loaded 2-core machine
ESTOP_WITHIN_S = 1.0  # [s] web -> Redis -> bench worker -> rosserial; milliseconds when idle
# Drives slowly forward whatever the robot reads: the test is about where the run runs and how
# it is stopped, not about the student's logic (that is tests/hardware/test_serve_hardware.py).
DRIVE = """\
RATE_HZ = 10


def step(obs):
    return {"Control": (0.05, 0.0)}
"""
BENCH_PORT = re.compile(r"CrowBots connect to [\d.]+:(\d+)")


@dataclass
class BenchCluster(Cluster):
    """The lab's processes with some settings of their own (every process reads them)."""

    extra_env: dict[str, str] = field(default_factory=dict)

    @property
    def env(self) -> dict[str, str]:
        return {**super().env, **self.extra_env}


@contextlib.contextmanager
def bench_lab(folder: Path, extra_env: dict[str, str], plain_worker: bool = True):
    """web, [plain worker,] bench worker, and the firmware double connected to the bench."""
    if not Path(REDIS_SERVER).exists():
        pytest.skip(f"redis-server is not installed ({REDIS_SERVER}); the cluster needs it")
    from tests.store.conftest import POSTGRES_URL, _postgres_admin

    admin = _postgres_admin()  # skips, saying so, when PostgreSQL is not reachable
    name = f"robodojo_bench_{uuid.uuid4().hex[:10]}"
    admin.execute(f'CREATE DATABASE "{name}"')
    redis = PrivateRedis(free_port(), folder)
    redis.start()
    database = f"{POSTGRES_URL.rsplit('/', 1)[0]}/{name}"
    made = BenchCluster(folder / "data", redis.url, database, extra_env=extra_env)
    firmware = None
    try:
        made.webs.append(made.start_web())
        instructor = made.webs[0].admin()
        robot = {"name": "crowbot-1", "kind": "crowbot", "address": "127.0.0.1"}
        assert instructor.post("/api/admin/robots", json=robot).status_code == 201
        if plain_worker:
            made.start_worker()
        bench = made.start_worker("--rosserial-port", "0", "--rosserial-host", "127.0.0.1")
        port = next(int(m[1]) for line in bench.output if (m := BENCH_PORT.search(line)))
        firmware = CrowBotFirmware("127.0.0.1", port, FirmwareOptions(log_commands=True))
        firmware.start()
        assert firmware.wait_until(lambda: firmware.configured, 20), "the firmware did not sync"
        wait_until(
            lambda: robot_row(instructor)["connection"] == "connected",
            20,
            "the web process saw crowbot-1 connected to the bench worker",
            poll_s=0.2,
        )
        yield made, bench, firmware
    finally:
        if firmware is not None:
            firmware.stop()
        made.stop()
        redis.stop()
        admin.execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')
        admin.close()


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    with bench_lab(tmp_path_factory.mktemp("bench"), {}) as made:
        yield made


def live(web, client, run_id: str):
    url = web.url.replace("http", "ws") + f"/api/runs/{run_id}/live?token={client.token}"
    return connect(url, open_timeout=30)


def frames_until(ws, predicate, timeout_s: float, why=lambda: "") -> list[dict]:
    """Frames read until one satisfies `predicate`; fails after `timeout_s` or when the socket
    closes, with `why()` (the run's end, the bench worker's output) in the message."""
    frames: list[dict] = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            frame = json.loads(ws.recv(timeout=max(0.05, deadline - time.monotonic())))
        except TimeoutError:
            break
        except ConnectionClosed:
            raise AssertionError(f"the live socket closed; got {frames[-5:]}; {why()}") from None
        frames.append(frame)
        if predicate(frame):
            return frames
    raise AssertionError(f"no such frame within {timeout_s} s; got {frames[-5:]}")


def commands(firmware: CrowBotFirmware) -> list[float]:
    return [c.linear.x for c in firmware.received_on("Control")]


def driving(firmware: CrowBotFirmware) -> bool:
    """The newest command the robot got moves it (the student's, not a watchdog's zero)."""
    sent = commands(firmware)
    return bool(sent) and sent[-1] > 0


def robot_row(client) -> dict:
    return client.get("/api/hardware").json()["robots"][0]


def test_a_run_on_the_bench_robot_through_a_web_process_that_holds_none(lab):
    cluster, bench, firmware = lab
    web = cluster.webs[0]
    admin = web.admin()
    health = admin.get("/api/admin/robots").json()["robots"][0]["health"]
    assert health["state"] == "connected" and health["last_heard_s_ago"] < 3.0
    hardware = admin.get("/api/admin/status").json()["hardware"]
    assert hardware["listening"] == "yes" and hardware["rosserial_port"] > 0

    ada, bob = web.student("ada"), web.student("bob")
    untested = ada.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "hardware": "crowbot-1",
              "duration": 5, "nodes": [{"name": "approach", "code": ROSPY}]},
    )  # fmt: skip
    assert untested.status_code == 409 and untested.json()["gate"]["passed"] is False

    add_bench_exercise(admin, "bench_drive", duration_s=60)  # its gate is waived
    body = {"exercise": "bench_drive", "hardware": "crowbot-1",
            "nodes": [{"name": "drive", "code": DRIVE}]}  # fmt: skip
    not_queued = ada.post("/api/runs", json=body)
    assert not_queued.status_code == 429 and "not in the queue" in not_queued.json()["detail"]
    assert ada.post("/api/hardware/crowbot-1/queue").json()["state"] == "offered"
    assert bob.post("/api/hardware/crowbot-1/queue").json()["position"] == 2
    not_yet = bob.post("/api/runs", json=body)
    assert not_yet.status_code == 429 and "not your turn" in not_yet.json()["detail"]

    started = ada.post("/api/runs", json=body)
    assert started.status_code == 201, started.text
    run_id = started.json()["id"]
    going = wait_for_state(ada, run_id, {"running", *ENDED}, START_TIMEOUT_S)
    assert going["state"] == "running", (going["reason"], bench.output[-30:])

    def why() -> str:
        run = ada.get(f"/api/runs/{run_id}").json()
        return f"run {run['state']}: {run['reason']}; bench worker: {bench.output[-30:]}"

    with live(web, ada, run_id) as ws:
        assert cluster.worker_of(run_id) is bench  # runs.worker_id: the bench worker's
        ws.send(json.dumps({"id": "s", "op": "subscribe", "topic": "Distance", "max_rate_hz": 10}))
        reading = frames_until(
            ws,
            lambda f: f.get("type") == "telemetry" and "Distance" in f.get("topic", ""),
            30,
            why,
        )[-1]
        assert reading["wall_s"] > 0  # the robot's own reading, produced on the bench worker
        assert firmware.wait_until(lambda: driving(firmware), START_TIMEOUT_S), (
            f"the student's commands did not reach the robot: {commands(firmware)[-5:]}"
        )

        pressed = time.monotonic()
        assert ada.post(f"/api/runs/{run_id}/estop").json()["action"] == "estop"
        assert firmware.wait_until(lambda: not driving(firmware), 5), "the robot did not stop"
        stopped_after_s = time.monotonic() - pressed
        end = frames_until(ws, lambda f: f.get("type") == "end", 30)[-1]
    print(f"emergency stop through the web process reached the robot in {stopped_after_s:.3f} s")
    assert stopped_after_s < ESTOP_WITHIN_S
    run = wait_for_state(ada, run_id, ENDED, 30)
    assert run["state"] == "interrupted" and "emergency stop" in run["reason"], run
    assert end["state"] == "interrupted"
    time.sleep(0.5)  # nothing drives the robot after the stop
    assert not driving(firmware)

    # The slot went to the next student, who can take the robot now.
    wait_until(lambda: robot_row(bob)["my_position"] == 1, 10, "bob is first in line")
    assert robot_row(bob)["queue"]["places"][0]["state"] == "offered"
    second = bob.post("/api/runs", json=body)
    assert second.status_code == 201, second.text
    wait_for_state(bob, second.json()["id"], {"running", *ENDED}, START_TIMEOUT_S)
    assert bob.post(f"/api/runs/{second.json()['id']}/stop").is_success
    assert wait_for_state(bob, second.json()["id"], ENDED, 30)["state"] == "interrupted"
    wait_until(lambda: robot_row(bob)["queue"]["places"] == [], 10, "the queue emptied")


def test_a_bench_worker_that_stops_leaves_the_robot_not_connected(lab):
    cluster, bench, _ = lab
    admin = cluster.webs[0].admin()
    bench.process.terminate()
    bench.process.wait(60)
    wait_until(
        lambda: admin.get("/api/admin/robots").json()["robots"][0]["connection"] == "not connected",
        10,
        "the web process saw the bench gone",
        poll_s=0.2,
    )
    student = cluster.webs[0].student("cleo")
    refused = student.post("/api/hardware/crowbot-1/queue")
    assert refused.status_code == 503 and "no bench worker is running" in refused.json()["detail"]
    assert robot_row(student)["queue"]["places"] == []  # the page still shows the robot


def test_a_run_past_its_slot_is_stopped_on_the_bench_worker(tmp_path):
    slot = {"ROBODOJO_HARDWARE_SLOT_S": "6", "ROBODOJO_HARDWARE_GATE": "false"}
    with bench_lab(tmp_path, slot, plain_worker=False) as (cluster, bench, firmware):
        student = cluster.webs[0].student("dan")
        assert student.post("/api/hardware/crowbot-1/queue").json()["state"] == "offered"
        started = student.post(
            "/api/runs",
            json={"robot": "crowbot", "world": "wall_approach", "hardware": "crowbot-1",
                  "duration": 60, "nodes": [{"name": "drive", "code": DRIVE}]},
        )  # fmt: skip
        assert started.status_code == 201, started.text  # no gate on this lab
        run = wait_for_state(student, started.json()["id"], ENDED, START_TIMEOUT_S + 10)
        assert run["state"] == "interrupted" and "time slot is over" in run["reason"], (
            run["reason"],
            bench.output[-30:],
        )
        assert cluster.worker_of(run["id"]) is bench
        assert not driving(firmware)
        wait_until(lambda: robot_row(student)["queue"]["places"] == [], 10, "the slot was freed")
