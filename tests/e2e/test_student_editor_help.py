"""The editor's help in a real browser against the real analysis routes (/api/editor/*): a typo
is underlined with its message, asked for only once typing stops; completion offers `linear`
after `cmd.` for a Twist; Format re-indents in one undoable edit (Shift+Alt+F too) and says
why it cannot when the code does not parse; find/replace; the colours follow the system's dark
mode live; axe-core finds no accessibility violation in the editor, light or dark; a completion
that answers after the student switched to a data file's tab is dropped without a page error."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from playwright.sync_api import expect

from tests.e2e.test_student_page import set_code, shot
from tests.waiting import wait_until

pytestmark = pytest.mark.slow  # Chromium drives the pages: seconds per test

AXE = Path(__file__).resolve().parents[2] / "web" / "node_modules" / "axe-core" / "axe.min.js"
READY_S = 180.0  # [s] the analysis workers' start and warm-up on a loaded 2-core machine
ANSWER_MS = 30_000  # [ms] for one answer of the warm analysis, on a loaded machine
LINT_DELAY_MS = 400  # web/src/student/assist.js: no lint request sooner after a keystroke
TYPO = "def step(obs):\n    distance = 1.0\n    print(distance)\n    return distancia\n"
TWIST = "from geometry_msgs.msg import Twist\n\n\ndef step(obs):\n    cmd = Twist()\n    cmd"
SQUASHED = "def step(obs):\n  if obs.time > 1:\n      return (0.1,0.0)\n  return None\n"
FORMATTED = "def step(obs):\n    if obs.time > 1:\n        return (0.1, 0.0)\n    return None\n"


@pytest.fixture(scope="module")
def editor_ready(web_lab) -> None:
    """The server's analysis workers answer (they read jedi, rospy and numpy at start)."""
    client = web_lab.student("editor-warm-up")
    request = {"code": "import rospy\nrospy.", "filename": "warm.py", "exercise": None,
               "robot": None, "line": 2, "column": 6}  # fmt: skip

    def ready():
        answer = client.post("/api/editor/complete", json=request)
        return answer.status_code == 200 and answer.json()["completions"]

    wait_until(ready, READY_S, "the editor's analysis answered", poll_s=0.5)


def open_editor(web_lab, new_page, name: str):
    """A student's page on free play with the crowbot, the editor showing its template."""
    _, token = web_lab.new_user(name)
    page = new_page()
    page.goto(f"{web_lab.url}/login?token={token}")
    expect(page).to_have_url(re.compile(r"/(#.*)?$"))
    page.goto(f"{web_lab.url}/#free/crowbot/wall_approach")
    expect(editor_text(page)).to_contain_text("def step")
    return page


def editor_text(page):
    return page.get_by_test_id("editor").locator(".cm-content")


def doc(page) -> str:
    """The editor's text (every line is drawn: the texts here are short)."""
    lines = page.locator("#editor .cm-line").all_text_contents()
    return "\n".join(lines)


def test_a_typo_is_underlined_with_its_message_once_typing_stops(
    web_lab, editor_ready, new_page, screenshots
):
    page = open_editor(web_lab, new_page, "typo")
    set_code(page, TYPO)
    underline = page.get_by_test_id("editor").locator(".cm-lintRange-error")
    expect(underline).to_have_text("distancia", timeout=ANSWER_MS)
    expect(page.locator(".cm-lint-marker-error")).to_have_count(1)
    underline.hover()
    tooltip = page.locator(".cm-tooltip-lint")
    expect(tooltip).to_contain_text("distancia")
    expect(tooltip.locator(".cm-diagnosticSource")).not_to_be_empty()  # the rule's id
    shot(page, screenshots, "editor-help-typo")

    # Typing faster than the debounce asks nothing until it stops: every lint request starts at
    # least LINT_DELAY_MS after the keystroke before it (times from the page's own clock).
    page.evaluate("""() => {
        window.keyTimes = [];
        document.addEventListener('keydown', () => window.keyTimes.push(performance.now()), true);
        performance.clearResourceTimings();
    }""")
    page.keyboard.press("Control+End")
    page.keyboard.type("\nprint(distance_total)", delay=40)
    expect(underline).to_have_text(["distancia", "distance_total"], timeout=ANSWER_MS)
    times = page.evaluate("""() => ({
        keys: window.keyTimes,
        lints: performance.getEntriesByType('resource')
            .filter((entry) => entry.name.endsWith('/api/editor/lint'))
            .map((entry) => entry.startTime),
    })""")
    assert times["lints"], "no lint request after typing"
    for started in times["lints"]:
        last_key = max(key for key in times["keys"] if key < started)  # a key was pressed first
        assert started - last_key >= LINT_DELAY_MS - 15, (started, last_key, times)
    assert page.console_watch.errors == [], page.console_watch.errors


