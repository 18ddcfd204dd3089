"""A run's ROS version, decided from its nodes (server/runs/spec.py): rclpy makes a node ROS 2,
rospy and the step API ROS 1, a file importing neither goes with the others; mixing is refused
with the sentence of the contract; an explicit value overrides."""

from __future__ import annotations

import pytest

from sandbox.protocol import Api
from server.runs.spec import NodeSpec, RunSpec, RunSpecError, node_ros_version

RCLPY = "import rclpy\nfrom rclpy.node import Node\nrclpy.init()\n"
RCLPY_FROM = "from rclpy.node import Node\n"
RCLPY_INSIDE = "def main():\n    import rclpy.executors\n    rclpy.init()\n"
ROSPY = "import rospy\nrospy.init_node('a')\n"
STEP = "def step(obs):\n    return 0.1, 0.0\n"
PLAIN = "print('hello')\n"


def node(name: str, code: str, **kw) -> NodeSpec:
    return NodeSpec(name=name, code=code, filename=f"{name}.py", **kw)


def spec(*nodes: NodeSpec, **kw) -> RunSpec:
    return RunSpec(robot="crowbot", world="wall_approach", nodes=nodes, **kw)


@pytest.mark.parametrize(
    ("code", "expected"),
    [
        (RCLPY, 2),
        (RCLPY_FROM, 2),
        (RCLPY_INSIDE, 2),
        (ROSPY, 1),
        ("from rospy import Publisher\n", 1),
        (STEP, 1),
        (PLAIN, None),
        ("import rclpyx\nimport my_rospy\n", None),  # names that only start alike
        ("def broken(:\n", None),  # its own error comes later, from the sandbox
    ],
)
def test_a_node_file_says_its_version_by_its_imports(code, expected):
    assert node_ros_version(node("a", code))[0] == expected


def test_a_file_importing_both_is_ros2_first():
    code = "try:\n    import rclpy\nexcept ImportError:\n    import rospy\n"
    assert node_ros_version(node("a", code)) == (2, "uses rclpy")


def test_the_step_api_asked_for_is_ros1_whatever_the_file_imports():
    assert node_ros_version(node("a", RCLPY, api=Api.STEP))[0] == 1


def test_the_run_follows_its_nodes():
    assert spec(node("a", ROSPY)).ros_version == 1
    assert spec(node("a", RCLPY), node("b", PLAIN)).ros_version == 2
    assert spec(node("a", PLAIN), node("b", RCLPY_FROM)).ros_version == 2
    assert spec(node("a", PLAIN)).ros_version == 1  # neither: ROS 1, as every run was


def test_mixing_is_refused_with_a_sentence_naming_one_node_of_each():
    mixed = spec(node("talker", RCLPY), node("driver", ROSPY))
    with pytest.raises(RunSpecError) as caught:
        mixed.validate()
    assert str(caught.value) == (
        "node `talker` uses rclpy (ROS 2) and node `driver` uses rospy (ROS 1); "
        "a run is one or the other"
    )
    with pytest.raises(RunSpecError, match=r"node `b` uses the step API \(ROS 1\)"):
        spec(node("a", RCLPY), node("b", STEP)).validate()


def test_a_node_may_say_its_version_explicitly():
    # A launch file's node (a Python launch file's nodes are ROS 2 whatever they import).
    assert spec(node("a", PLAIN, ros_version=2)).ros_version == 2
    with pytest.raises(RunSpecError, match=r"node `a` is a ROS 2 node \(ROS 2\) and node `b`"):
        spec(node("a", PLAIN, ros_version=2), node("b", ROSPY)).validate()
    with pytest.raises(RunSpecError, match="ros_version must be 1 or 2, got 3"):
        spec(node("a", PLAIN, ros_version=3)).validate()


def test_an_explicit_run_version_overrides_and_is_checked_against_the_nodes():
    assert spec(node("a", PLAIN), explicit_ros_version=2).ros_version == 2
    assert spec(node("a", RCLPY), explicit_ros_version=2).ros_version == 2
    with pytest.raises(RunSpecError) as caught:
        spec(node("a", RCLPY), explicit_ros_version=1).validate()
    assert str(caught.value) == (
        "node `a` uses rclpy (ROS 2) but this run is ROS 1; a run is one or the other"
    )


def test_a_ros2_only_built_in_in_a_ros1_run_is_refused_with_a_sentence():
    spec(node("a", RCLPY), builtin_nodes=("map_server", "nav2")).validate()  # ROS 2: fine
    spec(node("a", ROSPY), builtin_nodes=("map_server",)).validate()
    with pytest.raises(RunSpecError) as caught:
        spec(node("a", ROSPY), builtin_nodes=("map_server", "nav2")).validate()
    assert str(caught.value) == (
        "built-in node 'nav2' serves ROS 2 nodes (rclpy) only, and this run's nodes are ROS 1; "
        "write them with rclpy or leave the built-in out"
    )
