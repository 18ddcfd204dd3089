"""The guide at /guide/ (issue 22): served by the lab itself from web/guide/, public, under the
same Content-Security-Policy as the pages, and linked from both pages' headers."""

from __future__ import annotations

import re

import pytest

from server.api.http_guards import CONTENT_SECURITY_POLICY

pytestmark = pytest.mark.parametrize("lab", ["sqlite"], indirect=True)


def test_the_guide_is_served_without_a_login(lab):
    with lab.client() as anonymous:
        home = anonymous.get("/guide/")
        page = anonymous.get("/guide/students/getting-started/")
        short = anonymous.get("/guide", follow_redirects=False)
    assert home.status_code == 200 and "RoboDojo guide" in home.text
    assert page.status_code == 200 and "Getting started" in page.text
    assert short.status_code in (307, 308) and short.headers["location"].endswith("/guide/")
    assert home.headers["content-security-policy"] == CONTENT_SECURITY_POLICY


def test_a_missing_guide_page_is_the_guides_404(lab):
    with lab.client() as anonymous:
        answer = anonymous.get("/guide/no-such-page/")
    assert answer.status_code == 404
    assert "RoboDojo guide" in answer.text


def test_the_guide_never_leaves_the_guide_folder(lab):
    with lab.client() as anonymous:
        for path in ("/guide/../index.html", "/guide/%2e%2e/%2e%2e/server/api/app.py",
                     "/guide/..%2f..%2fpyproject.toml"):  # fmt: skip
            answer = anonymous.get(path)
            assert "create_app" not in answer.text and "[project]" not in answer.text, path


def test_both_pages_link_to_the_guide_in_their_header(lab):
    with lab.client() as anonymous:
        for path, target in (("/", "/guide/students/"), ("/admin", "/guide/instructors/")):
            header = re.search(r"<header.*?</header>", anonymous.get(path).text, re.DOTALL)
            assert header is not None, path
            assert f'href="{target}"' in header.group(0), path
            assert anonymous.get(target).status_code == 200, target
