"""Exercises for instructors over the real server: the list with reference solutions, custom
exercises from a template and from scratch (made, edited, deleted, refused with a sentence),
and try runs. Students get 404 for all of it, and no input makes the server answer 500."""

from __future__ import annotations

import json
import math
import time
import uuid

import pytest
from sqlalchemy import delete

from server.exercises.registry import exercise_ids, get_exercise
from server.service.exercises import GENERIC_CHECKS
from server.store.db import Store
from server.store.models import CustomExercise
from tests.api.conftest import STEP_CONTROLLER, wait_for_end

TEMPLATE = "crowbot_distance_pid"
JSON_CONTENT = {"content-type": "application/json"}


def new_id(stem: str) -> str:
    """Exercise ids are global on the session-wide server."""
    return f"{stem}_{uuid.uuid4().hex[:6]}"


def scratch(exercise_id: str, **changes) -> dict:
    """A from-scratch exercise: drive the CrowBot to the wall without touching it."""
    body = {
        "id": exercise_id,
        "title": "Drive up to the wall",
        "description": "Drive towards the wall and stop before it.",
        "robot": "crowbot",
        "world": "wall_approach",
        "duration_s": 3.0,
        "clock": "lockstep",
        "seeds": [4],
        "starter": [{"name": "driver", "code": STEP_CONTROLLER}],
        "checks": [
            {"name": "collisions", "threshold": 0},
            {"name": "distance_travelled_m", "threshold": 0.05},
        ],
    }
    return {**body, **changes}


def test_list_shows_reference_code_and_custom_flags(lab):
    with lab.admin() as admin:
        made = admin.post("/api/admin/exercises", json=scratch(new_id("listed")))
        assert made.status_code == 201, made.text
        answer = admin.get("/api/admin/exercises")
    assert answer.status_code == 200
    listed = {e["id"]: e for e in answer.json()["exercises"]}
    assert set(exercise_ids()) <= set(listed)
    builtin = listed[TEMPLATE]
    assert builtin["custom"] is False
    exercise = get_exercise(TEMPLATE)
    assert [(r["name"], r["code"]) for r in builtin["reference"]] == [
        (name, exercise.code_path(path).read_text("utf-8")) for name, path in exercise.reference
    ]
    custom = listed[made.json()["id"]]
    assert custom["custom"] is True and "reference" not in custom
    assert custom["created_by"] and custom["created_at"] and custom["template"] is None
    generic = {c["name"] for c in answer.json()["generic_checks"]}
    assert generic == set(GENERIC_CHECKS)


