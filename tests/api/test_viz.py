"""The 3D view through the real server: the owner (and an instructor) get viser's client and a
websocket that reaches the run's viser server; another student gets exactly what a missing run
gets (404, close 4404); without a login 401 / close 4401; another site's page is refused."""

from __future__ import annotations

import time

import pytest
import viser
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

from server.api.auth import SESSION_COOKIE
from tests.api.conftest import start_crowbot_run, wait_for_end
from tests.viz.conftest import viser_messages

SUBPROTOCOL = f"viser-v{viser.__version__}"
ROBOT_WAIT_S = 10.0  # [s] a loaded test machine; the target (bench/bench_viz.py) is < 2 s


def socket_url(lab, run_id: str) -> str:
    return lab.url.replace("http", "ws", 1) + f"/api/runs/{run_id}/viz"


def browser_socket(lab, client, run_id: str, **options):
    """The websocket as the browser opens it: session cookie, same-origin Origin header."""
    cookie = client.cookies.get(SESSION_COOKIE)
    return connect(
        socket_url(lab, run_id),
        subprotocols=options.pop("subprotocols", [SUBPROTOCOL]),
        additional_headers={"Cookie": f"{SESSION_COOKIE}={cookie}"},
        origin=options.pop("origin", lab.url),
        max_size=None,
        **options,
    )


def messages_until(ws, wanted, timeout_s: float = ROBOT_WAIT_S) -> list[dict]:
    """Every viser message received until one satisfies `wanted`."""
    seen: list[dict] = []
    deadline = time.monotonic() + timeout_s
    while True:
        frame = ws.recv(timeout=max(0.01, deadline - time.monotonic()))
        seen.extend(viser_messages(frame))
        if any(wanted(message) for message in seen):
            return seen


def is_robot_moving(message: dict) -> bool:
    return message["type"] == "SetPositionMessage" and message.get("name") == "/robot"


def test_the_owner_watches_the_robot_live(lab):
    owner = lab.student("viewer")
    run_id = start_crowbot_run(owner, duration_s=30.0)
    opened = time.monotonic()
    redirect = owner.get(f"/api/runs/{run_id}/viz", follow_redirects=False)
    assert redirect.status_code == 307 and redirect.headers["location"] == "viz/"
    page = owner.get(f"/api/runs/{run_id}/viz/")
    assert page.status_code == 200 and "<title>Viser</title>" in page.text
    assert page.headers["content-type"].startswith("text/html")
    assert "frame-ancestors 'self'" in page.headers["content-security-policy"]
    with browser_socket(lab, owner, run_id) as ws:
        assert ws.subprotocol == SUBPROTOCOL
        seen = messages_until(ws, is_robot_moving)
        robot_s = time.monotonic() - opened
        print(f"\nopening the view -> robot in the scene: {robot_s:.3f} s")
        names = {message.get("name") for message in seen}
        assert {"/robot", "/robot/body", "/world/walls", "/world/floor"} <= names
        moves = [m for m in messages_until(ws, is_robot_moving) if is_robot_moving(m)]
        assert all(0.0 < m["position"][0] < 1.5 for m in moves)  # inside the 1.5 m arena
    assert robot_s < ROBOT_WAIT_S
    assert owner.post(f"/api/runs/{run_id}/stop").status_code == 200
    with lab.admin() as admin:  # an instructor sees every run's view
        assert admin.get(f"/api/runs/{run_id}/viz/").status_code == 200


def test_a_finished_run_replays_with_a_time_slider(lab):
    owner = lab.student("replayer")
    run_id = start_crowbot_run(owner, duration_s=1.0, clock="lockstep")
    assert wait_for_end(owner, run_id)["state"] == "finished"
    with browser_socket(lab, owner, run_id) as ws:
        seen = messages_until(ws, lambda m: m["type"] == "GuiSliderMessage")
        slider = next(m for m in seen if m["type"] == "GuiSliderMessage")
        assert slider["props"]["max"] == pytest.approx(1.0, abs=0.05)
        assert "/robot" in {m.get("name") for m in seen}


def test_another_student_gets_what_a_missing_run_gets(lab):
    owner = lab.student("private")
    run_id = start_crowbot_run(owner, duration_s=1.0, clock="lockstep")
    stranger = lab.student("stranger")
    for path in (f"/api/runs/{run_id}/viz", f"/api/runs/{run_id}/viz/", "/api/runs/nope/viz/"):
        answer = stranger.get(path, follow_redirects=False)
        assert answer.status_code == 404 and "no such run" in answer.json()["detail"], path
    for run in (run_id, "nope"):
        with browser_socket(lab, stranger, run) as ws, pytest.raises(ConnectionClosed) as closed:
            ws.recv(timeout=5)
        assert closed.value.rcvd.code == 4404
    wait_for_end(owner, run_id)


def test_without_login_401_and_close_4401(lab):
    owner = lab.student("shy")
    run_id = start_crowbot_run(owner, duration_s=1.0, clock="lockstep")
    anonymous = lab.client()
    answer = anonymous.get(f"/api/runs/{run_id}/viz/")
    assert answer.status_code == 401 and "invite link" in answer.json()["detail"]
    with (
        connect(socket_url(lab, run_id), subprotocols=[SUBPROTOCOL]) as ws,
        pytest.raises(ConnectionClosed) as closed,
    ):
        ws.recv(timeout=5)
    assert closed.value.rcvd.code == 4401
    wait_for_end(owner, run_id)


def test_another_sites_page_cannot_open_the_socket_and_a_stale_client_is_told(lab):
    owner = lab.student("careful")
    run_id = start_crowbot_run(owner, duration_s=1.0, clock="lockstep")
    with pytest.raises(InvalidStatus) as refused:
        browser_socket(lab, owner, run_id, origin="http://evil.example")
    assert refused.value.response.status_code == 403
    # A client of another viser version: viser's own 1002 reaches the browser.
    with (
        browser_socket(lab, owner, run_id, subprotocols=["viser-v0.0.1"]) as ws,
        pytest.raises(ConnectionClosed) as closed,
    ):
        ws.recv(timeout=5)
    assert closed.value.rcvd.code == 1002
    wait_for_end(owner, run_id)


def test_disabling_the_owner_closes_their_3d_view(lab):
    owner = lab.student("disabled-viewer")
    run_id = start_crowbot_run(owner, duration_s=60.0)
    with browser_socket(lab, owner, run_id) as ws:
        messages_until(ws, is_robot_moving)
        with lab.admin() as admin:
            assert admin.post(f"/api/admin/users/{owner.user['id']}/disable").status_code == 200
        with pytest.raises(ConnectionClosed) as closed:
            deadline = time.monotonic() + ROBOT_WAIT_S
            while time.monotonic() < deadline:
                ws.recv(timeout=max(0.01, deadline - time.monotonic()))
    assert closed.value.rcvd is not None and closed.value.rcvd.code == 1008
    assert closed.value.rcvd.reason == "your account was disabled"
    with lab.admin() as admin:
        wait_for_end(admin, run_id)
