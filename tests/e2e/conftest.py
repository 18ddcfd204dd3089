"""End-to-end tests: the real server (`robodojo serve` in a subprocess) and Debian's Chromium
driven by Playwright, headless, with the flags this machine needs (no sandbox: we run as root
in a container; no GPU; no background networking: the machine has no internet and Chromium
would otherwise retry its update and sync hosts for the whole test).

Screenshots of every page land in `test-artifacts/screenshots/` (ROBODOJO_SCREENSHOTS to move
it), a folder CI keeps.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.api.conftest import LabServer, start_server, stop_server

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_FLAGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    "--no-first-run",
]
SCREENSHOTS = Path(
    os.environ.get("ROBODOJO_SCREENSHOTS", Path(__file__).resolve().parents[2] / "test-artifacts"
                   / "screenshots")
)  # fmt: skip


@pytest.fixture(scope="module")
def browser():
    """Per module, not per session: Playwright's sync API keeps an asyncio loop running on this
    thread while it is open, and later tests that call asyncio.run() would find it."""
    from playwright.sync_api import sync_playwright

    if not Path(CHROMIUM).exists():
        pytest.fail(
            f"{CHROMIUM} is missing: ./scripts/test installs Debian's chromium package; run it, "
            "or apt-get install chromium"
        )
    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(
            executable_path=CHROMIUM, headless=True, args=CHROMIUM_FLAGS
        )
        yield chromium
        chromium.close()


@pytest.fixture(scope="session")
def web_lab(tmp_path_factory) -> Iterator[LabServer]:
    server = start_server(tmp_path_factory.mktemp("web-lab"))
    yield server
    stop_server(server)


@pytest.fixture(autouse=True)
def _close_web_lab_clients(request) -> Iterator[None]:
    yield
    if "web_lab" in request.fixturenames:
        request.getfixturevalue("web_lab").close_clients()


@pytest.fixture(scope="session")
def screenshots() -> Path:
    shutil.rmtree(SCREENSHOTS, ignore_errors=True)
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    return SCREENSHOTS


class ConsoleWatch:
    """Console errors and uncaught page errors: a page under test must have none."""

    def __init__(self, page) -> None:
        self.errors: list[str] = []
        page.on("console", self._console)
        page.on("pageerror", lambda error: self.errors.append(f"pageerror: {error}"))

    def _console(self, message) -> None:
        if message.type == "error":
            self.errors.append(f"console: {message.text}")


@pytest.fixture
def new_page(browser):
    """A fresh browser context (its own cookies) per user; closed after the test."""
    contexts = []

    def make(width: int = 1366, height: int = 768):
        context = browser.new_context(viewport={"width": width, "height": height},
                                      accept_downloads=True)  # fmt: skip
        contexts.append(context)
        page = context.new_page()
        page.console_watch = ConsoleWatch(page)
        pages.append(page)
        return page

    pages = []
    yield make
    for context in contexts:
        context.close()
    # The pages are served with a Content-Security-Policy (server/api/http_guards.py): anything
    # it blocks shows as a console error, and fails every test whether it checks errors or not.
    blocked = [e for page in pages for e in page.console_watch.errors if "Content Security" in e]
    assert not blocked, blocked
