"""Who sees what: every route that names a run answers another student 404 (not 403, not the
data), over HTTP and the websocket; every admin route answers a student 404; without a login,
401 with what to do. The route lists come from the app itself, so a new route without a test
here fails `test_every_route_is_covered`."""

from __future__ import annotations

import json

import pytest
from fastapi.routing import APIRoute, APIWebSocketRoute
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from server.api.app import create_app
from tests.api.conftest import wait_for_end

SAVER = """\
RATE_HZ = 10


def step(obs):
    if obs.time > 0.5:
        with open("notes.txt", "w") as f:
            f.write("hello")
    print("tick")
    return {"Control": (0.0, 0.3)}
"""

# Every route that takes a run id, with a request that works for the run's owner.
RUN_ROUTES = {
    ("GET", "/api/runs/{run_id}"): "/api/runs/{id}",
    ("POST", "/api/runs/{run_id}/stop"): "/api/runs/{id}/stop",
    ("POST", "/api/runs/{run_id}/estop"): "/api/runs/{id}/estop",
    ("POST", "/api/runs/{run_id}/pause"): "/api/runs/{id}/pause",
    ("POST", "/api/runs/{run_id}/resume"): "/api/runs/{id}/resume",
    ("GET", "/api/runs/{run_id}/recording.mcap"): "/api/runs/{id}/recording.mcap",
    ("GET", "/api/runs/{run_id}/csv"): "/api/runs/{id}/csv",
    ("GET", "/api/runs/{run_id}/csv/{name}"): "/api/runs/{id}/csv/Distance.csv",
    ("GET", "/api/runs/{run_id}/logs"): "/api/runs/{id}/logs",
    ("GET", "/api/runs/{run_id}/logs/{node}.log"): "/api/runs/{id}/logs/saver.log",
    ("GET", "/api/runs/{run_id}/metrics.json"): "/api/runs/{id}/metrics.json",
    ("GET", "/api/runs/{run_id}/graph"): "/api/runs/{id}/graph",
    ("GET", "/api/runs/{run_id}/comparison"): "/api/runs/{id}/comparison",  # 409: a sim run
    ("GET", "/api/runs/{run_id}/viz"): "/api/runs/{id}/viz",
    ("GET", "/api/runs/{run_id}/viz/{asset:path}"): "/api/runs/{id}/viz/",
    ("GET", "/api/runs/{run_id}/artifacts"): "/api/runs/{id}/artifacts",
    ("GET", "/api/runs/{run_id}/artifacts/{name:path}"): "/api/runs/{id}/artifacts/saver/notes.txt",
}
# Routes on the caller's own things with no id of someone else's in them: another student
# reaches only their own (empty) data; shown by test_workspaces_are_private.
OWN_ROUTES = {"/api/workspaces/", "/api/me", "/api/logout", "/api/session", "/api/hardware",
              # The editor's help reads only the text it is sent and the catalogue (login and
              # origin: tests/api/test_editor.py::test_routes_need_a_login, ..._another_origin).
              "/api/editor/"}  # fmt: skip
# Routes on a course's leaderboards: a student reaches only their own courses' boards (another's
# is 404, like one that does not exist) and gets 404 on the instructor's; shown by
# tests/api/test_leaderboards.py::test_a_student_sees_only_their_own_courses_boards.
BOARD = "/api/courses/{course_id}/leaderboards/{exercise_id}"
COURSE_ROUTES = {
    ("GET", "/api/courses"),
    ("GET", BOARD),
    ("PUT", f"{BOARD}/settings"),
    ("POST", f"{BOARD}/reset"),
}
# Routes that take run ids in their query: another student's run is 404, as for RUN_ROUTES;
# shown by tests/api/test_checks.py::test_the_summary_reads_only_the_callers_runs_of_that_exercise.
QUERY_RUN_ROUTES = {("GET", "/api/exercises/{exercise_id}/check")}
PUBLIC_ROUTES = {"/login", "/", "/admin", "/api/health"}


def app_routes() -> list[tuple[str, str]]:
    """(method, path) of every route, through included routers (our routers add no prefix
    when included, so a route's own path is the full path)."""
    routes = []

    def walk(items) -> None:
        for route in items:
            if isinstance(route, APIRoute):
                routes.extend((method, route.path) for method in sorted(route.methods))
            elif isinstance(route, APIWebSocketRoute):
                routes.append(("WS", route.path))
            elif hasattr(route, "original_router"):  # FastAPI's included router
                walk(route.original_router.routes)

    walk(create_app().routes)
    assert len(routes) > 30, routes
    return routes


def test_every_route_is_covered():
    for method, path in app_routes():
        if path.startswith(("/docs", "/openapi", "/redoc")) or path in PUBLIC_ROUTES:
            continue
        if path.startswith("/api/admin/"):
            continue  # test_students_get_404_on_every_admin_route takes them all
        if (method, path) in COURSE_ROUTES or (method, path) in QUERY_RUN_ROUTES:
            continue
        if "{run_id}" in path:
            assert (method, path) in RUN_ROUTES or method == "WS", f"untested: {method} {path}"
            continue
        assert path.startswith(tuple(OWN_ROUTES)) or path in (
            "/api/runs",
            "/api/robots",
            "/api/worlds",
            "/api/exercises",
            "/api/exercises/{exercise_id}",
        ), f"a new route needs an access test: {method} {path}"


