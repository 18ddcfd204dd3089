"""The student page's "Sim vs real" view in Chromium: a run on the emulated CrowBot firmware
after the simulation run that passed its gate; the student opens it from the history, the
instructor by its id, and both see the check table and a chart per topic with both runs."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

from tests.hardware.test_comparison import EXERCISE, bench, exercise_run  # noqa: F401 (a fixture)

pytestmark = pytest.mark.slow  # a server, an emulated robot and Chromium


def test_the_student_and_the_instructor_see_sim_vs_real(bench, new_page, screenshots):  # noqa: F811
    student = bench.student("ada")
    simulated = exercise_run(student)
    student.post("/api/hardware/crowbot-1/queue")
    real = exercise_run(student, hardware="crowbot-1")
    assert real["simulation_run"] == simulated["id"]

    page = new_page(1400, 900)
    page.goto(f"{bench.url}/login?token={student.token}")
    page.goto(f"{bench.url}/#{EXERCISE}")
    page.get_by_role("tab", name="History").click()
    row = page.locator(f'[data-testid="history-row"][data-run="{real["id"]}"]')
    row.get_by_test_id("history-compare").click()
    expect(page.get_by_role("tab", name="Sim vs real")).to_have_attribute("aria-selected", "true")
    table = page.get_by_test_id("compare-checks")
    expect(table.locator("tbody tr")).to_have_count(4)
    expect(table.locator('tr[data-check="collisions"] td').nth(3)).to_have_text("the same")
    charts = page.get_by_test_id("compare-chart")
    expect(charts.first).to_have_attribute("data-topic", "Distance")
    topics = charts.evaluate_all("(figures) => figures.map((f) => f.dataset.topic)")
    assert topics[:3] == ["Distance", "Control", "Control_applied"]
    # Both runs drawn in the distance chart: a simulation and a robot line in its legend.
    legend = charts.first.locator(".u-legend").inner_text()
    assert "data [cm] sim" in legend and "data [cm] robot" in legend
    page.screenshot(path=str(screenshots / "compare-student.png"), full_page=True)
    assert not page.console_watch.errors, page.console_watch.errors

    teacher = new_page(1400, 900)
    teacher.goto(f"{bench.url}/login?token={bench.admin_token}")
    teacher.goto(f"{bench.url}/?run={real['id']}")
    teacher.get_by_role("tab", name="Sim vs real").click()
    expect(teacher.get_by_test_id("compare-checks").locator("tbody tr")).to_have_count(4)
    assert not teacher.console_watch.errors, teacher.console_watch.errors
