"""Issue 33, finding 1: nothing of the server's environment reaches a student.

bwrap is pid 1 inside every sandbox, and /proc/1/environ is the environment it was started with:
started with the server's, it handed a node (and a `.launch.py`, inside its 422) every variable
the server had, a planted PGPASSWORD among them. Here a canary variable is planted in the
server's environment and student code hunts for it everywhere it could be (/proc/1/environ,
/proc/self/environ, os.environ, every /proc/<pid>/environ); it must appear in no answer, log,
artifact, recording or file the lab keeps."""

from __future__ import annotations

import io
import os
import secrets
from collections.abc import Iterator
from pathlib import Path

import pytest
from mcap.reader import make_reader

from sandbox.launcher import Launcher
from sandbox.protocol import Api, Exited, Finishing, Yield
from tests.api.conftest import LabServer, start_server, stop_server, wait_for_end
from tests.sandbox.conftest import TEST_LIMITS, crowbot_info

# Every place a node might find the environment of a process, printed, saved as a file
# (an artifact) and published on a topic (the recording).
HUNT = """\
import glob
import os

import rospy
from std_msgs.msg import String


def read(path):
    try:
        with open(path, "rb") as source:
            return source.read().replace(b"\\0", b"\\n").decode("utf-8", "replace")
    except OSError as error:
        return f"{path}: {error}"


found = {
    "/proc/1/environ": read("/proc/1/environ"),
    "/proc/self/environ": read("/proc/self/environ"),
    "os.environ": repr(dict(os.environ)),
}
for path in sorted(glob.glob("/proc/[0-9]*/environ")):
    found[path] = read(path)
found["processes"] = " ".join(sorted(p for p in os.listdir("/proc") if p.isdigit()))
text = "\\n".join(f"== {where}\\n{what}" for where, what in found.items())
print(text)
with open("found.txt", "w") as out:
    out.write(text)
rospy.init_node("hunter")
pub = rospy.Publisher("found", String, queue_size=10)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    pub.publish(String(data=text))
    rate.sleep()
"""
# A launch file that gives back what it found in the error the student sees (the 422).
LEAKING_LAUNCH = """\
import os


def generate_launch_description():
    with open("/proc/1/environ", "rb") as source:
        pid1 = source.read().decode("utf-8", "replace")
    raise RuntimeError(f"environment: {dict(os.environ)!r} pid 1: {pid1}")
"""


def canary() -> tuple[str, str]:
    """A variable name and value no other code would ever print."""
    return f"ROBODOJO_CANARY_{secrets.token_hex(6)}", f"secret-{secrets.token_hex(12)}"


@pytest.fixture(scope="module")
def planted(tmp_path_factory) -> Iterator[tuple[LabServer, str, str]]:
    name, value = canary()
    server = start_server(tmp_path_factory.mktemp("environment"), {name: value})
    yield server, name, value
    stop_server(server)


def leaks(text: str | bytes, name: str, value: str) -> bool:
    if isinstance(text, bytes):
        return name.encode() in text or value.encode() in text
    return name in text or value in text


def recorded_bytes(recording: bytes) -> bytes:
    """Every message payload of an MCAP recording, decompressed (chunks may be zstd/lz4)."""
    reader = make_reader(io.BytesIO(recording))
    return b"".join(message.data for _, _, message in reader.iter_messages())


def test_a_node_finds_nothing_of_the_servers_environment(planted):
    server, name, value = planted
    student = server.student("hunter")
    started = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "duration": 1.5,
              "nodes": [{"name": "hunter", "code": HUNT}]},
    )  # fmt: skip
    assert started.status_code == 201, started.text
    run = wait_for_end(student, started.json()["id"])
    assert run["state"] == "finished", run["reason"]
    run_id = run["id"]
    logs = student.get(f"/api/runs/{run_id}/logs").json()["nodes"]["hunter"]
    printed = "\n".join(logs)
    # The hunt ran, saw the sandbox's own environment, and only the sandbox's processes.
    assert "HOME=/home/student" in printed and "== /proc/1/environ" in printed, printed[:2000]
    assert "== processes\n1 2" in printed, printed[-500:]
    assert not leaks(printed, name, value)
    artifacts = student.get(f"/api/runs/{run_id}/artifacts").json()["files"]
    assert [f["name"] for f in artifacts] == ["hunter/found.txt"]
    saved = student.get(artifacts[0]["url"]).content
    assert b"/proc/self/environ" in saved and not leaks(saved, name, value)
    recording = student.get(f"/api/runs/{run_id}/recording.mcap")
    assert recording.status_code == 200
    payloads = recorded_bytes(recording.content)
    assert b"/proc/1/environ" in payloads  # the topic with the hunt's text was recorded
    assert not leaks(payloads, name, value)
    for answer in (
        student.get(f"/api/runs/{run_id}"),
        student.get(f"/api/runs/{run_id}/metrics.json"),
        student.get(f"/api/runs/{run_id}/csv"),
    ):
        assert not leaks(answer.text, name, value), answer.url
    assert_nothing_kept(server, name, value)


def test_a_launch_file_gets_nothing_of_the_servers_environment_in_its_422(planted):
    server, name, value = planted
    student = server.student("launch_hunter")
    saved = student.put(
        "/api/workspaces/crowbot/files/leak.launch.py", json={"code": LEAKING_LAUNCH}
    )
    assert saved.status_code == 200, saved.text
    answer = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "duration": 1,
              "launch": {"file": "leak.launch.py"}},
    )  # fmt: skip
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"]
    assert "leak.launch.py" in detail and "HOME" in detail, detail  # the student's error came back
    assert not leaks(answer.text, name, value), detail
    assert_nothing_kept(server, name, value)


def assert_nothing_kept(server: LabServer, name: str, value: str) -> None:
    """No file of the lab's data folder (database, run folders, logs, artifacts) and no line
    the server printed holds the canary. (Recordings are checked decompressed by the callers.)"""
    for path in Path(server.data).rglob("*"):
        if path.is_file():
            assert not leaks(path.read_bytes(), name, value), path
    assert not leaks("\n".join(server.output), name, value)


def test_every_sandbox_process_starts_with_the_sandbox_environment(monkeypatch):
    """Below the server: a launcher made in a process whose environment holds the canary (as
    the server's did) starts warm and cold sandboxes, and none of them can read it."""
    name, value = canary()
    monkeypatch.setenv(name, value)
    launcher = Launcher(limits=TEST_LIMITS, pool_size=1)
    try:
        for _ in range(2):  # the first comes from the warm pool (if ready), the next cold
            node = launcher.start("hunter")
            try:
                reply = node.load(HUNT, "hunter.py", Api.AUTO, crowbot_info("hunter"))
                if isinstance(reply, (Yield, Finishing)):
                    reply = node.shutdown("test over")
                assert isinstance(reply, Exited)
                node.logs.drain()
                printed = "\n".join(node.logs.take())
            finally:
                node.close()
            assert "== /proc/1/environ" in printed, printed[-2000:]
            assert not leaks(printed, name, value), printed
            assert os.environ[name] == value  # the canary was there to be found
    finally:
        launcher.close()
