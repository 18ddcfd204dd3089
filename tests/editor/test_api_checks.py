"""Our API checks (server/editor/api_checks.py): each kind of finding, with its sentence and
place, and none on the lab's own exercises and examples (a check that cries wolf on correct
code is worse than none)."""

from __future__ import annotations

from pathlib import Path

import pytest

from server.editor.api_checks import check
from server.editor.context import builtin_topics
from server.editor.syntax import TOO_DEEP, parse
from server.exercises.registry import exercise_ids, get_exercise

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def findings(code: str, robot: str | None = "crowbot", extra=()) -> list:
    tree = parse(code).tree
    assert tree is not None, "the test's code must parse"
    return check(code, tree, robot, extra)


def only(code: str, robot: str | None = "crowbot"):
    found = findings(code, robot)
    assert len(found) == 1, found
    return found[0]


def test_a_field_a_twist_does_not_have_is_named_with_the_fields_it_has():
    code = "from geometry_msgs.msg import Twist\ncmd = Twist()\ncmd.linear_x = 0.1\n"
    found = only(code)
    assert found.rule == "robodojo-field" and found.severity == "error"
    assert found.message.startswith("`Twist` has no field `linear_x`.")
    assert "Fields: linear, angular." in found.message
    # The attribute's name is underlined, not the whole expression.
    assert (found.line, found.column, found.end_line, found.end_column) == (3, 4, 3, 12)


def test_nested_fields_keyword_arguments_and_module_attributes_are_followed():
    code = (
        "import geometry_msgs.msg\nfrom geometry_msgs.msg import Twist, Vector3\n"
        "cmd = Twist(linear=Vector3(x=1.0), angulr=Vector3())\n"
        "cmd.linear.w = 2\n"
        "other = geometry_msgs.msg.Twist()\nother.angular.zz\n"
    )
    found = findings(code)
    assert [(f.line, f.message.split(".")[0]) for f in found] == [
        (3, "`Twist` has no field `angulr`"),
        (4, "`Vector3` has no field `w`"),
        (6, "`Vector3` has no field `zz`"),
    ]


def test_a_subscriber_callback_knows_its_message_rospy_and_rclpy():
    rospy = (
        "import rospy\nfrom sensor_msgs.msg import LaserScan\n\n"
        "def on_scan(msg):\n    print(min(msg.ranges), msg.rangez)\n\n"
        'rospy.Subscriber("scan", LaserScan, on_scan)\n'
    )
    assert (
        "`LaserScan` has no field `rangez`. Did you mean `ranges`?"
        in only(rospy, "turtlebot3").message
    )
    rclpy = (
        "import rclpy\nfrom rclpy.node import Node\nfrom sensor_msgs.msg import LaserScan\n"
        "class Stop(Node):\n    def __init__(self):\n        super().__init__('stop')\n"
        "        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)\n"
        "    def on_scan(self, scan):\n        return scan.range_mini\n"
    )
    assert only(rclpy, "turtlebot3").message.startswith("`LaserScan` has no field `range_mini`")


def test_a_name_given_two_types_is_not_checked():
    code = (
        "from std_msgs.msg import Int32, String\n"
        "value = Int32()\nvalue = String()\nvalue.anything\n"
    )
    assert findings(code) == []


def test_a_misspelt_message_import_is_named_with_close_ones():
    found = only("from geometry_msgs.msg import Twsit\n")
    assert found.rule == "robodojo-import"
    assert found.message == "`geometry_msgs.msg` has no message `Twsit`. Did you mean `Twist`?"


def test_a_topic_name_close_to_the_robots_is_a_warning_with_the_list():
    code = (
        'import rospy\nfrom std_msgs.msg import Int32\nrospy.Subscriber("Distanse", Int32, print)\n'
    )
    found = only(code)
    assert (found.rule, found.severity) == ("robodojo-topic", "warning")
    assert "Robot crowbot has no topic `Distanse`. Did you mean `Distance`?" in found.message
    assert "Its topics: Distance (std_msgs/Int32), Button (std_msgs/Bool)" in found.message


def test_another_robots_topic_is_named_as_such_and_own_topics_are_fine():
    code = (
        "import rospy\nfrom geometry_msgs.msg import Twist\n"
        'rospy.Publisher("cmd_vel", Twist, queue_size=1)\n'
        'rospy.Publisher("my_debug_topic", Twist, queue_size=1)\n'
    )
    found = only(code)
    assert found.line == 3 and "`cmd_vel` is a topic of" in found.message


def test_a_topic_with_the_wrong_type_is_an_error():
    code = (
        "import rospy\nfrom std_msgs.msg import Float32\n"
        'rospy.Subscriber("Distance", Float32, print)\n'
    )
    found = only(code)
    assert found.rule == "robodojo-topic-type"
    assert "carries std_msgs/Int32, not std_msgs/Float32; use Int32" in found.message


