"""Courses over the real server: create, list, delete; enrol and unenrol; the exercises set;
the grade book CSV from a real, scored exercise run. Students get 404 for all of it, and no
input makes the server answer 500."""

from __future__ import annotations

import csv
import io
import time
import uuid

import pytest

from server.exercises.registry import get_exercise
from tests.api.conftest import wait_for_end

EXERCISE = "crowbot_distance_pid"
GRADES_HEADER = [
    "student_id",
    "student_name",
    "email",
    "exercise",
    "best_score",
    "attempts",
    "best_run_id",
    "best_run_url",
]


def wait_for_judged(client, run_id: str, timeout_s: float = 120.0) -> dict:
    """The run once its checks are stored: an exercise run reads 'finished' a moment before
    its judged score is in the store."""
    run = wait_for_end(client, run_id, timeout_s)
    deadline = time.monotonic() + 10.0
    while run["score"] is None and run["state"] == "finished" and time.monotonic() < deadline:
        time.sleep(0.1)
        run = client.get(f"/api/runs/{run_id}").json()
    return run


def unique(name: str) -> str:
    """Course names are unique across the whole (session-wide) server."""
    return f"{name} {uuid.uuid4().hex[:6]}"


def new_course(admin, name: str) -> dict:
    made = admin.post("/api/admin/courses", json={"name": unique(name)})
    assert made.status_code == 201, made.text
    return made.json()


def rows_of(answer) -> list[dict]:
    assert answer.status_code == 200, answer.text
    assert answer.headers["content-type"].startswith("text/csv")
    reader = csv.DictReader(io.StringIO(answer.text))
    assert reader.fieldnames == GRADES_HEADER
    return list(reader)


@pytest.fixture(scope="module")
def scored(lab):
    """A student with two runs of the exercise: the reference solution, run for the exercise's
    whole duration (judged, score > 0), then a second try stopped at once (an attempt, no
    better score). The run takes a few seconds of wall time: it is made once per module."""
    student = lab.student("Lovelace, Ada")
    exercise = get_exercise(EXERCISE)
    nodes = [
        {"name": name, "code": exercise.code_path(path).read_text("utf-8")}
        for name, path in exercise.reference
    ]
    started = student.post("/api/runs", json={"exercise": EXERCISE, "nodes": nodes})
    assert started.status_code == 201, started.text
    best = wait_for_judged(student, started.json()["id"])
    assert best["state"] == "finished", best
    assert best["duration_s"] == exercise.duration_s
    assert best["score"] is not None and best["score"] > 0, best["checks"]

    again = student.post("/api/runs", json={"exercise": EXERCISE, "nodes": nodes})
    assert again.status_code == 201, again.text
    student.post(f"/api/runs/{again.json()['id']}/stop")
    stopped = wait_for_end(student, again.json()["id"])
    assert stopped["state"] != "finished"
    return student, best, stopped


# ------------------------------------------------------------------------------ courses
def test_course_create_list_get_delete(lab):
    with lab.admin() as admin:
        name = unique("Robotics 101")
        made = admin.post("/api/admin/courses", json={"name": name})
        assert made.status_code == 201, made.text
        course = made.json()
        assert course["name"] == name and len(course["id"]) == 32
        assert course["students"] == [] and course["exercises"] == []

        again = admin.post("/api/admin/courses", json={"name": name})
        assert again.status_code == 409
        assert name in again.json()["detail"] and "choose another name" in again.json()["detail"]

        listed = admin.get("/api/admin/courses").json()["courses"]
        mine = [c for c in listed if c["id"] == course["id"]]
        assert mine and mine[0]["student_count"] == 0 and mine[0]["name"] == name
        assert admin.get(f"/api/admin/courses/{course['id']}").json()["name"] == name

        deleted = admin.delete(f"/api/admin/courses/{course['id']}")
        assert deleted.status_code == 200 and deleted.json()["ok"] is True
        gone = admin.get(f"/api/admin/courses/{course['id']}")
        assert gone.status_code == 404 and "GET /api/admin/courses" in gone.json()["detail"]
        assert admin.delete(f"/api/admin/courses/{course['id']}").status_code == 404
        listed = admin.get("/api/admin/courses").json()["courses"]
        assert all(c["id"] != course["id"] for c in listed)
        # The name is free again.
        assert admin.post("/api/admin/courses", json={"name": name}).status_code == 201


@pytest.mark.parametrize(
    "body",
    [{}, {"name": ""}, {"name": "   "}, {"name": "x" * 121}, {"name": 5}, {"name": "a", "x": 1}],
)
def test_course_create_refuses_bad_bodies(lab, body):
    with lab.admin() as admin:
        answer = admin.post("/api/admin/courses", json=body)
    assert answer.status_code == 422, answer.text
    assert answer.json()["detail"]


