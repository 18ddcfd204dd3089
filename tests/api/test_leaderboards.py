"""Leaderboards over the real server: ranking (score, then the key figure, then the earlier run),
names or pseudonyms, the student's own rank, hiding, resetting, and who may see which board.

Most runs here are written into the store directly (the lab's own tables, as a finished run
leaves them), so a ranking with exact ties can be set up without minutes of simulation; one test
ranks a real, judged run of the exercise's reference solution.
"""

from __future__ import annotations

import time
import uuid

import pytest

from server.exercises.registry import get_exercise
from server.store.db import Store
from server.store.models import RunRecord
from tests.api.test_admin_courses import new_course, wait_for_judged

EXERCISE = "crowbot_distance_pid"  # key figure: settling_time, lower is better
OTHER_EXERCISE = "crowbot_light_tracking"


@pytest.fixture
def store(lab):
    opened = Store.open(lab.database_url)
    yield opened
    opened.close()


def add_run(
    store: Store,
    user_id: str,
    score: float,
    settling_s: float | None,
    created_at: float,
    state: str = "finished",
    exercise: str = EXERCISE,
    hardware: str | None = None,
) -> str:
    run_id = uuid.uuid4().hex
    with store.session() as db:
        db.add(
            RunRecord(
                id=run_id,
                user_id=user_id,
                exercise_id=exercise,
                robot="crowbot",
                world="corridor",
                clock="lockstep",
                duration_s=30.0,
                seed=1,
                state=state,
                reason="",
                created_at=created_at,
                code=[],
                metrics={},
                nodes={},
                checks=[
                    {
                        "name": "settling_time",
                        "description": "time until the distance stays within 2 cm of 0.2 m",
                        "value": settling_s,
                        "threshold": 20.0,
                        "comparison": "<=",
                        "unit": "s",
                        "passed": score == 1.0,
                    }
                ],
                score=score,
                run_dir="/nonexistent",
                hardware=hardware,
            )
        )
    return run_id


def course_with(lab, admin, names: list[str], exercises=(EXERCISE,)):
    """A course with the exercises set and a logged-in student client per name."""
    course = new_course(admin, "Leaderboards")
    for exercise in exercises:
        assert admin.put(f"/api/admin/courses/{course['id']}/exercises/{exercise}").is_success
    students = []
    for name in names:
        client = lab.student(name)
        where = f"/api/admin/courses/{course['id']}/students/{client.user['id']}"
        assert admin.put(where).is_success
        students.append(client)
    return course, students


def board_path(course_id: str, exercise: str = EXERCISE) -> str:
    return f"/api/courses/{course_id}/leaderboards/{exercise}"


def test_ranking_by_score_then_key_figure_then_earlier_run(lab, store):
    tag = uuid.uuid4().hex[:6]
    names = [f"{who} {tag}" for who in ("Ada", "Barbara", "Claude", "Dennis", "Edsger")]
    with lab.admin() as admin:
        course, (ada, barbara, claude, dennis, edsger) = course_with(lab, admin, names)
        instructor_view = None
        t0 = time.time() - 1000.0
        add_run(store, ada.user["id"], 1.0, 5.0, t0)
        add_run(store, barbara.user["id"], 1.0, 4.0, t0 + 1)
        add_run(store, claude.user["id"], 0.75, 1.0, t0 + 2)  # fastest, but a lower score
        add_run(store, dennis.user["id"], 1.0, 4.0, t0 + 3)  # ties Barbara, later
        add_run(store, edsger.user["id"], 0.5, 2.0, t0 + 4)
        add_run(store, edsger.user["id"], 1.0, None, t0 + 5)  # never settled: behind at 1.0
        # A run that failed does not count, whatever its checks said. (No scored run of another
        # exercise here: the session-wide grade book without a course would list it for every
        # student, and test_admin_courses counts their rows.)
        add_run(store, claude.user["id"], 1.0, 0.5, t0 + 6, state="failed")
        # Nor does a run on a real robot: boards compare simulated runs.
        add_run(store, claude.user["id"], 1.0, 0.4, t0 + 7, hardware="crowbot-1")
        # Ada's worse try later does not replace her best.
        add_run(store, ada.user["id"], 0.5, 1.0, t0 + 8)
        instructor_view = admin.get(board_path(course["id"]))
    assert instructor_view.status_code == 200, instructor_view.text
    ranked = [row["real_name"] for row in instructor_view.json()["entries"]]
    assert ranked == [names[1], names[3], names[0], names[4], names[2]]
    assert [row["rank"] for row in instructor_view.json()["entries"]] == [1, 2, 3, 4, 5]
    assert instructor_view.json()["key_figure"]["check"] == "settling_time"
    assert instructor_view.json()["key_figure"]["better"] == "lower"

    mine = ada.get(board_path(course["id"]))
    assert mine.status_code == 200, mine.text
    body = mine.json()
    assert body["you"]["rank"] == 3 and body["you"]["of"] == 5
    marked = [row for row in body["entries"] if row["you"]]
    assert len(marked) == 1 and marked[0]["rank"] == 3
    assert marked[0]["score"] == 1.0 and marked[0]["key_value"] == 5.0
    # A student who has no graded run is on no rank, and told so by `you` being null.
    nobody = lab.student(f"Nobody {tag}")
    with lab.admin() as admin:
        admin.put(f"/api/admin/courses/{course['id']}/students/{nobody.user['id']}")
    assert nobody.get(board_path(course["id"])).json()["you"] is None