def test_custom_exercise_from_a_template(lab):
    exercise_id = new_id("gentle_pid")
    body = {
        "id": exercise_id,
        "template": TEMPLATE,
        "title": "A gentler PID",
        "duration_s": 20,
        "checks": [{"name": "settling_time", "threshold": 18.5}],
    }
    student = lab.student("kim")
    with lab.admin() as admin:
        made = admin.post("/api/admin/exercises", json=body)
        assert made.status_code == 201, made.text
        out = made.json()
        assert out["id"] == exercise_id and out["custom"] is True and out["template"] == TEMPLATE
        assert out["title"] == "A gentler PID" and out["duration_s"] == 20
        assert out["robot"] == "crowbot" and out["world"] == "wall_approach"
        assert [(c["name"], c["threshold"]) for c in out["checks"]] == [("settling_time", 18.5)]
        # No starter given: the template's.
        assert [s["name"] for s in out["starter"]] == ["pid_distance"]

        # Students see it in the catalog, without any reference code.
        seen = student.get(f"/api/exercises/{exercise_id}")
        assert seen.status_code == 200 and seen.json()["title"] == "A gentler PID"
        assert "reference" not in seen.json()

        again = admin.post("/api/admin/exercises", json=body)
        assert again.status_code == 409 and "PUT /api/admin/exercises/" in again.json()["detail"]

        edited = admin.put(
            f"/api/admin/exercises/{exercise_id}",
            json={**{k: v for k, v in body.items() if k != "id"}, "title": "Gentler still"},
        )
        assert edited.status_code == 200, edited.text
        assert edited.json()["title"] == "Gentler still"
        assert edited.json()["created_at"] == out["created_at"]
        assert admin.get(f"/api/admin/exercises/{exercise_id}").json()["title"] == "Gentler still"

        # A check the template does not have: 422 naming the ones it has.
        wrong = admin.put(
            f"/api/admin/exercises/{exercise_id}",
            json={"template": TEMPLATE, "checks": [{"name": "speed", "threshold": 1}]},
        )
        assert wrong.status_code == 422
        for name in ("settling_time", "steady_state_error", "overshoot", "collisions"):
            assert name in wrong.json()["detail"]

        # The template fixes the robot, the world, the clock and the seeds.
        for change in ({"robot": "ir_scout"}, {"clock": "realtime"}, {"seeds": [1]}):
            refused = admin.post("/api/admin/exercises", json={**body, "id": new_id("x"), **change})
            assert refused.status_code == 422, (change, refused.text)
            assert "template" in refused.json()["detail"]
        unknown = admin.post(
            "/api/admin/exercises", json={**body, "id": new_id("x"), "template": "no_such"}
        )
        assert unknown.status_code == 404 and TEMPLATE in unknown.json()["valid"]

        deleted = admin.delete(f"/api/admin/exercises/{exercise_id}")
        assert deleted.status_code == 200 and deleted.json()["ok"] is True
        assert admin.get(f"/api/admin/exercises/{exercise_id}").status_code == 404
        assert student.get(f"/api/exercises/{exercise_id}").status_code == 404
        assert admin.delete(f"/api/admin/exercises/{exercise_id}").status_code == 404


def test_builtin_exercises_cannot_be_taken_edited_or_deleted(lab):
    with lab.admin() as admin:
        taken = admin.post("/api/admin/exercises", json=scratch(TEMPLATE))
        assert taken.status_code == 409 and "template" in taken.json()["detail"]
        edit = admin.put(f"/api/admin/exercises/{TEMPLATE}", json={"title": "mine now"})
        assert edit.status_code == 409
        assert "built-in" in edit.json()["detail"] and "template" in edit.json()["detail"]
        delete = admin.delete(f"/api/admin/exercises/{TEMPLATE}")
        assert delete.status_code == 409 and "built-in" in delete.json()["detail"]
        assert admin.get(f"/api/admin/exercises/{TEMPLATE}").json()["title"] != "mine now"
        unknown = admin.put("/api/admin/exercises/no_such_one", json={"title": "x"})
        assert unknown.status_code == 404 and "no_such_one" in unknown.json()["detail"]


def test_custom_exercise_from_scratch_and_its_try_run(lab):
    exercise_id = new_id("to_the_wall")
    with lab.admin() as admin:
        made = admin.post("/api/admin/exercises", json=scratch(exercise_id))
        assert made.status_code == 201, made.text
        out = made.json()
        assert (out["robot"], out["world"], out["seeds"]) == ("crowbot", "wall_approach", [4])
        assert [c["name"] for c in out["checks"]] == ["collisions", "distance_travelled_m"]

        tried = admin.post(f"/api/admin/exercises/{exercise_id}/try")
        assert tried.status_code == 201, tried.text
        assert tried.json()["tried"] == "starter" and tried.json()["exercise"] == exercise_id
        assert tried.json()["duration_s"] == 3.0 and tried.json()["seed"] == 4
        run = wait_for_end(admin, tried.json()["id"])
        assert run["state"] == "finished", run
        for _ in range(100):  # the judged checks land a moment after the end
            if run["checks"]:
                break
            run = admin.get(f"/api/runs/{run['id']}").json()
        assert {c["name"]: c["passed"] for c in run["checks"]} == {
            "collisions": True,
            "distance_travelled_m": True,
        }
        assert run["score"] == 1.0
        assert admin.delete(f"/api/admin/exercises/{exercise_id}").status_code == 200
        # The run outlives its exercise.
        assert admin.get(f"/api/runs/{run['id']}").status_code == 200


