"""A student's rospy script that finished in simulation drives the emulated CrowBot firmware
(rosserial over TCP, tests/hardware/crowbot_firmware.py) through `robodojo serve`: the
simulation gate, the queue, the limits between the node and the wire, the emergency stop, the
recording showing the commands reaching the robot, and a robot that disconnects."""

from __future__ import annotations

import io
import time
from collections.abc import Iterator

import pytest
from mcap.reader import make_reader

from tests.api.conftest import LabServer, start_server, stop_server, wait_for_end
from tests.hardware.crowbot_firmware import CrowBotFirmware, FirmwareOptions
from tests.waiting import wait_until

pytestmark = pytest.mark.slow  # a server and an emulated robot per module, runs on the robot

ROSPY = """\
import rospy
from std_msgs.msg import Int32
from geometry_msgs.msg import Twist

rospy.init_node("approach")
pub = rospy.Publisher("Control", Twist, queue_size=1)
latest = {"cm": None}
rospy.Subscriber("Distance", Int32, lambda msg: latest.update(cm=msg.data))
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    cmd = Twist()
    if latest["cm"] is not None and latest["cm"] > 30:
        cmd.linear.x = 0.1
    pub.publish(cmd)
    rate.sleep()
"""


def add_bench_exercise(admin, exercise_id: str, duration_s: float) -> dict:
    """A custom CrowBot exercise that waives the simulation gate (hardware_gate false), with
    ROSPY as its starter: a run on the bench needs no simulated run first."""
    made = admin.post(
        "/api/admin/exercises",
        json={"id": exercise_id, "title": "Drive on the bench", "robot": "crowbot",
              "world": "wall_approach", "duration_s": duration_s, "hardware_gate": False,
              "starter": [{"name": "approach", "code": ROSPY}],
              "checks": [{"name": "collisions", "threshold": 0}]},
    )  # fmt: skip
    assert made.status_code == 201, made.text
    return made.json()


@pytest.fixture(scope="module")
def bench(tmp_path_factory) -> Iterator[tuple[LabServer, CrowBotFirmware]]:
    # The lab's default (issue 16): simulation runs on worker processes, while the robot's runs
    # stay in the web process holding its connection (the other servers here run in-process).
    server = start_server(tmp_path_factory.mktemp("bench"), {"ROBODOJO_WORKERS": "2"})
    admin = server.admin()
    port = admin.get("/api/admin/status").json()["hardware"]["rosserial_port"]
    made = admin.post(
        "/api/admin/robots", json={"name": "crowbot-1", "kind": "crowbot", "address": "127.0.0.1"}
    )
    assert made.status_code == 201, made.text
    firmware = CrowBotFirmware("127.0.0.1", port, FirmwareOptions(log_commands=True)).start()
    assert firmware.wait_until(lambda: firmware.configured, 10), "the firmware did not negotiate"
    wait_until(
        lambda: admin.get("/api/admin/robots").json()["robots"][0]["connection"] == "connected",
        10,
        "the server counted crowbot-1 as connected",
        poll_s=0.1,
    )
    server.close_clients()
    yield server, firmware
    firmware.stop()
    stop_server(server)


@pytest.fixture(autouse=True)
def _close_bench_clients(request) -> Iterator[None]:
    yield
    if "bench" in request.fixturenames:
        request.getfixturevalue("bench")[0].close_clients()


def hardware_run(client, code: str, duration: float = 3.0):
    return client.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "hardware": "crowbot-1",
              "duration": duration, "nodes": [{"name": "approach", "code": code}]},
    )  # fmt: skip


