"""ROS 2 Python launch files read into plans by a real sandboxed launch job: arguments,
parameters from dicts and YAML files, remappings, namespaces, groups, conditions, includes,
and executables found as colcon installs them."""

from __future__ import annotations

import pytest

from tests.launch2.conftest import plan_of, workspace

TWO_NODES = """\
    import os

    from ament_index_python.packages import get_package_share_directory
    from launch import LaunchDescription
    from launch.actions import DeclareLaunchArgument, GroupAction
    from launch.conditions import IfCondition
    from launch.substitutions import LaunchConfiguration
    from launch_ros.actions import Node, PushRosNamespace


    def generate_launch_description():
        config = os.path.join(get_package_share_directory("my_pkg"), "config", "params.yaml")
        return LaunchDescription([
            DeclareLaunchArgument("speed", default_value="0.2", description="[m/s]"),
            DeclareLaunchArgument("with_listener", default_value="true"),
            Node(
                package="my_pkg",
                executable="talker",
                parameters=[config, {"speed": LaunchConfiguration("speed"), "mode": "fast"}],
                remappings=[("chatter", "chat")],
                output="screen",
            ),
            GroupAction([
                PushRosNamespace("robot1"),
                Node(
                    package="my_pkg",
                    executable="listener",
                    name="listener",
                    parameters=[config],
                    arguments=["--verbose"],
                    condition=IfCondition(LaunchConfiguration("with_listener")),
                ),
            ]),
        ])
    """


def test_two_nodes_with_parameters_remaps_and_a_namespace(launcher):
    plan = plan_of(launcher, workspace(two=TWO_NODES), "two", speed="0.5")
    assert plan.ros_version == 2
    assert {node.ros_version for node in plan.nodes} == {2}
    talker, listener = plan.nodes
    assert (talker.name, talker.filename, talker.namespace) == ("talker", "talker.py", "/")
    # The YAML's /** rule, then its talker rule (the code's node name), nested names dotted;
    # the dict's text argument read as YAML (0.5 a float), its plain string kept a string.
    assert talker.params == {
        "use_sim_time": False,
        "rate": 5.0,
        "pid.kp": 1.5,
        "pid.gains": [1, 2, 3],
        "speed": 0.5,
        "mode": "fast",
    }
    assert talker.remaps == (("chatter", "chat"),)
    assert talker.args == ()
    # setup.py's console_scripts names talker's main(), which the file never calls itself.
    assert talker.code.endswith(
        "if __name__ == '__main__':  # setup.py's console_scripts entry point\n    main()\n"
    )
    assert (listener.name, listener.namespace) == ("listener", "/robot1")
    assert listener.params == {"use_sim_time": False, "rate": 1.0, "topic": "chatter"}
    assert listener.args == ("--verbose", "--ros-args", "-r", "__node:=listener")
    assert "console_scripts" not in listener.code  # it has its own __main__ guard


def test_defaults_and_a_condition_that_is_false(launcher):
    plan = plan_of(launcher, workspace(two=TWO_NODES), "two", with_listener="false")
    assert [node.name for node in plan.nodes] == ["talker"]
    assert plan.nodes[0].params["speed"] == 0.2


PARENT = """\
    from launch import LaunchDescription
    from launch.actions import DeclareLaunchArgument, GroupAction, IncludeLaunchDescription
    from launch.launch_description_sources import PythonLaunchDescriptionSource
    from launch.substitutions import LaunchConfiguration, PathJoinSubstitution, ThisLaunchFileDir
    from launch_ros.actions import Node, SetParameter
    from launch_ros.substitutions import FindPackageShare


    def generate_launch_description():
        child = PathJoinSubstitution([FindPackageShare("my_pkg"), "launch", "child.launch.py"])
        return LaunchDescription([
            DeclareLaunchArgument("first", default_value="r1"),
            GroupAction([
                SetParameter("use_sim_time", True),
                IncludeLaunchDescription(
                    PythonLaunchDescriptionSource(child),
                    launch_arguments={"robot": LaunchConfiguration("first")}.items(),
                ),
            ]),
            IncludeLaunchDescription(
                PythonLaunchDescriptionSource([ThisLaunchFileDir(), "/child.launch.py"]),
                launch_arguments=[("robot", "r2"), ("gain", "3")],
            ),
            # An include does not scope its arguments: `robot` is still set here (ros2 launch).
            Node(package="my_pkg", executable="talker", name=LaunchConfiguration("robot")),
        ])
    """

CHILD = """\
    from launch import LaunchDescription
    from launch.actions import DeclareLaunchArgument, GroupAction
    from launch.substitutions import LaunchConfiguration
    from launch_ros.actions import Node, PushRosNamespace


    def generate_launch_description():
        return LaunchDescription([
            DeclareLaunchArgument("robot"),
            DeclareLaunchArgument("gain", default_value="1"),
            GroupAction([
                PushRosNamespace(LaunchConfiguration("robot")),
                Node(
                    package="my_pkg",
                    executable="listener",
                    name="listener",
                    parameters=[{"gain": LaunchConfiguration("gain")}],
                ),
            ]),
        ])
    """


def test_includes_pass_arguments_and_scopes_hold(launcher):
    plan = plan_of(launcher, workspace(parent=PARENT, child=CHILD), "parent")
    first, second, last = plan.nodes
    assert (first.name, first.namespace) == ("r1_listener", "/r1")
    assert first.params == {"use_sim_time": True, "gain": 1}
    # SetParameter stayed inside its group; the second include gave gain:=3.
    assert (second.name, second.namespace) == ("r2_listener", "/r2")
    assert second.params == {"gain": 3}
    assert (last.name, last.namespace, last.params) == ("r2", "/", {})
    assert last.args == ("--ros-args", "-r", "__node:=r2")


def test_a_flat_workspace_is_a_package_of_any_name(launcher):
    files = {
        "wall_follower.py": "import rclpy\n",
        "config/gains.yaml": "wall_follower:\n  ros__parameters:\n    kp: 2\n",
        "follow.launch.py": (
            "from launch import LaunchDescription\n"
            "from launch_ros.actions import Node\n"
            "def generate_launch_description():\n"
            "    return LaunchDescription([Node(package='course', executable='wall_follower',\n"
            "        name='wall_follower', parameters=['config/gains.yaml'],\n"
            "        ros_arguments=['--log-level', 'debug'])])\n"
        ),
    }
    from server.runs.launch_py import read_launch

    (node,) = read_launch("follow.launch.py", files, {}, launcher).nodes
    assert (node.name, node.filename) == ("wall_follower", "wall_follower.py")
    assert node.params == {"kp": 2}
    assert node.args == ("--ros-args", "--log-level", "debug", "--ros-args", "-r",
                         "__node:=wall_follower")  # fmt: skip


@pytest.mark.parametrize(
    ("namespaces", "labels"),
    [(("a", "b"), ["a_listener", "b_listener"]), (("/", "/"), ["listener", "listener_2"])],
)
def test_nodes_of_one_name_get_labels_of_their_own(launcher, namespaces, labels):
    nodes = ",".join(
        f"Node(package='my_pkg', executable='listener', namespace='{ns}')" for ns in namespaces
    )
    text = (
        "from launch import LaunchDescription\nfrom launch_ros.actions import Node\n"
        f"def generate_launch_description():\n    return LaunchDescription([{nodes}])\n"
    )
    plan = plan_of(launcher, workspace(many=text), "many")
    assert [node.name for node in plan.nodes] == labels