def test_try_a_builtin_exercise_runs_its_reference(lab):
    with lab.admin() as admin:
        tried = admin.post(f"/api/admin/exercises/{TEMPLATE}/try")
        assert tried.status_code == 201, tried.text
        assert tried.json()["tried"] == "reference" and tried.json()["exercise"] == TEMPLATE
        admin.post(f"/api/runs/{tried.json()['id']}/stop")
        assert wait_for_end(admin, tried.json()["id"])["state"] in ("finished", "interrupted")
        missing = admin.post("/api/admin/exercises/no_such_exercise/try")
        assert missing.status_code == 404 and TEMPLATE in missing.json()["valid"]


@pytest.mark.parametrize(
    "changes, status, words",
    [
        ({"checks": [{"name": "speed", "threshold": 1}]}, 422, list(GENERIC_CHECKS)),
        ({"checks": []}, 422, ["at least one check", "collisions"]),
        ({"robot": "hovercraft"}, 404, ["unknown robot 'hovercraft'", "crowbot"]),
        ({"world": "mars"}, 404, ["unknown world 'mars'", "wall_approach"]),
        ({"robot": "crop_rover"}, 422, ["cannot be placed in world"]),
        ({"title": None}, 422, ["needs 'title'"]),
        ({"duration_s": None}, 422, ["needs 'duration_s'"]),
        ({"starter": []}, 422, ["starter code"]),
        ({"duration_s": 100000}, 422, ["longer than this lab allows"]),
        ({"duration_s": -1}, 422, ["duration_s"]),
        ({"checks": [{"name": "collisions", "threshold": 0}] * 2}, 422, ["listed twice"]),
        ({"starter": [{"name": "a", "code": ""}, {"name": "a", "code": ""}]}, 422, ["twice"]),
        ({"starter": [{"name": "bad name", "code": ""}]}, 422, ["starter.0.name"]),
        ({"checks": [{"name": "collisions", "threshold": math.inf}]}, 422, ["threshold"]),
        ({"checks": [{"name": "collisions", "threshold": math.nan}]}, 422, ["threshold"]),
        ({"clock": "sundial"}, 422, ["clock"]),
        ({"seeds": []}, 422, ["seeds"]),
        ({"seeds": [-1]}, 422, ["seeds"]),
        ({"id": "Bad-Id"}, 422, ["id"]),
        ({"id": "ab"}, 422, ["id"]),
        ({"id": "a" * 65}, 422, ["id"]),
        ({"id": "../../etc/passwd"}, 422, ["id"]),
        ({"surprise": 1}, 422, ["surprise"]),
        ({"starter": "print(1)"}, 422, ["starter"]),
        ({"checks": [{"name": "collisions"}]}, 422, ["threshold"]),
    ],
)
def test_bad_definitions_are_refused_with_a_sentence(lab, changes, status, words):
    body = scratch(new_id("bad"), **changes)
    body = {key: value for key, value in body.items() if value is not None}
    with lab.admin() as admin:
        # json.dumps, not httpx's encoder: it writes NaN and Infinity, as a careless client may.
        answer = admin.post("/api/admin/exercises", content=json.dumps(body), headers=JSON_CONTENT)
        assert answer.status_code == status, answer.text
        detail = answer.json()["detail"]
        for word in words:
            assert word in detail, (word, detail)
        if "id" not in changes:  # nothing was stored
            assert admin.get(f"/api/admin/exercises/{body['id']}").status_code == 404


