"""Leaderboards in Chromium: the student sees their rank under the exercise's text (by
pseudonym), the instructor sees the board with names in the course's panel and hides it, and the
student's page then shows no board."""

from __future__ import annotations

import time
import uuid

import pytest

from server.store.db import Store
from tests.api.test_admin_courses import new_course
from tests.api.test_leaderboards import EXERCISE, add_run
from tests.e2e.test_admin_page import _log_in


@pytest.mark.slow
def test_student_rank_and_instructor_board(web_lab, new_page, screenshots) -> None:
    from playwright.sync_api import expect

    lab = web_lab
    tag = uuid.uuid4().hex[:6]
    with lab.admin() as admin:
        course = new_course(admin, "Boards")
        admin.put(f"/api/admin/courses/{course['id']}/exercises/{EXERCISE}")
        users = [lab.new_user(f"{who} {tag}") for who in ("Ada", "Alan")]
        for user, _ in users:
            admin.put(f"/api/admin/courses/{course['id']}/students/{user['id']}")
    store = Store.open(lab.database_url)
    try:
        add_run(store, users[0][0]["id"], 1.0, 6.0, time.time() - 60)
        add_run(store, users[1][0]["id"], 1.0, 4.0, time.time() - 60)
    finally:
        store.close()

    student = new_page()
    _log_in(student, lab, users[0][1])
    student.goto(f"{lab.url}/#{EXERCISE}")
    rank = student.get_by_test_id("leaderboard-rank")
    expect(rank).to_contain_text("you are 2 of 2", timeout=15_000)
    board = student.get_by_test_id("leaderboard")
    board.locator("summary").click()  # closed at first: the exercise's text stays in view
    expect(board.locator("tr.you")).to_contain_text("6 s")
    assert f"Alan {tag}" not in board.inner_text()  # pseudonyms by default
    student.screenshot(path=str(screenshots / "student-leaderboard.png"))

    instructor = new_page()
    _log_in(instructor, lab, lab.admin_token)
    instructor.goto(f"{lab.url}/admin#courses")
    instructor.get_by_role("button", name=course["name"]).click()
    table = instructor.get_by_test_id("board-table")
    expect(table.locator("tbody tr")).to_have_count(2, timeout=10_000)
    expect(table.locator("tbody tr").first).to_contain_text(f"Alan {tag}")
    instructor.get_by_label("shown to students").uncheck()
    expect(instructor.locator("#board-status")).to_contain_text("Hidden")
    instructor.screenshot(path=str(screenshots / "admin-leaderboard.png"), full_page=True)

    # The board's answer is awaited, so "hidden" is the page's reading of it, not a board
    # that has not loaded yet.
    with student.expect_response(lambda r: "/leaderboards/" in r.url) as answer:
        student.reload()
    assert answer.value.status == 404
    expect(student.locator("#exercise-body")).to_contain_text("Checks", timeout=15_000)
    expect(student.locator("#leaderboard")).to_be_hidden()
    errors = [e for p in (student, instructor) for e in p.console_watch.errors if "404" not in e]
    assert not errors, errors
