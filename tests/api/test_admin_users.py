"""Instructor admin API for users, runs and the server's status."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta

from tests.api.conftest import STEP_CONTROLLER, wait_for_end


def test_bulk_import_from_csv_gives_each_student_a_working_invite(lab):
    admin = lab.admin()
    csv_text = (
        'name,email\nAda Lovelace,ada@example.org\n"Hopper, Grace",\nAlan Turing,alan@example.org\n'
    )
    answer = admin.post(
        "/api/admin/users/bulk", content=csv_text.encode(), headers={"content-type": "text/csv"}
    )
    assert answer.status_code == 201, answer.text
    users = answer.json()["users"]
    assert [u["name"] for u in users] == ["Ada Lovelace", "Hopper, Grace", "Alan Turing"]
    assert [u["email"] for u in users] == ["ada@example.org", None, "alan@example.org"]
    assert all(u["role"] == "student" for u in users)
    for user in users:
        assert user["invite_url"].endswith(f"/login?token={user['token']}")
        browser = lab.client()
        assert (
            browser.get(f"/login?token={user['token']}", follow_redirects=False).status_code == 303
        )
        assert browser.get("/api/me").json()["id"] == user["id"]
    listed = {u["id"]: u for u in admin.get("/api/admin/users").json()["users"]}
    assert "token" not in listed[users[0]["id"]]  # shown once, at creation


def test_a_bad_csv_says_which_line(lab):
    admin = lab.admin()
    no_header = admin.post("/api/admin/users/bulk", content=b"Ada\nBob\n")
    assert no_header.status_code == 422 and "'name' column" in no_header.json()["detail"]
    bad_email = admin.post(
        "/api/admin/users/bulk", content=b"name,email\nAda,ada@x.org\nBob,nope\n"
    )
    assert bad_email.status_code == 422 and "line 3" in bad_email.json()["detail"]
    not_utf8 = admin.post("/api/admin/users/bulk", content=b"name\n\xff\xfe\n")
    assert not_utf8.status_code == 422 and "UTF-8" in not_utf8.json()["detail"]


def test_a_new_token_retires_the_old_one(lab):
    admin = lab.admin()
    user, token = lab.new_user("renewed")
    answer = admin.post(f"/api/admin/users/{user['id']}/token")
    assert answer.status_code == 200
    assert lab.client(token).get("/api/me").status_code == 401
    assert lab.client(answer.json()["token"]).get("/api/me").json()["name"] == "renewed"


def test_disabled_users_can_be_enabled_and_an_instructor_cannot_disable_themselves(lab):
    admin = lab.admin()
    user, token = lab.new_user("paused")
    assert admin.patch(f"/api/admin/users/{user['id']}", json={"disabled": True}).is_success
    assert lab.client(token).get("/api/me").status_code == 401
    assert admin.patch(f"/api/admin/users/{user['id']}", json={"disabled": False}).is_success
    assert lab.client(token).get("/api/me").status_code == 200
    me = admin.get("/api/me").json()
    refused = admin.patch(f"/api/admin/users/{me['id']}", json={"disabled": True})
    assert refused.status_code == 422 and "yourself" in refused.json()["detail"]
    assert admin.get("/api/admin/users/nobody").status_code == 404


def test_the_session_cookie_is_secure_behind_tls(lab):
    _, token = lab.new_user("tls")
    answer = lab.client().get(
        f"/login?token={token}", headers={"X-Forwarded-Proto": "https"}, follow_redirects=False
    )
    cookie = answer.headers["set-cookie"].lower()
    assert "; secure" in cookie
    plain = lab.client().get(f"/login?token={token}", follow_redirects=False)
    assert "secure" not in plain.headers["set-cookie"].lower()


def test_admin_run_filters_and_status(lab):
    admin = lab.admin()
    student = lab.student("filtered")
    started = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "duration": 1,
              "nodes": [{"name": "d", "code": STEP_CONTROLLER}]},
    )  # fmt: skip
    run_id = started.json()["id"]
    wait_for_end(student, run_id)
    mine = {"user": student.user["id"]}
    assert [r["id"] for r in admin.get("/api/admin/runs", params=mine).json()["runs"]] == [run_id]
    assert admin.get("/api/admin/runs", params={**mine, "state": "failed"}).json()["total"] == 0
    later = (datetime.now(UTC) + timedelta(hours=1)).isoformat()
    assert admin.get("/api/admin/runs", params={**mine, "since": later}).json()["total"] == 0
    bad = admin.get("/api/admin/runs", params={"state": "exploded"})
    assert bad.status_code == 422 and "query.state" in bad.json()["detail"]
    status = admin.get("/api/admin/status").json()
    assert status["runs"]["max_runs_total"] >= 1
    (web,) = status["runs"]["workers"]  # --workers 0: the web process runs every run
    assert web["role"] == "web process: every run"
    assert web["capacity"] == status["runs"]["max_runs_total"]
    assert status["server"]["rss_mib"] > 10
    assert status["database"] in ("sqlite", "postgresql")
    assert status["machine"]["cpus"] >= 1


def test_pages_learn_who_is_logged_in_without_a_401(lab):
    assert lab.client().get("/api/session").json() == {"user": None}
    student = lab.student("pager")
    assert student.get("/api/session").json()["user"]["role"] == "student"


def test_the_login_link_lands_instructors_on_their_console(lab):
    landing = lab.client().get(f"/login?token={lab.admin_token}", follow_redirects=False)
    assert landing.headers["location"] == "/admin"
    _, token = lab.new_user("lander")
    assert (
        lab.client().get(f"/login?token={token}", follow_redirects=False).headers["location"] == "/"
    )


def test_active_runs_with_their_students_names(lab):
    admin = lab.admin()
    student = lab.student("Named Student")
    run_id = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "clock": "realtime", "duration": 30,
              "nodes": [{"name": "d", "code": STEP_CONTROLLER}]},
    ).json()["id"]  # fmt: skip
    active = admin.get("/api/admin/runs", params={"state": "active"}).json()["runs"]
    mine = [r for r in active if r["id"] == run_id]
    assert mine and mine[0]["user_name"] == "Named Student"
    student.post(f"/api/runs/{run_id}/stop")
    wait_for_end(student, run_id)
    active = admin.get("/api/admin/runs", params={"state": "active"}).json()["runs"]
    assert run_id not in [r["id"] for r in active]


def test_a_bad_email_is_a_sentence_not_a_pattern(lab):
    answer = lab.admin().post("/api/admin/users", json={"name": "x", "email": "nope"})
    assert answer.status_code == 422
    assert "does not look like an email address" in answer.json()["detail"]
    assert "^" not in answer.json()["detail"]