def test_ros2_twist_topics_take_twist_stamped():
    code = (
        "import rclpy\nfrom rclpy.node import Node\nfrom geometry_msgs.msg import TwistStamped\n"
        "node = Node('n')\nnode.create_publisher(TwistStamped, 'cmd_vel', 10)\n"
    )
    assert findings(code, "turtlebot3") == []


def test_obs_names_must_be_sensor_topics_in_subscribe():
    code = (
        'SUBSCRIBE = ["Distance"]\n\n'
        "def step(obs):\n"
        "    near = obs.Distanc\n"
        "    light = obs.Light\n"
        '    return obs["Distance"].dat, obs.time\n'
    )
    found = findings(code)
    assert [(f.line, f.rule) for f in found] == [
        (4, "robodojo-topic"),
        (5, "robodojo-topic"),
        (6, "robodojo-field"),
    ]
    assert "obs has no `Distanc`: robot crowbot's sensor topics are Distance, Button" in (
        found[0].message
    )
    assert "not in SUBSCRIBE. Add it there, e.g. SUBSCRIBE = ['Distance', 'Light']" in (
        found[1].message
    )
    assert found[2].message.startswith("`Int32` has no field `dat`")


def test_subscribe_and_rate_are_checked():
    code = 'RATE_HZ = 0\nSUBSCRIBE = ["Distance", "Lite"]\n\ndef step(obs):\n    return None\n'
    found = findings(code)
    assert [f.rule for f in found] == ["robodojo-step", "robodojo-topic"]
    assert "0 < RATE_HZ <= 1000; it is 0." in found[0].message
    assert "SUBSCRIBE names `Lite`" in found[1].message and "Did you mean `Line`?" in (
        found[1].message
    )


@pytest.mark.parametrize(
    ("signature", "says"),
    [
        ("def step():", "takes none"),
        ("def step(obs, extra):", "takes 2 (obs, extra)"),
        ("async def step(obs):", "not async"),
    ],
)
def test_a_step_function_with_the_wrong_signature(signature, says):
    found = only(f"{signature}\n    return None\n")
    assert found.rule == "robodojo-step" and says in found.message
    assert found.line == 1


def test_accepted_step_signatures_pass():
    for signature in ("def step(obs):", "def step(obs, gain=2):", "def step(*args):"):
        assert findings(f"{signature}\n    return None\n") == [], signature


def test_without_a_robot_topics_are_not_judged_but_fields_are():
    code = "def step(obs):\n    return obs.Anything\n"
    assert findings(code, None) == []
    code = "from std_msgs.msg import Int32\nInt32().dat\n"
    assert only(code, None).rule == "robodojo-field"


def test_exercise_built_in_nodes_topics_are_obs_topics():
    code = 'SUBSCRIBE = ["odom", "plan"]\n\ndef step(obs):\n    return obs.plan.poses\n'
    extra = builtin_topics(("map_server", "localization", "waypoints", "planner"))
    assert findings(code, "turtlebot", extra) == []
    assert findings(code, "turtlebot")  # without the planner, plan is no topic


def test_columns_count_characters_not_utf8_bytes():
    code = 'from std_msgs.msg import Int32\nétiquette = "é"; m = Int32(); m.dta\n'
    found = only(code)
    assert (found.column, found.end_column) == (32, 35)  # in bytes: 34, 37


def test_no_finding_on_the_labs_exercises_and_examples():
    """Starter and reference code of every exercise, and every example: all correct code."""
    for exercise_id in exercise_ids():
        exercise = get_exercise(exercise_id)
        extra = builtin_topics(exercise.builtin_nodes)
        for _, path in (*exercise.starter, *exercise.reference):
            code = exercise.code_path(path).read_text()
            assert findings(code, exercise.robot, extra) == [], (exercise_id, path)
    for path in sorted(EXAMPLES.glob("*/*.py")):
        robot = path.stem.split("_obstacle")[0]
        assert findings(path.read_text(), robot) == [], path


@pytest.mark.parametrize(
    "code",
    [
        "x = " + "(" * 5000 + ")" * 5000 + "\n",
        "x = " + "1+" * 100_000 + "1\n",
        "x = " + "-" * 100_000 + "1\n",
        "".join("    " * i + "if True:\n" for i in range(120)) + "    " * 120 + "pass\n",
    ],
    ids=["brackets", "long-sum", "unary-chain", "indentation"],
)
def test_code_python_cannot_compile_is_said_so(code):
    parsed = parse(code)
    assert parsed.tree is None and parsed.too_deep
    assert [p.message for p in parsed.problems] == [TOO_DEEP]
