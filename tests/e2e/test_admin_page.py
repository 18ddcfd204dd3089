"""The instructor console (`/admin`, web/admin.html and its bundle web/static/admin.js, built from
web/src/admin/): served with its bundles, every source module's imports resolve, and in Chromium
an instructor creates a user (the invite link shows once), watches a student's live run and
stops it, and reads a course's grade book; a student is told the page is for instructors."""

from __future__ import annotations

import re
from pathlib import Path

import httpx
import pytest

from tests.api.conftest import STEP_CONTROLLER, LabServer, wait_for_end

WEB = Path(__file__).resolve().parents[2] / "web"
SOURCES = WEB / "src"
TEST_IDS = (
    "create-user-form",
    "create-user-submit",
    "invite-link",
    "users-table",
    "runs-table",
    "grades-table",
)
BUNDLE_LINK = re.compile(r'(?:href|src)="(/static/[\w.-]+\.(js|css))\?v=[0-9a-f]+"')
IMPORT = re.compile(r"import\s*\{([^}]*)\}\s*from\s*\"(\.\.?/[\w./-]+\.js)\"", re.S)
EXPORT = re.compile(r"export\s+(?:async\s+)?(?:function|const|let|class)\s+([\w$]+)")


def exported_names(path: Path) -> set[str]:
    return set(EXPORT.findall(path.read_text("utf-8")))


def test_console_page_and_bundles_are_served(web_lab: LabServer) -> None:
    with httpx.Client(base_url=web_lab.url) as client:
        page = client.get("/admin")
        assert page.status_code == 200
        assert page.headers["content-type"].startswith("text/html")
        for test_id in TEST_IDS:
            assert f'data-testid="{test_id}"' in page.text, test_id
        bundles = BUNDLE_LINK.findall(page.text)
        assert sorted(path for path, _ in bundles) == ["/static/admin.css", "/static/admin.js"]
        for path, suffix in bundles:
            answer = client.get(path)
            assert answer.status_code == 200, path
            kind = "javascript" if suffix == "js" else "css"
            assert kind in answer.headers["content-type"], (path, answer.headers)


def test_every_source_import_names_an_export() -> None:
    """A missing export fails the bundler; this finds it without Node, in every page's sources."""
    modules = sorted(SOURCES.rglob("*.js"))
    assert any(m.parent.name == "admin" for m in modules)
    for module in modules:
        for names, target in IMPORT.findall(module.read_text("utf-8")):
            source = (module.parent / target).resolve()
            assert source.is_file(), f"{module.name} imports {target}, which does not exist"
            available = exported_names(source)
            for name in (n.strip() for n in names.split(",")):
                if name:
                    assert name in available, f"{module.name}: {target} does not export {name}"


# ------------------------------------------------------------------------------ in Chromium
def _log_in(page, lab: LabServer, token: str) -> None:
    """The invite link's cookie, taken without rendering the lab page it redirects to."""
    answer = page.context.request.get(f"{lab.url}/login?token={token}", max_redirects=0)
    assert answer.status == 303, answer.text()
    page.goto(f"{lab.url}/admin")


