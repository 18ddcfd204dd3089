"""The student page with a launch file and a data file in the workspace: the student adds two
nodes, a CSV and a launch file in the browser, the run selector switches to the launch file
when its tab opens, and the run starts both nodes (the graph and the console show them), one of
them reading the CSV from its working directory."""

from __future__ import annotations

import re

import pytest
from playwright.sync_api import expect

from tests.e2e.test_student_page import make_student, set_code, shot

pytestmark = pytest.mark.slow  # Chromium drives the pages: seconds per test

TALKER = """\
import rospy
from std_msgs.msg import String

rospy.init_node("talker")
pub = rospy.Publisher("chatter", String, queue_size=10)
rate = rospy.Rate(5)
while not rospy.is_shutdown():
    pub.publish(String(data="hello"))
    rate.sleep()
"""
LISTENER = """\
import csv

import rospy
from std_msgs.msg import String

with open("waypoints.csv") as source:
    print("waypoints", len(list(csv.DictReader(source))))


def heard(message):
    print("heard", message.data)


rospy.init_node("listener")
rospy.Subscriber("chatter", String, heard)
rospy.spin()
"""
WAYPOINTS = "x,y\n0.5,0.0\n1.0,0.5\n"
LAUNCH = """\
<launch>
  <node pkg="chat" type="talker.py" name="talker" output="screen"/>
  <node pkg="chat" type="listener.py" name="listener" output="screen"/>
</launch>
"""


def add_node(page, name: str, code: str) -> None:
    page.get_by_test_id("file-new").click()
    page.get_by_label("Node name").fill(name)
    page.get_by_label("Node name").press("Enter")
    expect(page.get_by_test_id("editor-tab").and_(page.locator(f'[data-file="{name}.py"]')))\
        .to_have_attribute("aria-selected", "true")  # fmt: skip
    set_code(page, code)


def add_data_file(page, name: str, text: str) -> None:
    page.get_by_test_id("file-new-data").click()
    page.get_by_test_id("file-new-name").fill(name)
    page.get_by_test_id("file-new-create").click()
    tab = page.get_by_test_id("editor-tab").and_(page.locator(f'[data-file="{name}"]'))
    expect(tab).to_have_attribute("aria-selected", "true")
    set_code(page, text)


def test_a_launch_file_in_the_workspace_runs_its_nodes(web_lab, new_page, screenshots):
    invite = make_student(web_lab, new_page, screenshots, "lin")
    page = new_page()
    page.goto(invite)
    expect(page).to_have_url(re.compile(r"/(#.*)?$"))
    page.goto(f"{web_lab.url}/#free/crowbot/wall_approach")
    expect(page.get_by_test_id("editor").locator(".cm-content")).to_contain_text("def ")

    add_node(page, "talker", TALKER)
    add_node(page, "listener", LISTENER)
    add_data_file(page, "waypoints.csv", WAYPOINTS)
    # A name the server would refuse is stopped in the form, with the reason.
    page.get_by_test_id("file-new-data").click()
    page.get_by_test_id("file-new-name").fill("../secret.csv")
    page.get_by_test_id("file-new-create").click()
    assert "no hidden files, '..'" in page.get_by_test_id("file-new-name").evaluate(
        "input => input.validationMessage"
    )
    page.get_by_test_id("file-new-name").press("Escape")
    add_data_file(page, "two.launch", LAUNCH)
    # Opening the launch file's tab chose it as what runs; the params field is for nodes only.
    expect(page.get_by_test_id("run-what")).to_have_value("two.launch")
    expect(page.get_by_test_id("run-params")).to_be_hidden()
    expect(page.get_by_test_id("save-status")).to_contain_text(re.compile("[Ss]aved"),
                                                               timeout=10_000)  # fmt: skip
    shot(page, screenshots, "student-launch-file")

    page.get_by_test_id("run-duration").fill("3")
    page.get_by_test_id("run-button").click()
    expect(page.get_by_test_id("run-state")).to_contain_text("finished", timeout=30_000)
    console = page.get_by_test_id("console")
    expect(console).to_contain_text("waypoints 2")
    expect(console).to_contain_text("heard hello")
    page.locator("#tab-graph").click()
    graph = page.get_by_test_id("graph")
    expect(graph.locator('[data-testid="graph-node"][data-name="talker"]')).to_be_visible()
    expect(graph.locator('[data-testid="graph-node"][data-name="listener"]')).to_be_visible()
    expect(graph.locator('[data-testid="graph-topic"][data-name*="chatter"]')).to_be_visible()
    shot(page, screenshots, "student-launch-run")

    # The files survive a reload, data files among them; "my nodes" runs the .py files only.
    page.reload()
    tabs = page.get_by_test_id("editor-tab")
    expect(tabs.and_(page.locator('[data-file="waypoints.csv"]'))).to_be_visible()
    expect(page.get_by_test_id("run-what")).to_have_value("")
    page.get_by_test_id("run-params").fill("_speed:=0.2\nbad line")
    page.get_by_test_id("run-button").click()
    expect(page.get_by_test_id("run-message")).to_contain_text("params line 2")
    assert page.console_watch.errors == [], page.console_watch.errors
