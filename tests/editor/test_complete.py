"""Completion, signature help and hover (server/editor/complete.py) over the generated stubs
and the sandbox's rospy/rclpy source, and the promise that nothing is run to give them."""

from __future__ import annotations

from server.editor.context import builtin_topics
from tests.editor.conftest import cursor_at_end


def labels(analyser, code: str, robot: str | None = None, extra=()) -> list[str]:
    line, column = cursor_at_end(code)
    answer = analyser.complete(code, line, column, robot, extra)
    return [c["label"] for c in answer["completions"]]


def hover(analyser, code: str, line: int, column: int, robot: str | None = None):
    return analyser.hover(code, line, column, robot)["text"]


def test_rospy_offers_its_api(analyser):
    offered = labels(analyser, "import rospy\nrospy.")
    for name in ("init_node", "Publisher", "Subscriber", "Rate", "is_shutdown", "loginfo"):
        assert name in offered
    assert not [name for name in offered if name.startswith("_")]


def test_a_twist_offers_its_fields_with_type_and_unit(analyser):
    code = "from geometry_msgs.msg import Twist\ncmd = Twist()\ncmd."
    line, column = cursor_at_end(code)
    completions = analyser.complete(code, line, column, None)["completions"]
    by_label = {c["label"]: c for c in completions}
    assert {"linear", "angular"} <= set(by_label)
    assert by_label["linear"]["type"] == "property"
    assert by_label["linear"]["detail"] == "linear: geometry_msgs/Vector3 [m/s]"
    vector = labels(analyser, "from geometry_msgs.msg import Twist\nTwist().linear.")
    assert {"x", "y", "z"} <= set(vector)


def test_a_callbacks_annotated_message_offers_ranges(analyser):
    code = "from sensor_msgs.msg import LaserScan\n\ndef on_scan(msg: LaserScan):\n    msg.ra"
    assert labels(analyser, code) == ["range_max", "range_min", "ranges"]


def test_obs_offers_the_robots_sensor_topics(analyser):
    code = "def step(obs):\n    obs."
    offered = labels(analyser, code, "crowbot")
    assert {"Distance", "Button", "Light", "Line", "time"} <= set(offered)
    assert "Control" not in offered  # a command topic: obs carries sensors
    assert "data" in labels(analyser, "def step(obs):\n    obs.Distance.", "crowbot")
    turtlebot = labels(analyser, code, "turtlebot")
    assert "plan" not in turtlebot
    extra = builtin_topics(("map_server", "localization", "waypoints", "planner"))
    assert {"plan", "pose", "odom"} <= set(labels(analyser, code, "turtlebot", extra))


def test_rclpy_node_and_ros2_messages(analyser):
    code = (
        "import rclpy\nfrom rclpy.node import Node\nfrom geometry_msgs.msg import Twist\n"
        "class Driver(Node):\n    def go(self):\n        self.create_"
    )
    offered = labels(analyser, code)
    assert {"create_publisher", "create_subscription", "create_timer"} <= set(offered)
    ros2_twist = "import rclpy\nfrom geometry_msgs.msg import Twist\nTwist().angular."
    assert {"x", "y", "z"} <= set(labels(analyser, ros2_twist))


def test_signature_help_knows_which_argument(analyser):
    code = "import rospy\nrospy.Publisher('Control', "
    line, column = cursor_at_end(code)
    signature = analyser.complete(code, line, column, None)["signature"]
    assert signature["label"].startswith("Publisher(name: str, data_class")
    assert signature["params"][:2] == ["name: str", "data_class: type[Message]"]
    assert signature["active"] == 1


def test_hover_shows_a_fields_type_and_unit(analyser):
    code = "from sensor_msgs.msg import LaserScan\nscan = LaserScan()\nscan.ranges\n"
    text = hover(analyser, code, 3, 7)
    assert text.startswith("ranges: float32[] [m")
    twist = "from geometry_msgs.msg import Twist\ncmd = Twist()\ncmd.angular.z = 1\n"
    assert hover(analyser, twist, 3, 6) == "angular: geometry_msgs/Vector3 [rad/s]"


def test_hover_on_an_obs_topic_says_its_type_and_description(analyser):
    code = "def step(obs):\n    return obs.Distance.data\n"
    text = hover(analyser, code, 2, 16, "crowbot")
    assert text == "std_msgs/Int32: ultrasonic range to the obstacle ahead [cm]; 0 when no echo"
    # On the `def step(obs` line the cursor is past the annotation the analysis adds.
    assert hover(analyser, code, 1, 10, "crowbot").startswith("obs: The latest message")


def test_positions_outside_the_text_do_not_fail(analyser):
    code = "import rospy\n"
    assert analyser.complete(code, 99, 99, None)["completions"] is not None
    assert hover(analyser, code, 99, 0) is None


def test_analysis_reads_modules_and_never_runs_them(analyser, stub_root, tmp_path):
    """A module that would leave a file behind when imported is completed from its text."""
    canary = tmp_path / "ran"
    module = stub_root / "ros1" / "canary_module.py"
    module.write_text(
        f"from pathlib import Path\nPath({str(canary)!r}).write_text('imported')\n"
        "def only_in_canary():\n    return 1\n"
    )
    try:
        assert "only_in_canary" in labels(analyser, "import canary_module\ncanary_module.only")
        code = "import canary_module\ncanary_module.only_in_canary()\n"
        assert hover(analyser, code, 2, 16).startswith("only_in_canary()")
    finally:
        module.unlink()
    student = f"from pathlib import Path\nPath({str(canary)!r}).write_text('x')\nPath."
    assert "cwd" in labels(analyser, student)
    assert not canary.exists()