def test_enrol_and_unenrol(lab):
    with lab.admin() as admin:
        course = new_course(admin, "Mechatronics")
        user, _ = lab.new_user("Grace Hopper")
        where = f"/api/admin/courses/{course['id']}/students/{user['id']}"

        first = admin.put(where)
        assert first.status_code == 200 and first.json()["changed"] is True
        assert admin.put(where).json() == {**first.json(), "changed": False}  # idempotent
        one = admin.get(f"/api/admin/courses/{course['id']}").json()
        assert [s["id"] for s in one["students"]] == [user["id"]]
        listed = admin.get("/api/admin/courses").json()["courses"]
        assert next(c for c in listed if c["id"] == course["id"])["student_count"] == 1

        # The users route enrols at creation (it calls this module's store).
        made = admin.post("/api/admin/users", json={"name": "Alan", "course": course["id"]})
        assert made.status_code == 201, made.text
        students = admin.get(f"/api/admin/courses/{course['id']}").json()["students"]
        assert {s["name"] for s in students} == {"Grace Hopper", "Alan"}

        removed = admin.delete(where)
        assert removed.status_code == 200 and removed.json()["changed"] is True
        assert admin.delete(where).json()["changed"] is False
        students = admin.get(f"/api/admin/courses/{course['id']}").json()["students"]
        assert [s["name"] for s in students] == ["Alan"]

        nobody = admin.put(f"/api/admin/courses/{course['id']}/students/{'0' * 32}")
        assert nobody.status_code == 404 and "no user" in nobody.json()["detail"]
        nowhere = admin.put(f"/api/admin/courses/{'0' * 32}/students/{user['id']}")
        assert nowhere.status_code == 404 and "no course" in nowhere.json()["detail"]

        # Deleting the course keeps its students.
        assert admin.delete(f"/api/admin/courses/{course['id']}").status_code == 200
        assert admin.get(f"/api/admin/users/{user['id']}").status_code == 200


def test_course_exercises(lab):
    with lab.admin() as admin:
        course = new_course(admin, "Control")
        base = f"/api/admin/courses/{course['id']}/exercises"
        added = admin.put(f"{base}/{EXERCISE}")
        assert added.status_code == 200, added.text
        assert added.json()["changed"] is True and added.json()["exercises"] == [EXERCISE]
        assert admin.put(f"{base}/{EXERCISE}").json()["changed"] is False
        assert admin.get(f"/api/admin/courses/{course['id']}").json()["exercises"] == [EXERCISE]

        unknown = admin.put(f"{base}/no_such_exercise")
        assert unknown.status_code == 404
        assert "no_such_exercise" in unknown.json()["detail"]
        assert EXERCISE in unknown.json()["valid"]

        removed = admin.delete(f"{base}/{EXERCISE}")
        assert removed.status_code == 200 and removed.json()["exercises"] == []
        assert admin.delete(f"{base}/{EXERCISE}").json()["changed"] is False
        assert admin.put(f"/api/admin/courses/{'0' * 32}/exercises/{EXERCISE}").status_code == 404


# ------------------------------------------------------------------------------ grades
def test_grades_csv_of_a_course(lab, scored):
    student, best, _ = scored
    with lab.admin() as admin:
        idle, _ = lab.new_user("=HYPERLINK(1)")  # never ran; a name a spreadsheet would run
        course = new_course(admin, "Grades, with a comma")
        for user_id in (student.user["id"], idle["id"]):
            assert admin.put(f"/api/admin/courses/{course['id']}/students/{user_id}").is_success

        # No exercise set: every exercise a member has a scored run of.
        rows = rows_of(admin.get("/api/admin/grades.csv", params={"course": course["id"]}))
        assert [(r["student_name"], r["exercise"]) for r in rows] == [
            ("'=HYPERLINK(1)", EXERCISE),
            ("Lovelace, Ada", EXERCISE),
        ]
        ada = rows[1]
        assert ada["student_id"] == student.user["id"]
        assert float(ada["best_score"]) == pytest.approx(best["score"], abs=1e-5)
        assert ada["attempts"] == "2"  # the stopped run is an attempt, not the best
        assert ada["best_run_id"] == best["id"]
        assert ada["best_run_url"].startswith("http")
        assert ada["best_run_url"].endswith(f"/api/runs/{best['id']}")
        path = ada["best_run_url"][ada["best_run_url"].index("/api/") :]
        assert admin.get(path).json()["score"] == best["score"]
        assert rows[0]["best_score"] == "" and rows[0]["attempts"] == "0"
        assert rows[0]["best_run_id"] == "" and rows[0]["best_run_url"] == ""

        # An exercise set for the course is listed even with no runs of it.
        for exercise in (EXERCISE, "crowbot_light_tracking"):
            assert admin.put(f"/api/admin/courses/{course['id']}/exercises/{exercise}").is_success
        answer = admin.get("/api/admin/grades.csv", params={"course": course["id"]})
        assert "attachment" in answer.headers["content-disposition"]
        rows = rows_of(answer)
        assert len(rows) == 4
        tracking = [r for r in rows if r["exercise"] == "crowbot_light_tracking"]
        assert {r["attempts"] for r in tracking} == {"0"}
        assert {r["best_score"] for r in tracking} == {""}

        # Names with commas and quotes survive the round trip: the csv module quotes them.
        assert '"Lovelace, Ada"' in answer.text