def test_code_that_passed_in_simulation_drives_the_real_robot(bench):
    server, firmware = bench
    student = server.student("ada")
    robots = student.get("/api/hardware").json()["robots"]
    assert robots[0]["name"] == "crowbot-1" and robots[0]["connection"] == "connected"

    refused = hardware_run(student, ROSPY)
    assert refused.status_code == 409
    assert refused.json()["gate"] == {
        "passed": False,
        "simulation_run": None,
        "reason": refused.json()["detail"],
    }
    simulated = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "duration": 2,
              "nodes": [{"name": "approach", "code": ROSPY}]},
    ).json()  # fmt: skip
    assert wait_for_end(student, simulated["id"])["state"] == "finished"

    not_queued = hardware_run(student, ROSPY)
    assert not_queued.status_code == 429 and "not in the queue" in not_queued.json()["detail"]
    joined = student.post("/api/hardware/crowbot-1/queue").json()
    assert joined["position"] == 1 and joined["state"] == "offered"

    before = len(firmware.received_on("Control"))
    started = hardware_run(student, ROSPY)
    assert started.status_code == 201, started.text
    assert started.json()["hardware"] == "crowbot-1" and started.json()["clock"] == "realtime"
    run = wait_for_end(student, started.json()["id"], timeout_s=30)
    assert run["state"] == "finished", run["reason"]

    commands = firmware.received_on("Control")[before:]
    assert len(commands) >= 15  # 10 Hz for 3 s reached the robot over rosserial
    assert max(c.linear.x for c in commands) == pytest.approx(0.1, abs=1e-6)
    assert (commands[-1].linear.x, commands[-1].angular.z) == (0.0, 0.0)  # zero at the end
    assert list(firmware.received_on("Leds")[-1].data) == [0, 0, 0]  # LEDs off

    recording = student.get(f"/api/runs/{run['id']}/recording.mcap").content
    topics = {}
    for _, channel, _message in make_reader(io.BytesIO(recording)).iter_messages():
        topics[channel.topic] = topics.get(channel.topic, 0) + 1
    assert topics["/Distance"] >= 40 and topics["/Control"] >= 15  # the robot's own readings
    robot_log = student.get(f"/api/runs/{run['id']}/logs").json()["nodes"]["robot"]
    assert robot_log and robot_log[0].startswith("[info]")  # the firmware's nh.loginfo lines
    # The slot is given back: the queue is empty again.
    assert student.get("/api/hardware").json()["robots"][0]["queue"]["places"] == []


def test_the_emergency_stop_stops_the_robot_at_once(bench):
    server, firmware = bench
    student = server.student("bob")
    code = ROSPY.replace("cmd.linear.x = 0.1", "cmd.linear.x = 0.05")
    simulated = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "duration": 1,
              "nodes": [{"name": "approach", "code": code}]},
    ).json()  # fmt: skip
    wait_for_end(student, simulated["id"])
    student.post("/api/hardware/crowbot-1/queue")
    run_id = hardware_run(student, code, duration=30).json()["id"]
    assert firmware.wait_until(
        lambda: any(c.linear.x > 0 for c in firmware.received_on("Control")[-3:]), 10
    )
    pressed = time.monotonic()
    assert student.post(f"/api/runs/{run_id}/estop").json()["action"] == "estop"
    assert firmware.wait_until(lambda: firmware.received_on("Control")[-1].linear.x == 0.0, 1)
    stopped_after_s = time.monotonic() - pressed
    run = wait_for_end(student, run_id)
    assert run["state"] == "interrupted" and "emergency stop" in run["reason"]
    assert stopped_after_s < 0.1  # within one 10 Hz control period


def test_a_robot_that_disconnects_ends_its_run(bench):
    server, firmware = bench
    student = server.student("cleo")
    simulated = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "duration": 1,
              "nodes": [{"name": "approach", "code": ROSPY}]},
    ).json()  # fmt: skip
    wait_for_end(student, simulated["id"])
    student.post("/api/hardware/crowbot-1/queue")
    before = len(firmware.received_on("Control"))
    run_id = hardware_run(student, ROSPY, duration=30).json()["id"]
    wait_until(
        lambda: len(firmware.received_on("Control")) > before,
        10,
        "the hardware run's first command reached the robot",
    )
    firmware._close()  # the robot's WiFi drops
    run = wait_for_end(student, run_id, timeout_s=20)
    assert run["state"] == "failed", run
    assert run["reason"] == "failed: lost the link to the robot: the robot closed the connection"
    # The robot comes back and rejoins the pool.
    firmware.stop()
    firmware._stopping.clear()
    firmware.start()
    assert firmware.wait_until(lambda: firmware.configured, 10)
    admin = server.admin()
    wait_until(
        lambda: admin.get("/api/admin/robots").json()["robots"][0]["connection"] == "connected",
        10,
        "the robot rejoined the pool",
        poll_s=0.1,
    )


CREATE_DRIVER = """\
RATE_HZ = 10
SUBSCRIBE = ["odom"]


def step(obs):
    return {"cmd_vel": (0.15, 0.0)}
"""


