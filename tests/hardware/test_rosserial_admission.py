"""rosserial admission (issue 14, finding 3): only registered addresses get a session, idle
handshakes cannot hold a slot, a second connection cannot take a robot out of a running student's
hands, and the rosserial port listens where `--rosserial-host` (default: all interfaces) says.

Distinct source addresses come from binding client sockets to 127.0.0.x (all of 127/8 is
loopback on Linux); the registered robot is the firmware emulator, connecting from 127.0.0.1.
"""

from __future__ import annotations

import dataclasses
import socket
import time
from collections.abc import Iterator

import pytest

from server.api.serve import _settings
from server.cli import build_parser
from server.hardware.rosserial import (
    DEFAULT_LIMITS,
    Refusal,
    RobotConnection,
    RosserialHandler,
    RosserialServer,
)
from tests.api.conftest import LabServer, start_server, stop_server, wait_for_end
from tests.hardware.crowbot_firmware import CrowBotFirmware
from tests.hardware.test_serve_hardware import ROSPY, add_bench_exercise
from tests.waiting import wait_until

pytestmark = pytest.mark.slow  # a server per module; handshake timeouts take seconds

ROBOT = "127.0.0.1"  # the firmware emulator's source address
STRANGER = "127.0.0.2"
FLOOD = 20  # idle sockets from one unregistered address: more than max_connections (16)


def connect_from(source: str, port: int, host: str = "127.0.0.1") -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.bind((source, 0))
    sock.settimeout(2.0)
    try:
        sock.connect((host, port))
    except OSError:
        sock.close()
        raise
    return sock


def first_bytes(sock: socket.socket, timeout_s: float = 2.0) -> bytes | None:
    """What the server sends first: b"" when it closed the connection without a word, None when
    it sent nothing and kept it open."""
    sock.settimeout(timeout_s)
    try:
        return sock.recv(4096)
    except (ConnectionResetError, BrokenPipeError):
        return b""
    except TimeoutError:
        return None


def wait_for_connection(admin, name: str, predicate, timeout_s: float = 10.0) -> str:
    deadline = time.monotonic() + timeout_s
    while True:
        robots = {r["name"]: r for r in admin.get("/api/admin/robots").json()["robots"]}
        state = robots[name]["connection"]
        if predicate(state) or time.monotonic() > deadline:
            return state
        time.sleep(0.1)


@pytest.fixture(scope="module")
def lab(tmp_path_factory) -> Iterator[tuple[LabServer, int]]:
    # The lab's default bind (every interface: test_rosserial_host_defaults_... checks it); the test
    # servers otherwise keep rosserial on loopback.
    server = start_server(
        tmp_path_factory.mktemp("admission"), env_extra={"ROBODOJO_ROSSERIAL_HOST": "0.0.0.0"}
    )
    admin = server.admin()
    port = admin.get("/api/admin/status").json()["hardware"]["rosserial_port"]
    made = admin.post(
        "/api/admin/robots", json={"name": "crowbot-1", "kind": "crowbot", "address": ROBOT}
    )
    assert made.status_code == 201, made.text
    add_bench_exercise(admin, "bench_drive", duration_s=6)
    server.close_clients()
    yield server, port
    stop_server(server)


def test_an_unregistered_flood_is_refused_and_the_robot_still_connects(lab):
    server, port = lab
    flood = [connect_from(STRANGER, port) for _ in range(FLOOD)]
    try:
        # Closed at once, before the topic request: no session, no slot.
        assert [first_bytes(sock) for sock in flood] == [b""] * FLOOD
        with CrowBotFirmware(ROBOT, port) as firmware:
            assert firmware.wait_until(lambda: firmware.configured, 10), "robot turned away"
            admin = server.admin()
            assert wait_for_connection(admin, "crowbot-1", lambda s: s == "connected") == (
                "connected"
            )
    finally:
        for sock in flood:
            sock.close()
    refusals = [line for line in server.output if f"refused a connection from {STRANGER}" in line]
    assert len(refusals) == 1, refusals  # one sentence per address per minute, not 20
    assert "no registered robot's address" in refusals[0] and "register it" in refusals[0]

    # It kept connecting, so it is backed off: even once registered, it waits out the back-off,
    # while an address registered at the same time that never flooded is admitted at once.
    admin = server.admin()
    for name, address in (("crowbot-2", STRANGER), ("crowbot-3", "127.0.0.3")):
        made = admin.post(
            "/api/admin/robots", json={"name": name, "kind": "crowbot", "address": address}
        )
        assert made.status_code == 201, made.text
    late = connect_from(STRANGER, port)
    fresh = connect_from("127.0.0.3", port)
    try:
        assert first_bytes(late) == b""
        assert first_bytes(fresh)  # the topic request: it got a session
    finally:
        late.close()
        fresh.close()
        admin.delete("/api/admin/robots/crowbot-2")
        admin.delete("/api/admin/robots/crowbot-3")

    # The rosserial port listens on all interfaces (the web service is on 127.0.0.1 only), and
    # admission still closes an address no robot has (crowbot-3's was just removed).
    other_interface = connect_from("127.0.0.3", port, host="127.0.0.3")
    try:
        assert first_bytes(other_interface) == b""
    finally:
        other_interface.close()


