"""Sim-vs-real through `robodojo serve`: a student's PID code passes the simulation gate of the
CrowBot distance exercise, then drives the emulated CrowBot firmware (rosserial over TCP); the
hardware run links to that simulation run, and GET /api/runs/{id}/comparison overlays their
topics and puts the exercise's checks side by side. Only the owner and instructors see it."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.api.conftest import LabServer, start_server, stop_server, wait_for_end
from tests.hardware.crowbot_firmware import CrowBotFirmware
from tests.hardware.test_serve_hardware import ROSPY, add_bench_exercise
from tests.waiting import wait_until

pytestmark = pytest.mark.slow  # a server and an emulated robot for the module, runs on it

EXERCISE = "crowbot_distance_pid"
TRY_S = 3.0  # [s] a short try of the exercise, in simulation and on the robot


@pytest.fixture(scope="module")
def bench(tmp_path_factory) -> Iterator[LabServer]:
    server = start_server(tmp_path_factory.mktemp("simreal"))
    admin = server.admin()
    port = admin.get("/api/admin/status").json()["hardware"]["rosserial_port"]
    made = admin.post(
        "/api/admin/robots", json={"name": "crowbot-1", "kind": "crowbot", "address": "127.0.0.1"}
    )
    assert made.status_code == 201, made.text
    firmware = CrowBotFirmware("127.0.0.1", port).start()
    assert firmware.wait_until(lambda: firmware.configured, 10), "the firmware did not negotiate"
    wait_until(
        lambda: admin.get("/api/admin/robots").json()["robots"][0]["connection"] == "connected",
        10,
        "the server counted crowbot-1 as connected",
        poll_s=0.1,
    )
    server.close_clients()
    yield server
    firmware.stop()
    stop_server(server)


def exercise_run(client, hardware: str | None = None) -> dict:
    body = {"exercise": EXERCISE, "duration": TRY_S,
            "nodes": [{"name": "pid_distance", "code": ROSPY}]}  # fmt: skip
    if hardware is not None:
        body["hardware"] = hardware
    started = client.post("/api/runs", json=body)
    assert started.status_code == 201, started.text
    return wait_for_end(client, started.json()["id"], timeout_s=30)


def test_a_hardware_run_is_compared_with_the_simulation_run_that_passed_its_gate(bench):
    student = bench.student("ada")
    simulated = exercise_run(student)
    assert simulated["state"] == "finished", simulated["reason"]
    assert simulated["simulation_run"] is None and "comparison" not in simulated["links"]
    refused = student.get(f"/api/runs/{simulated['id']}/comparison")
    assert refused.status_code == 409 and "ran in simulation" in refused.json()["detail"]

    student.post("/api/hardware/crowbot-1/queue")
    real = exercise_run(student, hardware="crowbot-1")
    assert real["state"] == "finished", real["reason"]
    assert real["simulation_run"] == simulated["id"]  # the gate's run, stored with the run
    assert real["links"]["comparison"] == f"/api/runs/{real['id']}/comparison"

    answer = student.get(real["links"]["comparison"])
    assert answer.status_code == 200, answer.text
    report = answer.json()
    assert (report["hardware_run"], report["simulation_run"]) == (real["id"], simulated["id"])
    assert report["exercise"] == EXERCISE and report["robot"] == "crowbot-1"

    # One time base, from the start to the longer run's end, 10 Hz.
    times = report["time_s"]
    assert times[0] == 0.0 and times[1] == pytest.approx(0.1)
    assert TRY_S - 0.5 <= times[-1] <= TRY_S + 1.0
    series = {(s["topic"], s["field"]): s for s in report["series"]}
    for s in series.values():
        assert len(s["simulation"]) == len(s["hardware"]) == len(times)
    distance = series[("Distance", "data")]
    assert distance["shared"]
    sim_cm = [v for v in distance["simulation"] if v is not None]
    real_cm = [v for v in distance["hardware"] if v is not None]
    assert len(sim_cm) > 0.8 * len(times) and len(real_cm) > 0.5 * len(times)
    # The code drives forward at 0.1 m/s while the wall is farther than 30 cm, in both runs.
    command = series[("Control", "linear.x")]
    assert command["shared"]
    assert max(v for v in command["simulation"] if v is not None) == pytest.approx(0.1)
    assert max(v for v in command["hardware"] if v is not None) == pytest.approx(0.1)
    # What the safety layer sent exists on the robot only.
    applied = series[("Control_applied", "linear.x")]
    assert not applied["shared"] and set(applied["simulation"]) == {None}
    assert any(v is not None and v > 0 for v in applied["hardware"])
    assert [k for k in series][:2] == [("Distance", "data"), ("Control", "angular.z")]
    assert distance["unit"] == "cm"
    # The true pose is the simulator's: the bench does not know where the robot is.
    pose = series[("pose", "x")]
    assert not pose["shared"] and set(pose["hardware"]) == {None}
    assert sum(v is not None for v in pose["simulation"]) > 0.8 * len(times)

    # The exercise's checks side by side, each with its gap in a sentence.
    checks = {c["name"]: c for c in report["checks"]}
    assert list(checks) == ["settling_time", "steady_state_error", "overshoot", "collisions"]
    by_name = {c["name"]: c for c in real["checks"]}
    sim_by_name = {c["name"]: c for c in simulated["checks"]}
    for name, row in checks.items():
        assert row["hardware"]["value"] == by_name[name]["value"]
        assert row["simulation"]["value"] == sim_by_name[name]["value"]
        assert row["sentence"].startswith(name.replace("_", " ") + ": ")
        if row["simulation"]["value"] is None and row["hardware"]["value"] is None:
            assert "nothing to judge in either run" in row["sentence"]  # 3 s: never settled
            continue
        assert "in simulation" in row["sentence"] and "on the robot" in row["sentence"]
        if row["simulation"]["value"] is not None and row["hardware"]["value"] is not None:
            assert row["difference"] == pytest.approx(
                row["hardware"]["value"] - row["simulation"]["value"]
            )

    # The instructor opens it for any student; another student is told it does not exist.
    assert bench.admin().get(real["links"]["comparison"]).status_code == 200
    other = bench.student("bob").get(real["links"]["comparison"])
    assert other.status_code == 404 and other.json()["detail"] == "no such run (or it is not yours)"


def test_a_robot_run_without_a_simulation_run_says_so(bench):
    admin = bench.admin()
    add_bench_exercise(admin, "bench_no_gate", duration_s=1)
    student = bench.student("cleo")
    student.post("/api/hardware/crowbot-1/queue")
    started = student.post(
        "/api/runs",
        json={"exercise": "bench_no_gate", "hardware": "crowbot-1",
              "nodes": [{"name": "approach", "code": ROSPY}]},
    )  # fmt: skip
    assert started.status_code == 201, started.text
    run = wait_for_end(student, started.json()["id"], timeout_s=30)
    assert run["simulation_run"] is None and "comparison" not in run["links"]
    answer = student.get(f"/api/runs/{run['id']}/comparison")
    assert answer.status_code == 409
    assert "has no simulation run linked" in answer.json()["detail"]
    assert "run the same code in simulation" in answer.json()["detail"]
    admin.delete("/api/admin/exercises/bench_no_gate")
