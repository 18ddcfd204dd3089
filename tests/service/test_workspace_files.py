"""The rules of what a workspace holds (server/service/workspace_files.py) and how a launch file
of it becomes nodes (server/service/workspace_runs.py), as pure functions: names, kinds, sizes,
text, caps, the data files a run copies, and a reader fault turned into a sentence."""

from __future__ import annotations

import logging
import re

import pytest

from server.runs.launch import LaunchFileError
from server.service import workspace_runs
from server.service.runs import RunRequestError
from server.service.workspace_files import (
    Caps,
    WorkspaceFileError,
    check_content,
    check_fits,
    data_files,
    file_name,
    is_node_file,
)

CAPS = Caps(code_bytes=100, data_bytes=200, workspace_bytes=300, files=3)


@pytest.mark.parametrize(
    ("given", "stored"),
    [
        ("pid", "pid.py"),
        ("pid.py", "pid.py"),
        ("waypoints.csv", "waypoints.csv"),
        ("config/gains.yaml", "config/gains.yaml"),
        ("launch/two.launch", "launch/two.launch"),
        ("scripts/helper", "scripts/helper.py"),
        ("Map-1.JSON", "Map-1.JSON"),
    ],
)
def test_good_names_are_stored_as_given_with_py_for_a_bare_node_name(given, stored):
    assert file_name(given) == stored


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ("", "empty"),
        (" a.csv", "space"),
        ("/etc/passwd", "absolute"),
        ("C:x.csv", "absolute"),
        ("a\\b.csv", "absolute"),
        ("../x.csv", "'..'"),
        ("a//b.csv", "empty"),
        ("./a.csv", "'.'"),
        (".env.txt", "hidden"),
        ("a/b/c/d.csv", "folders deep"),
        ("a b.csv", "only letters"),
        ("x.exe", "'.exe' cannot be kept"),
        ("x.tar.gz", "'.gz' cannot be kept"),
        ("2fast.py", "node name"),
        ("a" * 62 + ".csv", "longer than 64"),
    ],
)
def test_bad_names_are_refused_with_a_sentence(name, words):
    with pytest.raises(WorkspaceFileError, match=re.escape(words)) as caught:
        file_name(name)
    assert caught.value.status == 422


def test_only_top_level_python_files_are_nodes():
    assert is_node_file("pid.py") and not is_node_file("scripts/pid.py")
    assert not is_node_file("two.launch") and not is_node_file("pid.csv")
    assert not is_node_file("two.launch.py")  # a ROS 2 launch file is code, never a node


def test_a_ros2_launch_file_keeps_its_name():
    assert file_name("launch/two.launch.py") == "launch/two.launch.py"
    assert file_name("bringup.launch.py") == "bringup.launch.py"
    with pytest.raises(WorkspaceFileError, match=re.escape(".launch.py for a ROS 2 launch")):
        file_name("2.launch.py")


def test_sizes_are_capped_per_kind_and_binary_text_is_refused():
    check_content("a.py", "#" * 100, CAPS)
    check_content("a.csv", "1" * 200, CAPS)
    with pytest.raises(WorkspaceFileError, match="code file is 100 bytes") as code:
        check_content("a.py", "#" * 101, CAPS)
    assert code.value.status == 413
    with pytest.raises(WorkspaceFileError, match="data file is 200 bytes"):
        check_content("a.csv", "é" * 101, CAPS)  # bytes, not characters
    with pytest.raises(WorkspaceFileError, match="0x00 on line 3"):
        check_content("a.csv", "a\nb\n\x00", CAPS)
    with pytest.raises(WorkspaceFileError, match="0x1b"):
        check_content("a.txt", "colour \x1b[31m", CAPS)
    check_content("a.txt", "tab\there\r\nform\x0cfeed\n", CAPS)


def test_the_workspace_caps_count_files_and_bytes_of_the_newest_versions():
    existing = {"a.py": 100, "b.csv": 150}
    check_fits("b.csv", "x" * 200, existing, CAPS)  # replaces b: 100 + 200
    with pytest.raises(WorkspaceFileError, match="the limit is 300 bytes") as total:
        check_fits("c.csv", "x" * 51, existing, CAPS)
    assert total.value.status == 413
    with pytest.raises(WorkspaceFileError, match="at most 3 files"):
        check_fits("d.csv", "", {**existing, "c.csv": 0}, CAPS)
    check_fits("c.csv", "", {**existing, "c.csv": 0}, CAPS)  # saving an existing file


def test_a_run_copies_every_data_file_and_no_code():
    files = {"pid.py": "x", "scripts/h.py": "y", "w.csv": "1,2\n", "c/g.yaml": ""}
    files["a.launch"] = "<l/>"
    assert data_files(files.items()) == (
        ("a.launch", b"<l/>"),
        ("c/g.yaml", b""),
        ("w.csv", b"1,2\n"),
    )


def test_a_launch_file_must_be_one_of_the_workspace():
    files = {"two.launch": "<launch/>", "pid.py": "x"}
    with pytest.raises(RunRequestError, match=re.escape("its launch files: two.launch")):
        workspace_runs.launch_plan(files, "one.launch", {}, None)
    with pytest.raises(RunRequestError, match="not a launch file"):
        workspace_runs.launch_plan(files, "pid.py", {}, None)
    with pytest.raises(RunRequestError, match="no launch file yet"):
        workspace_runs.launch_plan({"pid.py": "x"}, "x.launch", {}, None)
    with pytest.raises(WorkspaceFileError, match=re.escape("'..'")):
        workspace_runs.launch_plan(files, "../two.launch", {}, None)


def test_a_fault_of_the_reader_is_a_sentence_with_an_incident_not_a_crash(monkeypatch, caplog):
    def broken(*_args):
        raise TypeError("'int' object is not iterable")

    monkeypatch.setattr(workspace_runs, "read_launch", broken)
    expected = re.escape("could not be read (TypeError; incident")
    with (
        caplog.at_level(logging.ERROR, "robodojo.service"),
        pytest.raises(LaunchFileError, match=expected),
    ):
        workspace_runs.launch_plan({"a.launch": "<launch/>"}, "a.launch", {}, None)
    assert "the launch reader failed on a.launch" in caplog.text