@pytest.fixture(scope="module")
def finished_run(lab):
    owner = lab.student("owner")
    started = owner.post(
        "/api/runs",
        json={
            "robot": "crowbot",
            "world": "wall_approach",
            "nodes": [{"name": "saver", "code": SAVER}],
            "duration": 2,
        },
    )
    assert started.status_code == 201, started.text
    run = wait_for_end(owner, started.json()["id"])
    assert run["state"] == "finished", run["reason"]
    return owner.token, run["id"]  # clients close after each test; the token lasts


@pytest.mark.parametrize(("method", "path"), sorted(RUN_ROUTES))
def test_another_student_gets_404_for_a_run_route(lab, finished_run, method, path):
    owner_token, run_id = finished_run
    owner = lab.client(owner_token)
    url = RUN_ROUTES[(method, path)].format(id=run_id)
    stranger = lab.student("stranger")
    answer = stranger.request(method, url)
    assert answer.status_code == 404, answer.text
    assert run_id not in answer.text or "no such run" in answer.text
    mine = owner.request(method, url)
    # The owner reaches the same route (an ended run refuses controls with 409, not 404).
    # (307: the 3D view's address without its slash redirects to it.)
    assert mine.status_code in (200, 307, 409), (url, mine.text)
    with lab.admin() as admin:
        assert admin.request(method, url).status_code in (200, 307, 409)


def test_another_student_cannot_watch_a_run(lab, finished_run):
    _, run_id = finished_run
    stranger = lab.student("peeker")
    url = lab.url.replace("http", "ws") + f"/api/runs/{run_id}/live?token={stranger.token}"
    with connect(url) as ws, pytest.raises(ConnectionClosed) as closed:
        ws.recv(timeout=5)
    assert closed.value.rcvd.code == 4404


def test_the_owner_watches_an_ended_run_to_its_end(lab, finished_run):
    owner_token, run_id = finished_run
    url = lab.url.replace("http", "ws") + f"/api/runs/{run_id}/live?token={owner_token}"
    with connect(url) as ws:
        frames = []
        while not frames or frames[-1]["type"] != "end":
            frames.append(json.loads(ws.recv(timeout=10)))
    assert frames[0]["type"] == "snapshot" and frames[-1]["state"] == "finished"


def test_without_login_the_api_says_how_to_log_in(lab):
    anonymous = lab.client()
    for url in ("/api/runs", "/api/robots", "/api/admin/users", "/api/workspaces/crowbot"):
        answer = anonymous.get(url)
        assert answer.status_code == 401
        assert "invite link" in answer.json()["detail"]
    assert anonymous.get("/api/me", headers={"Authorization": "Bearer nonsense"}).status_code == 401
    assert lab.client().get("/login?token=nonsense").status_code == 401


def test_students_get_404_on_every_admin_route(lab):
    student = lab.student("curious")
    admin_routes = [(m, p) for m, p in app_routes() if p.startswith("/api/admin/")]
    assert len(admin_routes) >= 8
    for method, path in admin_routes:
        url = path.replace("{", "").replace("}", "")  # any id: the check comes first
        answer = student.request(method, url, json={})
        assert answer.status_code == 404, (method, path, answer.text)


def test_workspaces_are_private(lab):
    ada = lab.student("ada")
    bob = lab.student("bob")
    assert ada.put("/api/workspaces/crowbot/files/secret.py", json={"code": "x = 1"}).is_success
    assert bob.get("/api/workspaces/crowbot").json()["files"] == []
    for url in (
        "/api/workspaces/crowbot/files/secret.py/versions",
        "/api/workspaces/crowbot/files/secret.py/versions/1",
    ):
        assert bob.get(url).status_code == 404
        assert ada.get(url).status_code == 200
    assert bob.post("/api/workspaces/crowbot/files/secret.py/versions/1/restore").status_code == 404


def test_a_disabled_student_is_logged_out_and_their_run_stops(lab):
    student = lab.student("leaving")
    started = student.post(
        "/api/runs",
        json={
            "robot": "crowbot",
            "world": "wall_approach",
            "nodes": [{"name": "saver", "code": SAVER}],
            "clock": "realtime",
            "duration": 60,
        },
    )
    assert started.status_code == 201
    with lab.admin() as admin:
        answer = admin.post(f"/api/admin/users/{student.user['id']}/disable")
        assert answer.status_code == 200 and answer.json()["disabled"] is True
        run = wait_for_end(admin, started.json()["id"])
    assert run["state"] == "interrupted" and "disabled" in run["reason"]
    assert student.get("/api/me").status_code == 401  # the cookie's session ended
    assert lab.client(student.token).get("/api/me").status_code == 401  # and the token