def test_a_student_finds_no_exercise_routes(lab):
    student = lab.student("eve")
    exercise_id = new_id("guarded")
    with lab.admin() as admin:
        assert admin.post("/api/admin/exercises", json=scratch(exercise_id)).status_code == 201
        routes = [
            ("GET", "/api/admin/exercises", None),
            ("GET", f"/api/admin/exercises/{TEMPLATE}", None),
            ("GET", f"/api/admin/exercises/{exercise_id}", None),
            ("POST", "/api/admin/exercises", scratch(new_id("sneaky"))),
            ("PUT", f"/api/admin/exercises/{exercise_id}", {"title": "pwned"}),
            ("DELETE", f"/api/admin/exercises/{exercise_id}", None),
            ("POST", f"/api/admin/exercises/{exercise_id}/try", None),
            ("POST", f"/api/admin/exercises/{TEMPLATE}/try", None),
        ]
        for method, path, body in routes:
            answer = student.request(method, path, json=body)
            assert answer.status_code == 404, (method, path, answer.text)
            assert answer.json() == {"detail": "Not Found"}
            with lab.client() as anonymous:
                assert anonymous.request(method, path, json=body).status_code == 401
        still = admin.get(f"/api/admin/exercises/{exercise_id}").json()
        assert still["title"] == "Drive up to the wall"
        runs = admin.get("/api/admin/runs", params={"user": student.user["id"]}).json()
        assert runs["total"] == 0  # no try run was started behind a 404


@pytest.mark.parametrize(
    "method, path, body",
    [
        ("GET", "/api/admin/exercises/%00", None),
        ("GET", "/api/admin/exercises/" + "x" * 5000, None),
        ("PUT", "/api/admin/exercises/%F0%9F%A4%96", {"title": "robot"}),
        ("DELETE", "/api/admin/exercises/' OR 1=1 --", None),
        ("POST", "/api/admin/exercises/%00/try", None),
        ("POST", "/api/admin/exercises", []),
        ("POST", "/api/admin/exercises", "text"),
        ("POST", "/api/admin/exercises", {"id": "abc"}),
        ("PUT", "/api/admin/exercises/abc", {"checks": "all"}),
    ],
)
def test_bad_input_is_a_4xx_sentence(lab, method, path, body):
    with lab.admin() as admin:
        answer = admin.request(method, path, json=body)
    assert 400 <= answer.status_code < 500, (answer.status_code, answer.text)
    assert answer.json()["detail"]


def test_a_stored_exercise_whose_template_is_gone(lab):
    """A definition stored by an older version, from a built-in exercise since renamed: shown
    with what to do, refused with 409 where it would be used, and repairable."""
    exercise_id = new_id("orphan")
    store = Store.open(lab.database_url)
    try:
        with store.session() as db:
            db.add(
                CustomExercise(
                    id=exercise_id,
                    definition={"id": exercise_id, "template": "renamed_long_ago", "starter": []},
                    created_by=None,
                    created_at=time.time(),
                    updated_at=time.time(),
                )
            )
        with lab.admin() as admin:
            listed = {e["id"]: e for e in admin.get("/api/admin/exercises").json()["exercises"]}
            assert "renamed_long_ago" in listed[exercise_id]["error"]
            assert "PUT /api/admin/exercises/" in listed[exercise_id]["error"]
            assert "error" in admin.get(f"/api/admin/exercises/{exercise_id}").json()
            tried = admin.post(f"/api/admin/exercises/{exercise_id}/try")
            assert tried.status_code == 409 and "edit it" in tried.json()["detail"]
            course = admin.post("/api/admin/courses", json={"name": new_id("orphans")}).json()
            assigned = admin.put(f"/api/admin/courses/{course['id']}/exercises/{exercise_id}")
            assert assigned.status_code == 409
            admin.delete(f"/api/admin/courses/{course['id']}")
            repaired = admin.put(f"/api/admin/exercises/{exercise_id}", json={"template": TEMPLATE})
            assert repaired.status_code == 200, repaired.text
            assert admin.get(f"/api/admin/exercises/{exercise_id}").json()["custom"] is True
    finally:
        # The server is shared by every API test: leave no definition behind that cannot build.
        with store.session() as db:
            db.execute(delete(CustomExercise).where(CustomExercise.id == exercise_id))
        store.close()


def test_the_server_logged_no_fault_on_these_routes(lab):
    """Last in this module: none of the requests above was answered with an incident."""
    faults = [line for line in lab.output if "incident" in line and "/api/admin/exercises" in line]
    assert not faults, faults