def test_pseudonyms_are_stable_and_do_not_leak_names(lab, store):
    tag = uuid.uuid4().hex[:6]
    names = [f"Hypatia Leakcheck {tag}", f"Emmy Leakcheck {tag}"]
    with lab.admin() as admin:
        course, (hypatia, emmy) = course_with(lab, admin, names)
        other, _ = course_with(lab, admin, [])
        admin.put(f"/api/admin/courses/{other['id']}/students/{hypatia.user['id']}")
        add_run(store, hypatia.user["id"], 1.0, 3.0, time.time() - 10)
        add_run(store, emmy.user["id"], 1.0, 2.0, time.time() - 10)

        first = hypatia.get(board_path(course["id"]))
        assert first.status_code == 200, first.text
        assert first.json()["names"] == "pseudonyms"  # the default
        for secret in (*names, "Leakcheck", hypatia.user["id"], emmy.user["id"]):
            assert secret not in first.text
        aliases = [row["name"] for row in first.json()["entries"]]
        assert len(set(aliases)) == 2 and all(len(a.split()) == 3 for a in aliases)
        # The same on every look, for every viewer; another course gives another pseudonym.
        assert [r["name"] for r in emmy.get(board_path(course["id"])).json()["entries"]] == aliases
        mine = first.json()["you"]["name"]
        elsewhere = hypatia.get(board_path(other["id"])).json()["you"]["name"]
        assert elsewhere != mine
        # The instructor sees both, side by side.
        rows = admin.get(board_path(course["id"])).json()["entries"]
        assert {(r["real_name"], r["pseudonym"]) for r in rows} == set(
            zip(names[::-1], aliases, strict=True)
        )

        named = admin.put(f"{board_path(course['id'])}/settings", json={"names": "names"})
        assert named.status_code == 200 and named.json()["names"] == "names"
    shown = [row["name"] for row in hypatia.get(board_path(course["id"])).json()["entries"]]
    assert shown == [names[1], names[0]]
    assert "user_id" not in hypatia.get(board_path(course["id"])).json()["entries"][0]


def test_a_student_sees_only_their_own_courses_boards(lab, store):
    tag = uuid.uuid4().hex[:6]
    with lab.admin() as admin:
        mine, (alan,) = course_with(lab, admin, [f"Alan {tag}"])
        theirs, (kurt,) = course_with(lab, admin, [f"Kurt {tag}"])
        add_run(store, kurt.user["id"], 1.0, 3.0, time.time() - 10)
        assert admin.get(board_path(theirs["id"])).status_code == 200

    anonymous = lab.client()
    for url in ("/api/courses", board_path(mine["id"])):
        assert anonymous.get(url).status_code == 401
        assert "invite link" in anonymous.get(url).json()["detail"]
    listed = alan.get("/api/courses").json()["courses"]
    assert [c["id"] for c in listed] == [mine["id"]] and listed[0]["exercises"] == [EXERCISE]
    other = alan.get(board_path(theirs["id"]))
    missing = alan.get(board_path("0" * 32))
    assert other.status_code == 404 and missing.status_code == 404
    # Another course reads exactly like none at all: nothing about it leaks.
    assert other.json()["detail"].replace(theirs["id"], "X") == missing.json()["detail"].replace(
        "0" * 32, "X"
    )
    assert "GET /api/courses" in other.json()["detail"]
    # An exercise the course does not set: 404 naming the ones it does.
    unset = alan.get(board_path(mine["id"], OTHER_EXERCISE))
    assert unset.status_code == 404 and EXERCISE in unset.json()["detail"]
    # Students change nothing (the instructor routes are 404 for them).
    hide = alan.put(f"{board_path(mine['id'])}/settings", json={"visible": False})
    assert hide.status_code == 404
    assert alan.post(f"{board_path(mine['id'])}/reset").status_code == 404