def test_completion_offers_linear_after_cmd_dot(web_lab, editor_ready, new_page, screenshots):
    page = open_editor(web_lab, new_page, "complete")
    set_code(page, TWIST)
    page.keyboard.type(".")
    option = page.locator(".cm-tooltip-autocomplete li").filter(has_text=re.compile(r"^linear"))
    expect(option).to_be_visible(timeout=ANSWER_MS)
    first = page.locator(".cm-tooltip-autocomplete li .cm-completionLabel").first
    expect(first).to_have_text(re.compile(r"^[^_]"))  # dunder names last
    shot(page, screenshots, "editor-help-complete")
    page.keyboard.type("lin")
    expect(page.locator(".cm-tooltip-autocomplete li[aria-selected]")).to_contain_text("linear")
    page.keyboard.press("Enter")
    assert doc(page).endswith("cmd.linear")

    # Inside a call's parentheses: the signature, above the call.
    page.keyboard.press("Enter")
    page.keyboard.type("print(")
    signature = page.get_by_test_id("signature-help")
    expect(signature).to_contain_text("print(", timeout=ANSWER_MS)
    page.keyboard.press("Escape")
    expect(signature).to_have_count(0)

    # Hover: the pointer resting on a name shows what it is.
    page.get_by_test_id("editor").locator(".cm-line").first.get_by_text("Twist").hover()
    expect(page.get_by_test_id("hover-doc")).to_contain_text("Twist", timeout=ANSWER_MS)
    assert page.console_watch.errors == [], page.console_watch.errors


def test_format_reindents_in_one_undoable_edit(web_lab, editor_ready, new_page, screenshots):
    page = open_editor(web_lab, new_page, "format")
    button = page.get_by_test_id("format-button")
    assert "Shift+Alt+F" in button.get_attribute("title")
    set_code(page, SQUASHED)
    button.click()
    expect(editor_text(page)).to_contain_text("        return (0.1, 0.0)", timeout=ANSWER_MS)
    assert doc(page) == FORMATTED
    expect(page.get_by_test_id("format-status")).to_have_text("Formatted.")
    page.keyboard.press("Control+z")  # one step back: the text as it was before formatting
    expect(editor_text(page)).to_contain_text("      return (0.1,0.0)")
    assert doc(page) == SQUASHED

    # The keyboard shortcut; then a text that does not parse is left alone, with a sentence.
    editor_text(page).click()
    page.keyboard.press("Shift+Alt+F")
    expect(editor_text(page)).to_contain_text("        return (0.1, 0.0)", timeout=ANSWER_MS)
    set_code(page, "def step(obs:\n  return None\n")
    button.click()
    outcome = page.get_by_test_id("format-status")
    expect(outcome).to_contain_text(re.compile(r"line \d+"), timeout=ANSWER_MS)  # where it broke
    assert doc(page) == "def step(obs:\n  return None\n"
    shot(page, screenshots, "editor-help-format-error")
    # Chromium logs every 4xx answer to the console; the 422 of the refusal is the expected one.
    errors = [e for e in page.console_watch.errors if "status of 422" not in e]
    assert len(errors) < len(page.console_watch.errors), "no 422 answer"
    assert errors == [], page.console_watch.errors


def test_find_and_replace(web_lab, new_page):
    page = open_editor(web_lab, new_page, "replace")
    set_code(page, "speed = 1\nprint(speed)\n")
    page.keyboard.press("Control+f")
    panel = page.locator(".cm-search")
    expect(panel).to_be_visible()
    panel.get_by_role("textbox", name="Find").fill("speed")
    panel.get_by_role("textbox", name="Replace").fill("velocity")
    panel.get_by_role("button", name="replace all").click()
    expect(editor_text(page)).to_contain_text("print(velocity)")
    assert doc(page) == "velocity = 1\nprint(velocity)\n"


