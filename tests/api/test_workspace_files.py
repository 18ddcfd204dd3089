"""Data files in a workspace (CSV, YAML, JSON, TXT, launch files) next to the code: kept with
versions like code, refused with a sentence when too big, badly named or binary, and copied into
every node's working directory when a run names the workspace; what a node writes comes back as
an artifact."""

from __future__ import annotations

import pytest

from tests.api.conftest import wait_for_end

WAYPOINTS = "x,y\n0.5,0.0\n1.0,0.5\n1.5,0.5\n"
# Reads the workspace's CSV from its working directory and writes a file of its own.
CSV_NODE = """\
import csv

with open("waypoints.csv") as source:
    rows = list(csv.DictReader(source))
print("read", len(rows), "waypoints, last x", rows[-1]["x"])
with open("out.csv", "w") as out:
    out.write("n,x\\n")
    for n, row in enumerate(rows):
        out.write(f"{n},{float(row['x']) * 2}\\n")

RATE_HZ = 5


def step(obs):
    return None
"""


def test_data_files_are_kept_with_versions_and_listed_by_kind(lab):
    student = lab.student("packer")
    base = "/api/workspaces/crowbot/files"
    assert student.put(f"{base}/waypoints.csv", json={"code": WAYPOINTS}).json()["version"] == 1
    assert student.put(f"{base}/config/gains.yaml", json={"code": "kp: 2.0\n"}).status_code == 200
    assert student.put(f"{base}/two.launch", json={"code": "<launch/>\n"}).status_code == 200
    assert student.put(f"{base}/pid", json={"code": "x = 1\n"}).json()["filename"] == "pid.py"
    assert (
        student.put(f"{base}/config/gains.yaml", json={"code": "kp: 3.0\n"}).json()["version"] == 2
    )
    files = {f["filename"]: f for f in student.get("/api/workspaces/crowbot").json()["files"]}
    assert set(files) == {"waypoints.csv", "config/gains.yaml", "two.launch", "pid.py"}
    assert files["config/gains.yaml"]["code"] == "kp: 3.0\n"
    assert {name: f["kind"] for name, f in files.items()} == {
        "waypoints.csv": "data",
        "config/gains.yaml": "data",
        "two.launch": "data",
        "pid.py": "code",
    }
    versions = student.get(f"{base}/config/gains.yaml/versions").json()["versions"]
    assert [v["version"] for v in versions] == [2, 1]
    assert student.get(f"{base}/config/gains.yaml/versions/1").json()["code"] == "kp: 2.0\n"
    assert student.delete(f"{base}/waypoints.csv").json()["versions_removed"] == 1
    names = {f["filename"] for f in student.get("/api/workspaces/crowbot").json()["files"]}
    assert "waypoints.csv" not in names


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ("..%2F..%2Fetc%2Fpasswd", "'..'"),
        ("config%2F..%2F..%2Fx.csv", "'..'"),
        ("%2Fetc%2Fpasswd.txt", "absolute path"),
        ("C:%5Cwindows.txt", "absolute path"),
        (".bashrc.txt", "hidden"),
        ("config%2F.secret.yaml", "hidden"),
        ("a%2Fb%2Fc%2Fd.csv", "folders deep"),
        ("photo.png", "'.png' cannot be kept"),
        ("run.sh", "'.sh' cannot be kept"),
        ("1pid.py", "node name"),
        ("my%20file.csv", "only letters"),
        ("x" * 70 + ".csv", "longer than 64"),
    ],
)
def test_bad_file_names_are_refused_with_a_sentence(lab, name, words):
    student = lab.student("namer")
    answer = student.put(f"/api/workspaces/crowbot/files/{name}", json={"code": "1\n"})
    assert answer.status_code == 422, answer.text
    assert words in answer.json()["detail"]
    assert student.get("/api/workspaces/crowbot").json()["files"] == []


