"""Launch files that cannot run: each is a LaunchFileError whose sentence names the file, the
line and what to do, whether the mistake is found while the file runs in the sandbox or by
what became of the job (a loop is stopped at its budget)."""

from __future__ import annotations

import re

import pytest

from server.runs.launch import LaunchFileError
from server.runs.launch_py import read_launch
from tests.launch2.conftest import JOB_BUDGET_S, plan_of, workspace

HEAD = (
    "from launch import LaunchDescription\n"
    "from launch.actions import DeclareLaunchArgument\n"
    "from launch.substitutions import LaunchConfiguration\n"
    "from launch_ros.actions import Node\n"
)  # four lines: the launch files below start on line 5


def launch(body: str) -> str:
    return HEAD + "def generate_launch_description():\n" + body


def error_of(launcher, text: str, **args: str) -> LaunchFileError:
    with pytest.raises(LaunchFileError) as caught:
        plan_of(launcher, workspace(bad=text), "bad", **args)
    return caught.value


def assert_error(error: LaunchFileError, line: int | None, *patterns: str) -> None:
    assert error.filename == "my_pkg/launch/bad.launch.py", str(error)
    assert error.line == line, str(error)
    for pattern in patterns:
        assert re.search(pattern, error.problem), error.problem


def test_a_syntax_error_names_its_line(launcher):
    error = error_of(launcher, launch("    return LaunchDescription([\n"))
    assert_error(error, 6, r"invalid Python: '\[' was never closed")


def test_a_package_not_in_the_workspace(launcher):
    body = (
        "    from ament_index_python.packages import get_package_share_directory\n"
        "    get_package_share_directory('other_pkg')\n"
    )
    error = error_of(launcher, launch(body))
    assert_error(error, 7, r"package 'other_pkg' is not in your workspace", r"my_pkg")


def test_an_argument_nobody_declares(launcher):
    body = "    return LaunchDescription([DeclareLaunchArgument('speed', default_value='1')])\n"
    error = error_of(launcher, launch(body), sped="0.3")
    assert_error(error, None, r"launch argument\(s\) sped are not declared", r"declared: speed")


def test_a_required_argument_not_given(launcher):
    body = "    return LaunchDescription([\n        DeclareLaunchArgument('robot'),\n    ])\n"
    error = error_of(launcher, launch(body))
    assert_error(error, 7, r"'robot' has no default_value and was not given", r"robot:=VALUE")


def test_a_configuration_used_before_it_is_declared(launcher):
    body = (
        "    return LaunchDescription([\n"
        "        Node(package='my_pkg', executable='talker',\n"
        "             name=LaunchConfiguration('nmae')),\n"
        "    ])\n"
    )
    error = error_of(launcher, launch(body))
    assert_error(error, 8, r"launch configuration 'nmae' does not exist")


def test_a_launch_file_cannot_open_a_socket(launcher):
    body = "    import socket\n    socket.create_connection(('192.0.2.1', 80))\n"
    error = error_of(launcher, launch(body))
    assert_error(error, 7, r"PermissionError", r"cannot open network connections")


@pytest.mark.slow
def test_a_launch_file_that_never_returns_is_stopped(launcher):
    error = error_of(launcher, launch("    while True:\n        pass\n"))
    assert_error(error, None, rf"longer than {JOB_BUDGET_S:g} s and was stopped", "loop")


def test_the_robot_comes_from_the_run(launcher):
    body = (
        "    return LaunchDescription([\n"
        "        Node(package='rviz2', executable='rviz2'),\n"
        "    ])\n"
    )
    error = error_of(launcher, launch(body))
    assert_error(error, 7, r"runs a ROS program that a run does not have", r"remove this Node")


def test_an_executable_that_is_not_in_the_workspace(launcher):
    body = "    return LaunchDescription([Node(package='my_pkg', executable='talkr')])\n"
    error = error_of(launcher, launch(body))
    assert_error(error, 6, r"no workspace file is executable 'talkr'", r"my_pkg/my_pkg/talker.py")