def test_a_hidden_board_is_404_for_students_and_shown_to_instructors(lab, store):
    tag = uuid.uuid4().hex[:6]
    with lab.admin() as admin:
        course, (grace,) = course_with(lab, admin, [f"Grace {tag}"])
        add_run(store, grace.user["id"], 1.0, 3.0, time.time() - 10)
        hidden = admin.put(f"{board_path(course['id'])}/settings", json={"visible": False})
        assert hidden.status_code == 200 and hidden.json()["visible"] is False
        assert hidden.json()["names"] == "pseudonyms"  # untouched
        seen = admin.get(board_path(course["id"]))
        assert seen.status_code == 200 and seen.json()["visible"] is False
        assert len(seen.json()["entries"]) == 1

        refused = grace.get(board_path(course["id"]))
        assert refused.status_code == 404
        assert "hidden by the instructor" in refused.json()["detail"]

        assert admin.put(f"{board_path(course['id'])}/settings", json={"visible": True}).json()[
            "visible"
        ]
        assert grace.get(board_path(course["id"])).json()["you"]["rank"] == 1
        bad = admin.put(f"{board_path(course['id'])}/settings", json={"names": "initials"})
        assert bad.status_code == 422


def test_reset_counts_only_later_runs(lab, store):
    tag = uuid.uuid4().hex[:6]
    with lab.admin() as admin:
        course, (linus, margaret) = course_with(lab, admin, [f"Linus {tag}", f"Margaret {tag}"])
        add_run(store, linus.user["id"], 1.0, 3.0, time.time() - 10)
        add_run(store, margaret.user["id"], 1.0, 2.0, time.time() - 10)
        assert len(admin.get(board_path(course["id"])).json()["entries"]) == 2

        reset = admin.post(f"{board_path(course['id'])}/reset")
        assert reset.status_code == 200, reset.text
        assert reset.json()["reset_at"] is not None
        assert "no longer count" in reset.json()["message"]
        assert "grade book" in reset.json()["message"]

        after = linus.get(board_path(course["id"])).json()
        assert after["entries"] == [] and after["you"] is None
        assert "only runs started since then count" in after["note"]
        add_run(store, linus.user["id"], 0.5, 9.0, time.time() + 1)
        again = linus.get(board_path(course["id"])).json()
        assert again["you"] == {"rank": 1, "of": 1, "name": again["entries"][0]["name"]}
        # The grade book still counts the runs from before the reset.
        grades = admin.get("/api/admin/grades.csv", params={"course": course["id"]}).text
        assert ",1," in grades  # best_score 1 (Margaret's and Linus's earlier runs)


def test_a_real_judged_run_is_ranked_by_its_settling_time(lab):
    exercise = get_exercise(EXERCISE)
    nodes = [
        {"name": name, "code": exercise.code_path(path).read_text("utf-8")}
        for name, path in exercise.reference
    ]
    with lab.admin() as admin:
        course, (student,) = course_with(lab, admin, [f"Runner {uuid.uuid4().hex[:6]}"])
    started = student.post("/api/runs", json={"exercise": EXERCISE, "nodes": nodes})
    assert started.status_code == 201, started.text
    run = wait_for_judged(student, started.json()["id"])
    assert run["score"] is not None, run
    settling = next(c["value"] for c in run["checks"] if c["name"] == "settling_time")

    body = student.get(board_path(course["id"])).json()
    assert body["you"]["rank"] == 1
    assert body["entries"][0]["key_value"] == settling
    assert body["entries"][0]["score"] == round(run["score"], 3)