def test_a_create_base_on_a_serial_port_is_driven_through_the_same_api(bench):
    from tests.hardware.create_emulator import CreateEmulator

    server, _ = bench
    with CreateEmulator() as emulator:
        admin = server.admin()
        made = admin.post(
            "/api/admin/robots",
            json={"name": "roomba-1", "kind": "turtlebot", "address": emulator.port,
                  "baud": 115200},
        )  # fmt: skip
        assert made.status_code == 201, made.text
        student = server.student("dora")
        body = {"robot": "turtlebot", "world": "office", "duration": 2,
                "nodes": [{"name": "drive", "code": CREATE_DRIVER}]}  # fmt: skip
        simulated = student.post("/api/runs", json=body).json()
        assert wait_for_end(student, simulated["id"])["state"] == "finished"
        student.post("/api/hardware/roomba-1/queue")
        started = student.post("/api/runs", json={**body, "hardware": "roomba-1"})
        assert started.status_code == 201, started.text
        run = wait_for_end(student, started.json()["id"], timeout_s=30)
        assert run["state"] == "finished", run["reason"]
        x, _, _ = emulator.pose()
        assert 0.1 < x < 0.35  # ~0.15 m/s for 2 s, ramped from rest
        assert emulator.commands(emulator_opcode("DRIVE_DIRECT"))[-1] == bytes(4)  # zero at end
        recording = student.get(f"/api/runs/{run['id']}/recording.mcap").content
        topics = {c.topic for _, c, _ in make_reader(io.BytesIO(recording)).iter_messages()}
        assert {"/odom", "/bumper", "/cmd_vel"} <= topics
        admin.delete("/api/admin/robots/roomba-1")


def emulator_opcode(name: str):
    from server.hardware.create import oi

    return oi.Opcode[name]


def test_a_turn_on_the_robot_ends_when_its_slot_is_over(tmp_path):
    server = start_server(tmp_path, {"ROBODOJO_HARDWARE_SLOT_S": "2",
                                     "ROBODOJO_HARDWARE_GATE": "false"})  # fmt: skip
    try:
        admin = server.admin()
        port = admin.get("/api/admin/status").json()["hardware"]["rosserial_port"]
        robot = {"name": "crowbot-9", "kind": "crowbot", "address": "127.0.0.1"}
        assert admin.post("/api/admin/robots", json=robot).status_code == 201
        with CrowBotFirmware("127.0.0.1", port) as firmware:
            assert firmware.wait_until(lambda: firmware.configured, 10)
            wait_until(
                lambda: (
                    admin.get("/api/admin/robots").json()["robots"][0]["connection"] == "connected"
                ),
                10,
                "the server counted crowbot-9 as connected",
                poll_s=0.1,
            )
            student = server.student("eve")
            student.post("/api/hardware/crowbot-9/queue")
            started = student.post(
                "/api/runs",
                json={"robot": "crowbot", "world": "wall_approach", "hardware": "crowbot-9",
                      "duration": 30, "nodes": [{"name": "approach", "code": ROSPY}]},
            )  # fmt: skip
            assert started.status_code == 201, started.text  # no gate on this server
            run = wait_for_end(student, started.json()["id"], timeout_s=20)
        assert run["state"] == "interrupted"
        assert "time slot is over" in run["reason"] and run["time_s"] < 5
    finally:
        stop_server(server)


def test_out_of_service_holds_the_queue_and_refuses_runs(bench):
    server, _ = bench
    admin = server.admin()
    first, second = server.student("fay"), server.student("gus")
    assert first.post("/api/hardware/crowbot-1/queue").json()["state"] == "offered"
    second.post("/api/hardware/crowbot-1/queue")
    assert admin.patch("/api/admin/robots/crowbot-1", json={"in_service": False}).is_success
    places = admin.get("/api/hardware").json()["robots"][0]["queue"]["places"]
    assert [p["state"] for p in places] == ["waiting", "waiting"]  # nobody lost a place
    refused = first.post("/api/hardware/crowbot-1/queue")
    assert refused.status_code == 409 and "out of service" in refused.json()["detail"]
    assert admin.patch("/api/admin/robots/crowbot-1", json={"in_service": True}).is_success
    mine = first.get("/api/hardware").json()["robots"][0]
    assert mine["my_position"] == 1 and mine["queue"]["places"][0]["state"] == "offered"
    assert "user_id" not in mine["queue"]["places"][0]  # students see places, not names
    first.delete("/api/hardware/crowbot-1/queue")
    second.delete("/api/hardware/crowbot-1/queue")


def test_an_exercise_can_waive_the_simulation_gate(bench):
    server, _ = bench
    admin = server.admin()
    made = add_bench_exercise(admin, "bench_free_drive", duration_s=2)
    assert made["hardware_gate"] is False
    student = server.student("hal")
    student.post("/api/hardware/crowbot-1/queue")
    started = student.post(
        "/api/runs",
        json={"exercise": "bench_free_drive", "hardware": "crowbot-1",
              "nodes": [{"name": "approach", "code": ROSPY}]},
    )  # fmt: skip
    assert started.status_code == 201, started.text  # no simulation run needed first
    assert wait_for_end(student, started.json()["id"], timeout_s=30)["state"] == "finished"
    admin.delete("/api/admin/exercises/bench_free_drive")