def test_binary_and_oversized_files_are_refused(lab):
    student = lab.student("uploader")
    base = "/api/workspaces/crowbot/files"
    binary = student.put(f"{base}/data.csv", json={"code": "a,b\n\x89PNG\x00\x01\n"})
    assert binary.status_code == 422
    assert "not text" in binary.json()["detail"] and "line 2" in binary.json()["detail"]
    # Text with tabs and Windows line ends is text.
    assert student.put(f"{base}/tabs.txt", json={"code": "a\tb\r\nc\td\r\n"}).status_code == 200

    huge = student.put(f"{base}/big.csv", json={"code": "1,2\n" * 300_000})  # 1.2 MB
    assert huge.status_code == 413
    assert "limit for a data file is 1048576 bytes" in huge.json()["detail"]
    big_code = student.put(f"{base}/big.py", json={"code": "#" * (300 * 1024)})
    assert big_code.status_code == 413 and "code file" in big_code.json()["detail"]

    chunk = "9" * (1000 * 1024) + "\n"  # just under the per-file cap: four fill the workspace
    for n in range(4):
        assert student.put(f"{base}/part{n}.csv", json={"code": chunk}).status_code == 200
    full = student.put(f"{base}/part4.csv", json={"code": chunk})
    assert full.status_code == 413 and "the limit is 4194304 bytes" in full.json()["detail"]
    # Replacing a file counts its new size, not both versions.
    assert student.put(f"{base}/part3.csv", json={"code": "small\n"}).status_code == 200
    names = {f["filename"] for f in student.get("/api/workspaces/crowbot").json()["files"]}
    assert names == {"tabs.txt", "part0.csv", "part1.csv", "part2.csv", "part3.csv"}


def test_a_run_from_a_workspace_gives_every_node_its_data_files(lab):
    student = lab.student("reader")
    base = "/api/workspaces/crowbot/files"
    student.put(f"{base}/waypoints.csv", json={"code": WAYPOINTS})
    started = student.post(
        "/api/runs",
        json={
            "robot": "crowbot",
            "world": "wall_approach",
            "workspace": "crowbot",
            "duration": 1.0,
            "nodes": [{"name": "reader", "code": CSV_NODE}],
        },
    )
    assert started.status_code == 201, started.text
    run = wait_for_end(student, started.json()["id"])
    assert run["state"] == "finished", run["reason"]
    logs = student.get(f"/api/runs/{run['id']}/logs").json()["nodes"]["reader"]
    assert any("read 3 waypoints, last x 1.5" in line for line in logs), logs
    artifacts = {a["name"] for a in student.get(f"/api/runs/{run['id']}/artifacts").json()["files"]}
    # The node's own file comes back; the unchanged input does not.
    assert any(name.endswith("out.csv") for name in artifacts), artifacts
    assert not any(name.endswith("waypoints.csv") for name in artifacts), artifacts
    out = next(name for name in artifacts if name.endswith("out.csv"))
    text = student.get(f"/api/runs/{run['id']}/artifacts/{out}").text
    assert text.splitlines() == ["n,x", "0,1.0", "1,2.0", "2,3.0"]


def test_a_run_without_the_workspace_or_with_someone_elses_file_gets_none(lab):
    owner = lab.student("owner")
    owner.put("/api/workspaces/crowbot/files/waypoints.csv", json={"code": WAYPOINTS})
    thief = lab.student("thief")
    # The thief names the same workspace: it is their own (empty) one, never the owner's.
    started = thief.post(
        "/api/runs",
        json={
            "robot": "crowbot",
            "world": "wall_approach",
            "workspace": "crowbot",
            "duration": 1.0,
            "nodes": [{"name": "reader", "code": CSV_NODE}],
        },
    )
    assert started.status_code == 201, started.text
    run = wait_for_end(thief, started.json()["id"])
    logs = "\n".join(thief.get(f"/api/runs/{run['id']}/logs").json()["nodes"]["reader"])
    assert "FileNotFoundError" in logs and "waypoints.csv" in logs
    assert "read 3 waypoints" not in logs
    answer = thief.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "workspace": "cooking",
              "nodes": [{"name": "a", "code": CSV_NODE}]},
    )  # fmt: skip
    assert answer.status_code == 404 and "crowbot" in answer.json()["valid"]
