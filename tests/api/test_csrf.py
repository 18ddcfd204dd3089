"""Issue 14, findings 2 and 6: a page on another origin (another port of the lab's host, a sibling
subdomain) cannot change anything with a student's or instructor's cookie, cannot open their
live websocket, and cannot switch their browser to another account; a disabled user's open
sockets close; resume/pause that would do nothing answer 409."""

from __future__ import annotations

import json
import time

import pytest
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

from server.api.auth import SESSION_COOKIE
from tests.api.conftest import start_crowbot_run, wait_for_end
from tests.waiting import wait_until

OTHER_PORT = "http://127.0.0.1:1"  # another port of the lab's host: same site, other origin


def browser(lab, token: str):
    """A browser that opened `token`'s invite link: holds the cookie, sends the lab's Origin."""
    client = lab.client()
    client.headers["Origin"] = lab.url
    assert client.get(f"/login?token={token}", follow_redirects=False).status_code == 303
    return client


def live_socket(lab, client, run_id: str, origin: str):
    cookie = client.cookies.get(SESSION_COOKIE)
    return connect(
        lab.url.replace("http", "ws", 1) + f"/api/runs/{run_id}/live",
        additional_headers={"Cookie": f"{SESSION_COOKIE}={cookie}"},
        origin=origin,
    )


def test_a_cookie_state_change_from_another_origin_is_refused(lab):
    target, _ = lab.new_user("target")
    instructor = browser(lab, lab.admin_token)
    path = f"/api/admin/users/{target['id']}/disable"
    for headers in ({"Origin": OTHER_PORT}, {"Origin": "null"}, {"Sec-Fetch-Site": "same-site"}):
        answer = instructor.post(path, headers=headers)
        assert answer.status_code == 403, (headers, answer.text)
        assert "lab's own page" in answer.json()["detail"]
    with lab.admin() as admin:
        assert admin.get(f"/api/admin/users/{target['id']}").json()["disabled"] is False
    # The lab's own page (Origin and Sec-Fetch-Site as Chromium sends them) goes through...
    answer = instructor.post(path, headers={"Sec-Fetch-Site": "same-origin"})
    assert answer.status_code == 200, answer.text
    assert answer.json()["disabled"] is True
    # ... and a script with a Bearer token is not a browser: no Origin rule applies to it.
    with lab.admin() as admin:
        answer = admin.post(
            f"/api/admin/users/{target['id']}/token", headers={"Origin": OTHER_PORT}
        )
    assert answer.status_code == 200, answer.text


def test_the_live_websocket_refuses_another_origin(lab):
    student = lab.student("watched")
    run_id = start_crowbot_run(student, clock="lockstep", duration_s=1.0)
    with pytest.raises(InvalidStatus) as refused:
        live_socket(lab, student, run_id, OTHER_PORT)
    assert refused.value.response.status_code == 403
    # The server's log reaches lab.output through a pump thread, a moment after the 403.
    wait_until(
        lambda: any("not the lab's origin" in line for line in lab.output),
        10,
        "the server logged the refused origin",
    )
    with live_socket(lab, student, run_id, lab.url) as ws:  # the lab's own page still may
        assert json.loads(ws.recv(timeout=10))["type"] == "snapshot"
    wait_for_end(student, run_id)


def test_a_login_link_asks_before_switching_a_signed_in_browser(lab):
    victim = lab.student("victim")
    other, other_token = lab.new_user("mallory")
    page = victim.get(f"/login?token={other_token}", follow_redirects=False)
    assert page.status_code == 200, page.text
    assert "You are signed in as <strong>victim</strong>" in page.text
    assert "Sign in as <strong>mallory</strong> instead?" in page.text
    assert victim.get("/api/me").json()["name"] == "victim"  # nothing switched yet
    # Another site's page cannot press the button for them.
    forged = victim.post(
        "/login",
        data={"token": other_token},
        headers={"Origin": OTHER_PORT},
        follow_redirects=False,
    )
    assert forged.status_code == 403
    assert victim.get("/api/me").json()["name"] == "victim"
    confirmed = victim.post("/login", data={"token": other_token}, follow_redirects=False)
    assert confirmed.status_code == 303, confirmed.text
    assert victim.get("/api/me").json()["id"] == other["id"]
    # A browser with no session is logged in at once, as before.
    fresh = lab.client()
    assert fresh.get(f"/login?token={other_token}", follow_redirects=False).status_code == 303


def test_disabling_a_user_closes_their_open_live_socket(lab):
    student = lab.student("soon-disabled")
    run_id = start_crowbot_run(student)
    with live_socket(lab, student, run_id, lab.url) as ws:
        assert json.loads(ws.recv(timeout=10))["type"] == "snapshot"
        with lab.admin() as admin:
            answer = admin.post(f"/api/admin/users/{student.user['id']}/disable")
        assert answer.status_code == 200, answer.text
        deadline = time.monotonic() + 10
        with pytest.raises(ConnectionClosed) as closed:
            while time.monotonic() < deadline:
                ws.recv(timeout=max(0.01, deadline - time.monotonic()))
    assert closed.value.rcvd is not None and closed.value.rcvd.code == 1008
    assert closed.value.rcvd.reason == "your account was disabled"
    with lab.admin() as admin:
        wait_for_end(admin, run_id)


def test_resume_of_a_running_run_and_pause_of_a_paused_one_answer_409(lab):
    student = lab.student("pauser")
    run_id = start_crowbot_run(student, clock="lockstep", duration_s=120.0)
    deadline = time.monotonic() + 30
    while student.get(f"/api/runs/{run_id}").json()["state"] != "running":
        assert time.monotonic() < deadline, "the run did not start"
        time.sleep(0.1)
    answer = student.post(f"/api/runs/{run_id}/resume")
    assert answer.status_code == 409 and "not paused" in answer.json()["detail"], answer.text
    assert student.post(f"/api/runs/{run_id}/pause").status_code == 200
    while student.get(f"/api/runs/{run_id}").json()["state"] != "paused":
        assert time.monotonic() < deadline, "the run did not pause"
        time.sleep(0.1)
    answer = student.post(f"/api/runs/{run_id}/pause")
    assert answer.status_code == 409 and "already paused" in answer.json()["detail"], answer.text
    assert student.post(f"/api/runs/{run_id}/resume").status_code == 200
    student.post(f"/api/runs/{run_id}/stop")
    wait_for_end(student, run_id)


@pytest.mark.slow
def test_behind_a_proxy_the_public_url_is_the_labs_origin_too(tmp_path):
    from tests.api.conftest import start_server, stop_server

    public = "https://lab.example.org"
    server = start_server(tmp_path / "lab", {"ROBODOJO_PUBLIC_URL": public})
    try:
        instructor = browser(server, server.admin_token)
        for origin in (public, "https://lab.example.org:443", server.url):
            answer = instructor.post(
                "/api/admin/users", json={"name": "via proxy"}, headers={"Origin": origin}
            )
            assert answer.status_code == 201, (origin, answer.text)
        answer = instructor.post(
            "/api/admin/users", json={"name": "x"}, headers={"Origin": "https://evil.example.org"}
        )
        assert answer.status_code == 403, answer.text
    finally:
        stop_server(server)
