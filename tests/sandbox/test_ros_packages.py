"""Inside a real sandboxed node: every message package imports, and a ROS 1 module RoboDojo
lacks fails with its sentence (sandbox/ros_imports.py), pointing at the student's line."""

from __future__ import annotations

from sandbox.protocol import Outcome
from sandbox.ros_imports import sentence_for
from tests.sandbox.test_attacks import finish


def test_message_packages_and_roslib_work_in_a_node(launcher) -> None:
    code = (
        "import roslib; roslib.load_manifest('my_course')\n"
        "import roslib.message\n"
        "from std_srvs.srv import SetBool, SetBoolResponse, Trigger\n"
        "from visualization_msgs.msg import Marker, MarkerArray\n"
        "from tf2_msgs.msg import TFMessage\n"
        "from nav_msgs.srv import GetMap\n"
        "from actionlib_msgs.msg import GoalStatus\n"
        "import sensor_msgs.msg\n"
        "scan = sensor_msgs.msg.LaserScan(ranges=[1.0, 2.0])\n"
        "assert sensor_msgs.msg.LaserScan.deserialize(scan.serialize()) == scan\n"
        "assert SetBool._md5sum == '09fb03525b03e7ea1fd3992bafd87e16'\n"
        "assert roslib.message.get_message_class('std_msgs/String')._type == 'std_msgs/String'\n"
        "assert Marker(type=Marker.SPHERE).serialize()\n"
    )
    exited = finish(launcher, code, "imports")
    assert exited.outcome is Outcome.FINISHED, exited


def test_a_missing_ros_module_fails_with_its_sentence(launcher) -> None:
    exited = finish(launcher, "import rospy\n\nfrom cv_bridge import CvBridge\n", "bridge")
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "ModuleNotFoundError"
    assert exited.error.message == sentence_for("cv_bridge")
    assert exited.error.line == 3


def test_a_misspelt_message_type_fails_with_the_close_match(launcher) -> None:
    exited = finish(launcher, "from std_msgs.msg import Float\n", "typo")
    assert exited.outcome is Outcome.ERROR
    assert exited.error.type == "ImportError"
    assert exited.error.message.startswith(
        "std_msgs.msg has no type 'Float'. Did you mean Float64 or Float32?"
    )