@pytest.mark.slow
def test_instructor_console_in_chromium(web_lab, new_page, screenshots) -> None:
    from playwright.sync_api import expect

    lab = web_lab
    page = new_page(1366, 768)
    _log_in(page, lab, lab.admin_token)

    # A user: created from the form, the invite link shown once, listed.
    page.goto(f"{lab.url}/admin#users")
    form = page.get_by_test_id("create-user-form")
    form.get_by_label("Name").fill("Grace Hopper")
    form.get_by_label("Email").fill("grace@example.org")
    page.get_by_test_id("create-user-submit").click()
    invite = page.get_by_test_id("invite-link")
    expect(invite).to_have_value(re.compile(r"/login\?token=[\w-]+$"))
    expect(page.get_by_test_id("users-table")).to_contain_text("grace@example.org")
    student_token = invite.input_value().rsplit("token=", 1)[1]
    page.screenshot(path=str(screenshots / "admin-users.png"), full_page=True)

    # The API's sentence, verbatim, next to the form.
    form.get_by_label("Name").fill("Nobody")
    form.get_by_label("Email").fill("nobody@localhost")  # the browser accepts it; the API not
    page.get_by_test_id("create-user-submit").click()
    expect(form.get_by_role("alert")).to_contain_text("body.email")

    # The student's live run: listed within a poll, stopped with its button.
    student = lab.client(student_token)
    started = student.post(
        "/api/runs",
        json={"robot": "crowbot", "world": "wall_approach", "clock": "realtime",
              "duration": 120, "nodes": [{"name": "pid", "code": STEP_CONTROLLER}]},
    )  # fmt: skip
    assert started.status_code == 201, started.text
    run_id = started.json()["id"]
    page.goto(f"{lab.url}/admin#runs")
    row = page.get_by_test_id("runs-table").locator(f'tr[data-run-id="{run_id}"]')
    expect(row).to_contain_text("Grace Hopper", timeout=20_000)
    expect(row.get_by_role("link", name="Watch")).to_have_attribute("href", f"/?run={run_id}")

    # The header counts the live runs the section lists: it said "0 active runs" beside one
    # when its 5 s status poll lagged the list; a status answer made stale on purpose must not
    # change the count shown beside the listed run.
    def stale_status(route) -> None:
        answer = route.fetch()
        body = answer.json()
        body["runs"]["active_runs"] = 0
        route.fulfill(response=answer, json=body)

    page.route("**/api/admin/status", stale_status)
    with page.expect_response("**/api/admin/status"):  # the stale answer has arrived
        page.evaluate("() => document.dispatchEvent(new Event('visibilitychange'))")  # poll now
    listed = page.locator("#live-table tbody tr").count()
    assert listed >= 1
    expect(page.locator("#status-summary")).to_contain_text(
        re.compile(rf"^{listed} active runs? ·")
    )
    page.unroute("**/api/admin/status")
    page.screenshot(path=str(screenshots / "admin-runs.png"), full_page=True)
    row.get_by_test_id("run-stop").click()
    expect(row).to_have_count(0, timeout=20_000)
    assert wait_for_end(student, run_id)["state"] == "interrupted"

    # The status shows the disk the ended run uses (measured when it ended), and who uses it.
    ended = student.get(f"/api/runs/{run_id}").json()
    assert ended["disk_bytes"] > 0
    page.goto(f"{lab.url}/admin#status")
    panel = page.get_by_test_id("status-panel")
    expect(panel).to_contain_text("Disk used by runs", timeout=10_000)
    expect(panel).to_contain_text(re.compile(r"most: Grace Hopper \d+\.\d MiB"))

    # A course: made, the student enrolled, an exercise assigned, the grade book shown.
    page.goto(f"{lab.url}/admin#courses")
    page.get_by_test_id("create-course-form").get_by_label("New course").fill("Navy 101")
    page.get_by_test_id("create-course-submit").click()
    enrol = page.get_by_test_id("enrol-form")
    enrol.get_by_label("Grace Hopper").check()
    enrol.get_by_role("button", name="Enrol ticked students").click()
    expect(page.get_by_test_id("course-students")).to_contain_text("Grace Hopper")
    assign = page.get_by_test_id("assign-exercise-form")
    assign.get_by_label("Assign").select_option("crowbot_distance_pid")
    assign.get_by_role("button", name="Assign exercise").click()
    grades = page.get_by_test_id("grades-table")
    expect(grades.locator("tbody tr")).to_have_count(1)
    expect(grades).to_contain_text("crowbot_distance_pid")
    expect(grades.locator("thead th").first).to_be_visible()
    assert "course=" in page.get_by_test_id("grades-export").get_attribute("href")
    page.screenshot(path=str(screenshots / "admin-courses.png"), full_page=True)

    errors = [e for e in page.console_watch.errors if "status of 422" not in e]
    assert not errors, errors

    # A student is told, kindly, that the page is for instructors.
    other = new_page(1920, 1080)
    _log_in(other, lab, student_token)
    expect(other.get_by_test_id("auth-gate")).to_contain_text("For instructors only")
    assert not other.console_watch.errors, other.console_watch.errors