class OnlyRobot(RosserialHandler):
    def __init__(self) -> None:
        self.ready: list[RobotConnection] = []

    def admit(self, host: str) -> Refusal | None:
        return None if host == ROBOT else Refusal(f"{host} is not registered")

    def on_robot_connected(self, robot: RobotConnection) -> None:
        self.ready.append(robot)


def test_idle_sockets_from_a_registered_address_cannot_hold_the_slots():
    handler = OnlyRobot()
    limits = dataclasses.replace(DEFAULT_LIMITS, max_connections=4, handshake_timeout_s=3.0)
    assert limits.negotiation_timeout_s == 45.0  # the old, long bound is not what closes them
    with RosserialServer(handler, host=ROBOT, port=0, limits=limits) as server:
        idle = [connect_from(ROBOT, server.port) for _ in range(6)]
        try:
            assert all(first_bytes(sock) for sock in idle)  # admitted: the topic request came
            wait_until(
                lambda: (
                    len([r for r in server.robots() if not r.announced])
                    <= DEFAULT_LIMITS.max_pending_per_address
                ),
                5,
                "the server closed the older pending connections of the address",
            )
            pending = [r for r in server.robots() if not r.announced]
            assert len(pending) == DEFAULT_LIMITS.max_pending_per_address  # the newest two
            with CrowBotFirmware(ROBOT, server.port) as firmware:
                assert firmware.wait_until(lambda: firmware.configured, 5), "robot turned away"
                assert firmware.wait_until(lambda: len(handler.ready) == 1, 5)
                # Not a wait for an event: the handshaken robot must outlive its own handshake
                # timeout (3 s; settle_s made it ready before that).
                time.sleep(3.5)
                assert [r.id for r in server.robots()] == [handler.ready[0].id]
                assert firmware.connected and firmware.configured  # the handshaken one stays
            closed = [first_bytes(sock, 0.5) for sock in idle]
            assert closed == [b""] * len(idle)  # every idle socket was closed by the server
        finally:
            for sock in idle:
                sock.close()


def test_a_second_connection_does_not_end_a_run_and_an_idle_robot_reconnects(lab):
    server, port = lab
    admin = server.admin()
    with CrowBotFirmware(ROBOT, port) as robot:
        assert robot.wait_until(lambda: robot.configured, 10)
        assert wait_for_connection(admin, "crowbot-1", lambda s: s == "connected") == "connected"
        student = server.student("ida")
        student.post("/api/hardware/crowbot-1/queue")
        started = student.post(
            "/api/runs",
            json={"exercise": "bench_drive", "hardware": "crowbot-1",
                  "nodes": [{"name": "approach", "code": ROSPY}]},
        )  # fmt: skip
        assert started.status_code == 201, started.text
        assert robot.wait_until(lambda: len(robot.received_on("Control")) >= 5, 10)

        with CrowBotFirmware(ROBOT, port) as impostor:  # same address, mid-run
            assert not impostor.wait_until(lambda: impostor.configured, 2)
            state = admin.get("/api/admin/robots").json()["robots"][0]["connection"]
            assert f"a second connection from {ROBOT} was refused while crowbot-1 is in a run" in (
                state
            )
        before = len(robot.received_on("Control"))
        assert robot.wait_until(lambda: len(robot.received_on("Control")) > before + 5, 5)
        run = wait_for_end(student, started.json()["id"], timeout_s=30)
        assert run["state"] == "finished", run["reason"]  # not "the robot connected again"
        assert robot.connected

        # Idle now: a reconnection (a rebooted robot) replaces the old session.
        with CrowBotFirmware(ROBOT, port) as rebooted:
            assert rebooted.wait_until(lambda: rebooted.configured, 10), "reboot not admitted"
            state = wait_for_connection(admin, "crowbot-1", lambda s: s == "connected")
            assert state == "connected"  # the conflict is history once the robot is back


def test_rosserial_host_defaults_to_all_interfaces_and_can_be_set():
    parser = build_parser()
    plain = _settings(parser.parse_args(["serve", "--host", "127.0.0.1"]))
    assert plain.rosserial_bind_host == "0.0.0.0"  # robots on the WiFi reach it
    assert _settings(parser.parse_args(["serve"])).rosserial_bind_host == "0.0.0.0"
    chosen = _settings(parser.parse_args(["serve", "--rosserial-host", "10.42.0.1"]))
    assert chosen.rosserial_bind_host == "10.42.0.1" and chosen.host == "127.0.0.1"
