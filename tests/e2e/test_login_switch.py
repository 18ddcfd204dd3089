"""Login CSRF in Chromium (issue 14, finding 2): an invite link opened in a browser that is
signed in as someone else asks first; its button (a same-origin form POST, as Chromium sends
it: Origin and Sec-Fetch-Site) switches the account."""

from __future__ import annotations

import pytest

from tests.api.conftest import LabServer

pytestmark = pytest.mark.slow  # Chromium drives the pages: seconds per test


def test_a_login_link_in_a_signed_in_browser_asks_then_switches(
    web_lab: LabServer, new_page
) -> None:
    from playwright.sync_api import expect

    lab = web_lab
    user, token = lab.new_user("Ada Switch")
    page = new_page()
    answer = page.context.request.get(f"{lab.url}/login?token={lab.admin_token}", max_redirects=0)
    assert answer.status == 303, answer.text()

    page.goto(f"{lab.url}/login?token={token}")
    expect(page.locator("p")).to_contain_text("You are signed in as instructor.")
    expect(page.locator("p")).to_contain_text("Sign in as Ada Switch instead?")
    me = page.context.request.get(f"{lab.url}/api/me").json()
    assert me["name"] == "instructor"  # asking switched nothing

    page.get_by_role("button", name="Sign in as Ada Switch").click()
    page.wait_for_url(f"{lab.url}/")
    assert page.context.request.get(f"{lab.url}/api/me").json()["id"] == user["id"]
