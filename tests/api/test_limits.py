"""Limits that protect the lab, and input that must never become a 500: each refusal is a 4xx
with a sentence (422 naming the field, 404 listing the valid ids, 429 saying when to retry)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.api.conftest import STEP_CONTROLLER, LabServer, start_server, stop_server, wait_for_end

SPIN = 'RATE_HZ = 10\n\n\ndef step(obs):\n    return {"Control": (0.0, 0.3)}\n'


@pytest.fixture(scope="module")
def small_lab(tmp_path_factory) -> Iterator[LabServer]:
    server = start_server(
        tmp_path_factory.mktemp("small-lab"),
        {
            "ROBODOJO_MAX_RUNS_PER_STUDENT": "1",
            "ROBODOJO_MAX_RUNS_TOTAL": "2",
            "ROBODOJO_MAX_RUN_DURATION_S": "60",
            "ROBODOJO_MAX_CODE_BYTES_PER_FILE": "2000",
            "ROBODOJO_MAX_CODE_BYTES_PER_RUN": "3000",
            "ROBODOJO_RETRY_AFTER_S": "7",
            "ROBODOJO_SANDBOX_POOL": "1",
        },
    )
    yield server
    stop_server(server)


@pytest.fixture(autouse=True)
def _close_small_lab_clients(request) -> Iterator[None]:
    yield
    if "small_lab" in request.fixturenames:
        request.getfixturevalue("small_lab").close_clients()


def free_run(**changes) -> dict:
    body = {
        "robot": "crowbot",
        "world": "wall_approach",
        "nodes": [{"name": "spin", "code": SPIN}],
        "clock": "realtime",
        "duration": 30,
    }
    body.update(changes)
    return body


@pytest.mark.slow
def test_runs_at_once_per_student_and_in_total_are_429_with_when_to_retry(small_lab):
    ada, bob, cleo = (small_lab.student(name) for name in ("ada", "bob", "cleo"))
    first = ada.post("/api/runs", json=free_run())
    assert first.status_code == 201, first.text
    second = ada.post("/api/runs", json=free_run())
    assert second.status_code == 429
    assert second.headers["retry-after"] == "7"
    assert "limit is 1" in second.json()["detail"]
    assert bob.post("/api/runs", json=free_run()).status_code == 201
    full = cleo.post("/api/runs", json=free_run())
    assert full.status_code == 429 and "maximum of 2 runs" in full.json()["detail"]
    for client in (ada, bob):
        run_id = client.get("/api/runs").json()["runs"][0]["id"]
        assert client.post(f"/api/runs/{run_id}/stop").status_code == 200
        assert wait_for_end(client, run_id)["state"] == "interrupted"
    again = cleo.post("/api/runs", json=free_run(clock="lockstep", duration=1))
    assert again.status_code == 201, again.text
    assert wait_for_end(cleo, again.json()["id"])["state"] == "finished"


@pytest.mark.parametrize(
    ("changes", "words"),
    [
        ({"duration": 61}, "longer than this lab allows (60 s)"),
        ({"nodes": [{"name": "big", "code": "#" * 2001}]}, "limit per file is 2000"),
        (
            {"nodes": [{"name": f"n{i}", "code": "#" * 1500} for i in range(3)]},
            "limit per run is 3000",
        ),
    ],
)
def test_size_and_duration_limits_are_422_sentences(small_lab, changes, words):
    student = small_lab.student("sizer")
    answer = student.post("/api/runs", json=free_run(**changes))
    assert answer.status_code == 422
    assert words in answer.json()["detail"]


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"robot": "crowbot", "world": "wall_approach"}, "body.nodes"),
        (free_run(nodes=[{"name": "1bad", "code": ""}]), "body.nodes.0.name"),
        (free_run(nodes=[{"name": "ok", "code": 5}]), "body.nodes.0.code"),
        (free_run(duration=-1), "body.duration"),
        (free_run(duration="long"), "body.duration"),
        (free_run(seed=-3), "body.seed"),
        (free_run(clock="warp"), "body.clock"),
        (free_run(extra=1), "body.extra"),
        (free_run(nodes=[]), "body.nodes"),
    ],
)
def test_invalid_input_is_422_with_the_field_path(lab, body, field):
    student = lab.student("typo")
    answer = student.post("/api/runs", json=body)
    assert answer.status_code == 422, answer.text
    paths = [problem["field"] for problem in answer.json()["errors"]]
    assert field in paths
    assert answer.json()["detail"].startswith(paths[0])


@pytest.mark.parametrize(
    ("body", "valid"),
    [
        (free_run(robot="crowbott"), "crowbot"),
        (free_run(world="moon"), "wall_approach"),
        ({"exercise": "nope", "nodes": [{"name": "a", "code": ""}]}, "crowbot_distance_pid"),
    ],
)
def test_unknown_ids_are_404_with_the_valid_ones(lab, body, valid):
    student = lab.student("lost")
    answer = student.post("/api/runs", json=body)
    assert answer.status_code == 404
    assert valid in answer.json()["valid"] and valid in answer.json()["detail"]


def test_a_robot_in_a_world_not_meant_for_it_is_422(lab):
    answer = lab.student("mix").post("/api/runs", json=free_run(world="crop_rows"))
    assert answer.status_code == 422 and "cannot be placed" in answer.json()["detail"]


GARBAGE = [
    "",
    "null",
    "[]",
    "{",
    '{"nodes": null}',
    '{"nodes": [null]}',
    '{"nodes": [{"name": "a", "code": "x"}], "robot": {"$gt": ""}}',
    '{"nodes": [{"name": "a", "code": "x"}], "exercise": "../../etc/passwd"}',
    '{"nodes": [{"name": "a", "code": "x"}], "robot": "crowbot", "world": "wall_approach",'
    ' "duration": 1e309}',
    '{"nodes": [{"name": "a", "code": "\\ud800"}], "robot": "crowbot", "world": "wall_approach"}',
    "\x00\xff",
]


@pytest.mark.parametrize("body", GARBAGE)
def test_garbage_bodies_never_500(lab, body):
    student = lab.student("fuzzer")
    answer = student.post(
        "/api/runs", content=body.encode("utf-8", "surrogatepass"),
        headers={"content-type": "application/json"},
    )  # fmt: skip
    assert 400 <= answer.status_code < 500, answer.text
    assert isinstance(answer.json()["detail"], str)


@pytest.mark.parametrize(
    "url",
    [
        "/api/runs/..%2F..%2Fetc%2Fpasswd",
        "/api/runs/" + "x" * 5000,
        "/api/runs/%00",
        "/api/exercises/%2e%2e",
        "/api/workspaces/crowbot/files/..%2Fsecret/versions",
        "/api/workspaces/nope",
        "/api/workspaces/crowbot/files/a.py/versions/-1",
        "/api/workspaces/crowbot/files/a.py/versions/99999999999999999999999",
        "/api/runs?limit=100000",
        "/api/runs?offset=-5",
    ],
)
def test_odd_urls_are_4xx_never_500(lab, url):
    answer = lab.student("prober").get(url)
    assert 400 <= answer.status_code < 500, (url, answer.status_code, answer.text)


def test_a_huge_body_is_refused_before_it_is_read(lab):
    answer = lab.student("hoarder").post(
        "/api/runs", content=b"x" * (5 * 1024 * 1024), headers={"content-type": "application/json"}
    )
    assert answer.status_code == 413 and "larger than" in answer.json()["detail"]


def test_workspace_file_limits(small_lab):
    student = small_lab.student("writer")
    too_big = student.put("/api/workspaces/crowbot/files/a.py", json={"code": "#" * 2001})
    assert (
        too_big.status_code == 413
        and "limit for a code file is 2000 bytes" in (too_big.json()["detail"])
    )
    bad_name = student.put("/api/workspaces/crowbot/files/-x.py", json={"code": ""})
    assert bad_name.status_code == 422


def test_stop_of_an_ended_run_is_409_with_its_state(lab):
    student = lab.student("late")
    started = student.post("/api/runs", json=free_run(clock="lockstep", duration=1))
    run_id = started.json()["id"]
    wait_for_end(student, run_id)
    answer = student.post(f"/api/runs/{run_id}/stop")
    assert answer.status_code == 409 and "has ended (finished)" in answer.json()["detail"]


def test_pausing_a_realtime_run_says_why_not(lab):
    student = lab.student("pauser")
    run_id = student.post("/api/runs", json=free_run(duration=20)).json()["id"]
    answer = student.post(f"/api/runs/{run_id}/pause")
    assert answer.status_code == 409 and "only a lockstep" in answer.json()["detail"]
    student.post(f"/api/runs/{run_id}/stop")
    wait_for_end(student, run_id)


def test_code_of_the_run_is_kept(lab):
    student = lab.student("keeper")
    run_id = student.post(
        "/api/runs",
        json=free_run(clock="lockstep", duration=1, nodes=[{"name": "d", "code": STEP_CONTROLLER}]),
    ).json()["id"]
    run = wait_for_end(student, run_id)
    assert run["state"] == "finished"
    assert run["code"] == [{"name": "d", "code": STEP_CONTROLLER}]
    listed = student.get("/api/runs").json()["runs"][0]
    assert listed["id"] == run_id and "code" not in listed  # listings stay small


ODD_VALUES = ["0", "-1", "99999999999999999999999", "1e309", "NaN", "..", "%00", "é", "x" * 300]


@pytest.mark.slow
def test_every_documented_route_survives_odd_parameters(lab):
    """Each route of the OpenAPI document, with each path and query parameter set to odd
    values in turn, as a student and as the instructor: a 4xx at worst, never a 500."""
    student = lab.student("odd")
    admin = lab.admin()
    spec = student.get("/openapi.json").json()
    tried = 0
    for path, methods in spec["paths"].items():
        for method, operation in methods.items():
            parameters = operation.get("parameters", [])
            for value in ODD_VALUES:
                url = path
                query = {}
                for parameter in parameters:
                    if parameter["in"] == "path":
                        url = url.replace("{" + parameter["name"] + "}", value)
                    elif parameter["in"] == "query":
                        query[parameter["name"]] = value
                for client in (student, admin):
                    answer = client.request(method.upper(), url, params=query, json={})
                    tried += 1
                    assert answer.status_code < 500, (method, url, query, answer.text)
    assert tried > 200