def axe_violations(page) -> list[dict]:
    """axe-core's violations in the editor and its toolbar (script evaluated, not a <script>
    tag: the page's Content-Security-Policy forbids inline scripts)."""
    if not AXE.exists():
        pytest.fail(f"{AXE} is missing: run `cd web && npm ci` (axe-core is a devDependency)")
    if not page.evaluate("() => Boolean(window.axe)"):
        page.evaluate(AXE.read_text())
    return page.evaluate("""async () => {
        const result = await axe.run({include: [['#editor'], ['.editor-bar']]});
        return result.violations.map((v) => ({id: v.id, help: v.help,
            nodes: v.nodes.map((n) => n.target.join(' ') + ': ' + n.failureSummary)}));
    }""")


def test_the_editor_follows_the_system_colour_scheme_live(web_lab, new_page, screenshots):
    page = open_editor(web_lab, new_page, "scheme")
    page.emulate_media(color_scheme="light")
    set_code(page, TYPO)
    content = page.locator("#editor .cm-editor")
    light = content.evaluate("element => getComputedStyle(element).backgroundColor")
    assert axe_violations(page) == []

    # The system turns dark: the editor follows at once, without a reload.
    page.emulate_media(color_scheme="dark")
    expect(content).not_to_have_css("background-color", light)
    dark = content.evaluate("element => getComputedStyle(element).backgroundColor")
    red, green, blue = (int(part) for part in re.findall(r"\d+", dark)[:3])
    assert red + green + blue < 3 * 64, dark
    shot(page, screenshots, "editor-dark")
    assert axe_violations(page) == []
    page.emulate_media(color_scheme="light")
    expect(content).to_have_css("background-color", light)
    assert page.console_watch.errors == [], page.console_watch.errors


def test_axe_finds_no_violation_with_diagnostics_and_completions_shown(
    web_lab, editor_ready, new_page, screenshots
):
    page = open_editor(web_lab, new_page, "axe")
    set_code(page, TYPO + "pri")
    expect(page.locator(".cm-lintRange-error")).to_have_count(2, timeout=ANSWER_MS)
    page.keyboard.press("Control+Space")  # the completion list is open while axe looks
    expect(page.locator(".cm-tooltip-autocomplete li").first).to_be_visible(timeout=ANSWER_MS)
    for scheme in ("light", "dark"):
        page.emulate_media(color_scheme=scheme)
        assert axe_violations(page) == [], scheme
        shot(page, screenshots, f"editor-help-{scheme}")
    assert page.console_watch.errors == [], page.console_watch.errors


def test_a_completion_answering_after_the_tab_switched_is_dropped(web_lab, editor_ready, new_page):
    """A completion asked for in a Python file whose answer comes after the student opened a
    data file's tab is dropped without a page error (CodeMirror's completion plugin outlives its
    editor state and reads the completion state of the one on show)."""
    page = open_editor(web_lab, new_page, "complete-late")
    held = []
    page.route("**/api/editor/complete", lambda route: held.append(route))  # answered below
    set_code(page, TWIST)
    page.keyboard.type(".")
    wait_until(lambda: page.wait_for_timeout(50) or held, ANSWER_MS / 1000, "a completion asked")
    page.get_by_test_id("file-new-data").click()
    page.get_by_test_id("file-new-name").fill("points.csv")
    page.get_by_test_id("file-new-create").click()
    tab = page.get_by_test_id("editor-tab").and_(page.locator('[data-file="points.csv"]'))
    expect(tab).to_have_attribute("aria-selected", "true")
    with page.expect_response("**/api/editor/complete", timeout=ANSWER_MS) as answered:
        for route in held:
            route.continue_()
    assert answered.value.ok
    page.wait_for_timeout(500)  # the answer reaches the completion plugin
    expect(page.locator(".cm-tooltip-autocomplete")).to_have_count(0)
    assert page.console_watch.errors == [], page.console_watch.errors