def test_grades_csv_without_a_course(lab, scored):
    student, best, _ = scored
    with lab.admin() as admin:
        rows = rows_of(admin.get("/api/admin/grades.csv"))
    mine = [r for r in rows if r["student_id"] == student.user["id"]]
    assert [(r["exercise"], r["best_run_id"]) for r in mine] == [(EXERCISE, best["id"])]
    # Every student is listed; the instructor is not.
    assert all(r["student_name"] != "instructor" for r in rows)


def test_grades_csv_of_an_empty_course_and_an_unknown_one(lab):
    with lab.admin() as admin:
        course = new_course(admin, "Empty")
        answer = admin.get("/api/admin/grades.csv", params={"course": course["id"]})
        assert rows_of(answer) == []
        assert answer.text.strip() == ",".join(GRADES_HEADER)
        unknown = admin.get("/api/admin/grades.csv", params={"course": "nope"})
        assert unknown.status_code == 404 and "no course 'nope'" in unknown.json()["detail"]


# ------------------------------------------------------------------------------ attacks
def admin_routes(course_id: str, user_id: str) -> list[tuple[str, str, dict | None]]:
    return [
        ("POST", "/api/admin/courses", {"name": unique("sneaky")}),
        ("GET", "/api/admin/courses", None),
        ("GET", f"/api/admin/courses/{course_id}", None),
        ("DELETE", f"/api/admin/courses/{course_id}", None),
        ("PUT", f"/api/admin/courses/{course_id}/students/{user_id}", None),
        ("DELETE", f"/api/admin/courses/{course_id}/students/{user_id}", None),
        ("PUT", f"/api/admin/courses/{course_id}/exercises/{EXERCISE}", None),
        ("DELETE", f"/api/admin/courses/{course_id}/exercises/{EXERCISE}", None),
        ("GET", "/api/admin/grades.csv", None),
        ("GET", f"/api/admin/grades.csv?course={course_id}", None),
    ]


def test_a_student_finds_no_course_routes(lab):
    student = lab.student("mallory")
    with lab.admin() as admin:
        course = new_course(admin, "Guarded")
        for method, path, body in admin_routes(course["id"], student.user["id"]):
            answer = student.request(method, path, json=body)
            assert answer.status_code == 404, (method, path, answer.text)
            assert answer.json() == {"detail": "Not Found"}
            # The Bearer token is refused the same way as the cookie.
            with lab.client(student.token) as bearer:
                assert bearer.request(method, path, json=body).status_code == 404
            with lab.client() as anonymous:
                assert anonymous.request(method, path, json=body).status_code == 401
        # Nothing changed behind the 404s.
        still = admin.get(f"/api/admin/courses/{course['id']}").json()
        assert still["students"] == [] and still["exercises"] == []


@pytest.mark.parametrize(
    "method, path, body",
    [
        ("GET", "/api/admin/courses/%00", None),
        ("GET", "/api/admin/courses/" + "x" * 5000, None),
        ("GET", "/api/admin/courses/..%2F..%2Fetc%2Fpasswd", None),
        ("GET", "/api/admin/courses/%F0%9F%A4%96", None),
        ("DELETE", "/api/admin/courses/' OR 1=1 --", None),
        ("PUT", "/api/admin/courses/nope/students/nobody", None),
        ("PUT", "/api/admin/courses/nope/exercises/../../etc", None),
        ("GET", "/api/admin/grades.csv?course=", None),
        ("GET", "/api/admin/grades.csv?course=" + "x" * 65, None),
        ("GET", "/api/admin/grades.csv?course=a&course=b", None),
        ("POST", "/api/admin/courses", ["a list"]),
        ("POST", "/api/admin/courses", "just a string"),
        ("POST", "/api/admin/courses", {"name": None}),
        ("POST", "/api/admin/courses", {"name": "a\x00b"}),
        ("POST", "/api/admin/courses", {"name": "line\nbreak"}),
    ],
)
def test_bad_input_is_a_4xx_sentence(lab, method, path, body):
    with lab.admin() as admin:
        answer = admin.request(method, path, json=body)
    assert 400 <= answer.status_code < 500, (answer.status_code, answer.text)
    assert answer.json()["detail"]


def test_malformed_json_is_a_4xx(lab):
    with lab.admin() as admin:
        answer = admin.post(
            "/api/admin/courses", content=b"{not json", headers={"content-type": "application/json"}
        )
    assert answer.status_code == 422 and answer.json()["detail"]


def test_the_server_logged_no_fault_on_these_routes(lab):
    """Last in this module: none of the requests above was answered with an incident."""
    faults = [line for line in lab.output if "incident" in line and "/api/admin/" in line]
    assert not [line for line in faults if "/courses" in line or "/grades" in line], faults
