"""The guide's screenshots: a real lab (`robodojo serve` in a subprocess on an empty data folder,
as the end-to-end tests start it) and Debian's Chromium through Playwright, doing what the
getting-started page tells a student to do. Run by `python3 -m guide.figures pages`.

Two students of one course run the tutorial's controller (one through the page, one through the
API with another gain, so the leaderboard has two rows); the screenshots are the student page
before and after the run, its plots and 3D view, the leaderboard, and the instructor console.
"""

from __future__ import annotations

import re
import tempfile
import time
from pathlib import Path

import httpx

from guide.samples import samples
from tests.api.conftest import start_server, stop_server
from tests.e2e.conftest import CHROMIUM, CHROMIUM_FLAGS

EXERCISE = "crowbot_distance_pid"
VIEWPORT = {"width": 1366, "height": 800}
RUN_TIMEOUT_MS = 120_000  # [ms] a 30 s lockstep run with grading, on a loaded 2-core machine
VIEW_SETTLE_MS = 4_000  # [ms] the 3D view's software WebGL draws its first frames


def _tutorial_code() -> str:
    """The controller of the getting-started page, as the page shows it."""
    for sample in samples():
        if sample.page == "students/getting-started.md" and not sample.fragment:
            return sample.code
    raise LookupError("docs/students/getting-started.md has no controller sample")


def _wait_for_end(client: httpx.Client, run_id: str, timeout_s: float = 120.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        state = client.get(f"/api/runs/{run_id}").json()["state"]
        if state not in ("created", "starting", "running", "paused"):
            return
        time.sleep(0.5)
    raise TimeoutError(f"run {run_id} did not end within {timeout_s} s")


def _prepare(lab, code: str) -> str:
    """A course with the exercise, two enrolled students; the second one's graded run. Returns
    the first student's token."""
    with lab.admin() as admin:
        course = admin.post("/api/admin/courses", json={"name": "Robotics 101"}).json()
        admin.put(f"/api/admin/courses/{course['id']}/exercises/{EXERCISE}")
        tokens = []
        for name in ("Ada Lovelace", "Alan Turing"):
            answer = admin.post("/api/admin/users",
                                json={"name": name, "course": course["id"]})  # fmt: skip
            tokens.append(answer.json()["token"])
    with lab.client(tokens[1]) as alan:
        other_gain = code.replace("KP = 0.4", "KP = 0.6")
        body = {"exercise": EXERCISE, "nodes": [{"name": "pid", "code": other_gain}]}
        run = alan.post("/api/runs", json=body)
        run.raise_for_status()
        _wait_for_end(alan, run.json()["id"])
    return tokens[0]


def _set_code(page, code: str) -> None:
    content = page.get_by_test_id("editor").locator(".cm-content")
    content.click()
    page.keyboard.press("Control+a")
    page.keyboard.insert_text(code)


def take(out: Path) -> None:
    from playwright.sync_api import expect, sync_playwright

    out.mkdir(parents=True, exist_ok=True)
    code = _tutorial_code()
    with tempfile.TemporaryDirectory(prefix="guide-screens-") as data:
        lab = start_server(Path(data))
        try:
            student_token = _prepare(lab, code)
            with sync_playwright() as playwright:
                browser = playwright.chromium.launch(executable_path=CHROMIUM, headless=True,
                                                     args=CHROMIUM_FLAGS)  # fmt: skip
                try:
                    _student(browser, lab, student_token, code, out, expect)
                    _instructor(browser, lab, out, expect)
                finally:
                    browser.close()
        finally:
            stop_server(lab)


def _shot(target, path: Path) -> None:
    target.screenshot(path=str(path))
    print(f"  {path}")


def _student(browser, lab, token: str, code: str, out: Path, expect) -> None:
    page = browser.new_context(viewport=VIEWPORT).new_page()
    page.goto(f"{lab.url}/login?token={token}")
    expect(page).to_have_url(re.compile(r"/(#.*)?$"))
    page.get_by_test_id("exercise-picker").select_option(EXERCISE)
    expect(page.get_by_test_id("editor").locator(".cm-content")).to_contain_text("def step")
    _shot(page, out / "student.png")

    _set_code(page, code)
    expect(page.get_by_test_id("save-status")).to_contain_text(re.compile("[Ss]aved"),
                                                               timeout=10_000)  # fmt: skip
    page.get_by_test_id("run-button").click()
    expect(page.get_by_test_id("checks").get_by_test_id("check").first).to_be_visible(
        timeout=RUN_TIMEOUT_MS
    )
    page.get_by_test_id("topic-item").filter(has_text="Distance").first.click()
    page.get_by_test_id("topic-field").filter(has_text="data").first.click()
    expect(page.get_by_test_id("plot").first.locator("canvas").first).to_be_visible()
    _shot(page.locator(".run-side"), out / "checks.png")
    _shot(page, out / "plots.png")

    board = page.get_by_test_id("leaderboard")
    expect(page.get_by_test_id("leaderboard-rank")).to_be_visible(timeout=15_000)
    board.locator("summary").click()
    _shot(page.locator("#exercise-text"), out / "leaderboard.png")

    page.locator("#tab-viz").click()
    frame = page.frame_locator("[data-testid=viz-frame]")
    expect(frame.locator("canvas").first).to_be_visible(timeout=30_000)
    page.wait_for_timeout(VIEW_SETTLE_MS)
    # viser's notice that headless Chromium draws with software WebGL says nothing about the lab
    notice = frame.get_by_text("Software WebGL rendering detected")
    if notice.count():
        close = ".mantine-Notification-closeButton, button.mantine-CloseButton-root"
        frame.locator(close).first.click()
        page.wait_for_timeout(500)
    _shot(page.locator(".run-side"), out / "viz.png")
    page.context.close()


def _instructor(browser, lab, out: Path, expect) -> None:
    page = browser.new_context(viewport=VIEWPORT).new_page()
    page.goto(f"{lab.url}/login?token={lab.admin_token}")
    expect(page).to_have_url(re.compile(r"/admin"))
    page.goto(f"{lab.url}/admin#courses")
    page.get_by_role("button", name="Robotics 101").click()
    expect(page.get_by_test_id("board-table").locator("tbody tr")).to_have_count(2, timeout=15_000)
    _shot(page, out / "admin.png")
    page.context.close()