def test_a_parameter_file_without_ros__parameters(launcher):
    files = workspace(
        bad=launch(
            "    return LaunchDescription([Node(package='my_pkg', executable='talker',\n"
            "        parameters=['my_pkg/config/flat.yaml'])])\n"
        )
    )
    files["my_pkg/config/flat.yaml"] = "speed: 0.2\n"
    with pytest.raises(LaunchFileError) as caught:
        plan_of(launcher, files, "bad")
    assert_error(
        caught.value, 6, r"my_pkg/config/flat.yaml is not a ROS 2 parameter file", "ros__parameters"
    )


def test_a_condition_that_is_not_a_boolean(launcher):
    body = (
        "    from launch.conditions import IfCondition\n"
        "    return LaunchDescription([\n"
        "        DeclareLaunchArgument('use', default_value='maybe'),\n"
        "        Node(package='my_pkg', executable='talker',\n"
        "             condition=IfCondition(LaunchConfiguration('use'))),\n"
        "    ])\n"
    )
    error = error_of(launcher, launch(body))
    assert_error(error, 10, r"'maybe'; it must be one of true, false, 1 or 0")


def test_what_the_reader_lacks_is_named_on_import(launcher):
    body = "    from launch.actions import SetROSLogDir\n"
    error = error_of(launcher, launch(body))
    assert_error(error, 6, r"launch\.actions\.SetROSLogDir is not available")


def test_programs_and_event_handlers_are_refused(launcher):
    body = (
        "    from launch.actions import ExecuteProcess\n"
        "    return LaunchDescription([\n"
        "        ExecuteProcess(cmd=['ros2', 'bag', 'record', '-a']),\n"
        "    ])\n"
    )
    error = error_of(launcher, launch(body))
    assert_error(error, 8, r"ExecuteProcess runs a program")


def test_ros2_xml_and_yaml_launch_files_are_not_read(launcher):
    files = workspace()
    files["my_pkg/launch/two.launch.xml"] = "<launch/>\n"
    with pytest.raises(LaunchFileError, match=r"ROS 2 XML/YAML launch file.*\.launch\.py"):
        read_launch("my_pkg/launch/two.launch.xml", files, {}, launcher)
    # Named as ROS 1 files but written for ROS 2: told apart by what they hold.
    files["my_pkg/launch/ros2.launch"] = '<launch>\n  <node pkg="my_pkg" exec="talker"/>\n</launch>'
    files["my_pkg/launch/ros2.yaml"] = "launch:\n- node: {pkg: my_pkg, exec: talker}\n"
    for name in ("ros2.launch", "ros2.yaml"):
        with pytest.raises(LaunchFileError, match=r"is a ROS 2 XML/YAML launch file"):
            read_launch(f"my_pkg/launch/{name}", files, {}, launcher)
    body = (
        "    from launch.actions import IncludeLaunchDescription\n"
        "    return LaunchDescription([IncludeLaunchDescription('my_pkg/launch/two.launch.xml')])\n"
    )
    files["my_pkg/launch/bad.launch.py"] = launch(body)
    with pytest.raises(LaunchFileError) as caught:
        read_launch("my_pkg/launch/bad.launch.py", files, {}, launcher)
    assert_error(caught.value, 7, r"ROS 2 XML or YAML launch file", r"write it as a \.launch\.py")


def test_a_python_node_is_not_a_launch_file(launcher):
    with pytest.raises(LaunchFileError, match=r"defines no generate_launch_description\(\)"):
        read_launch("my_pkg/my_pkg/talker.py", workspace(), {}, launcher)


def test_an_environment_variable_and_old_spellings_get_a_hint(launcher):
    error = error_of(launcher, launch("    import os\n    os.environ['TURTLEBOT3_MODEL']\n"))
    assert_error(error, 7, r"KeyError: 'TURTLEBOT3_MODEL'", r"a run has none: use a launch arg")
    body = "    return LaunchDescription([Node(package='my_pkg', node_executable='talker')])\n"
    error = error_of(launcher, launch(body))
    assert_error(error, 6, r"Eloquent and before; write executable=\.\.\.")
