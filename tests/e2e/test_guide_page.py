"""The guide in Chromium (issue 22): served by the lab under its Content-Security-Policy with
nothing blocked, its search working (Material's search runs in a web worker), its figures
loaded, and reached from both pages' Guide links."""

from __future__ import annotations

import re

import pytest
from playwright.sync_api import expect

from tests.waiting import wait_until

pytestmark = pytest.mark.slow  # Chromium drives the pages: seconds per test


def test_the_guide_reads_searches_and_shows_its_figures(web_lab, new_page, screenshots):
    page = new_page()
    page.goto(f"{web_lab.url}/guide/")
    expect(page).to_have_title(re.compile("RoboDojo guide"))
    page.get_by_role("link", name="Students", exact=True).first.click()
    page.goto(f"{web_lab.url}/guide/students/robots/")
    figure = page.locator("img[src$='crowbot.png']")
    expect(figure).to_be_visible()
    assert figure.evaluate("img => img.complete && img.naturalWidth > 100")
    expect(page.locator("table").first).to_contain_text("Distance")
    page.screenshot(path=str(screenshots / "guide-robots.png"), full_page=False)

    search = page.locator("input.md-search__input")
    results = page.locator(".md-search-result")

    def answered() -> bool:
        # Typed again until the search worker has loaded its index: a query typed before
        # that is not run again by Material.
        search.fill("")
        search.press_sequentially("rosserial")
        page.wait_for_timeout(500)
        return "matching document" in results.inner_text()

    search.click()
    wait_until(answered, 30.0, "the guide's search to answer")
    expect(results).to_contain_text("The robot network")
    page.screenshot(path=str(screenshots / "guide-search.png"), full_page=False)
    assert page.console_watch.errors == []


def test_both_pages_open_the_guide_from_their_header(web_lab, new_page):
    page = new_page()
    page.goto(f"{web_lab.url}/login?token={web_lab.admin_token}")
    expect(page).to_have_url(re.compile(r"/admin"))
    for path, title in (("/admin", "Instructors"), ("/", "Students")):
        page.goto(f"{web_lab.url}{path}")
        with page.context.expect_page() as opened:
            page.get_by_test_id("guide-link").click()
        guide = opened.value
        guide.wait_for_load_state()
        expect(guide.locator("h1")).to_contain_text(title)
        guide.close()
