"""Importing a ROS 1 module RoboDojo lacks fails with a sentence; other imports are untouched."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

from sandbox import ros_imports
from sandbox.msgs._catalog import packages
from sandbox.ros_imports import MISSING_MODULES, MissingRosModuleFinder, sentence_for

ROS_COMPAT = Path(ros_imports.__file__).parent / "ros_compat"


@pytest.fixture
def finder(monkeypatch: pytest.MonkeyPatch):
    """The finder installed on a copy of sys.meta_path, with ros_compat on sys.path."""
    monkeypatch.setattr(
        sys, "meta_path", [m for m in sys.meta_path if m is not MissingRosModuleFinder]
    )
    monkeypatch.syspath_prepend(str(ROS_COMPAT))
    ros_imports.install()
    before = set(sys.modules)
    yield
    for name in set(sys.modules) - before:
        if name.split(".")[0] in set(packages()):
            del sys.modules[name]


def test_cv_bridge_says_how_to_decode_an_image() -> None:
    assert sentence_for("cv_bridge") == (
        "cv_bridge is not available in RoboDojo: sensor_msgs/Image data is a bytes field; decode "
        "it with numpy: np.frombuffer(msg.data, np.uint8).reshape(msg.height, msg.width, -1)"
    )


@pytest.mark.parametrize("name", sorted(MISSING_MODULES))
def test_every_known_module_gets_its_own_sentence(name: str) -> None:
    sentence = sentence_for(name)
    assert sentence == f"{name} is not available in RoboDojo: {MISSING_MODULES[name]}"
    assert sentence_for(f"{name}.msg") == sentence  # submodules answer for their package


@pytest.mark.parametrize("name", ["actionlib", "move_base_msgs", "rospy_tutorials", "turtlesim",
    "cv_bridge", "message_filters", "gazebo_msgs", "kobuki_msgs", "dynamic_reconfigure",
    "tf_conversions", "laser_geometry", "rosbag", "roslaunch", "rosnode", "rostopic",
    "image_geometry"])  # fmt: skip
def test_the_modules_course_scripts_import_are_known(name: str) -> None:
    assert name in MISSING_MODULES


def test_any_other_message_package_lists_the_ones_we_have() -> None:
    assert sentence_for("diagnostic_msgs.msg") == (
        "diagnostic_msgs is not available in RoboDojo: RoboDojo provides the message packages "
        "actionlib_msgs, geometry_msgs, nav_msgs, sensor_msgs, std_msgs, std_srvs, tf2_msgs, "
        "visualization_msgs; for data of your own, std_msgs (String, Float64, "
        "Float64MultiArray...) usually fits"
    )
    assert sentence_for("my_robot_srvs").startswith("my_robot_srvs is not available")


def test_a_missing_module_of_a_package_we_have() -> None:
    assert sentence_for("std_srvs.msg") == (
        "std_srvs.msg is not available in RoboDojo: std_srvs has std_srvs.srv only"
    )
    assert sentence_for("sensor_msgs.msg.LaserScan") == (
        "sensor_msgs.msg.LaserScan is not a module: write `from sensor_msgs.msg import LaserScan`"
    )
    assert sentence_for("roslib.packages") == (
        "roslib.packages is not available in RoboDojo: roslib has load_manifest (which does "
        "nothing here) and roslib.message (get_message_class, get_service_class) only"
    )
    assert sentence_for("roslib") is None  # provided
    assert sentence_for("sensor_msgs.point_cloud2").startswith(
        "sensor_msgs.point_cloud2 is not available in RoboDojo: read sensor_msgs/PointCloud2"
    )


@pytest.mark.parametrize(
    "name", ["numpy", "json", "my_helpers", "controller", "std_msgs", "rospy", "tf", "tf2_ros",
             "msgs", "tf2_msgs", "robodojo_msgsx", "pkg.sub"],
)  # fmt: skip
def test_other_names_are_not_answered(name: str) -> None:
    assert sentence_for(name) is None
    assert MissingRosModuleFinder.find_spec(name, None) is None


@pytest.mark.usefixtures("finder")
def test_import_raises_module_not_found_with_the_sentence() -> None:
    with pytest.raises(ModuleNotFoundError) as caught:
        import cv_bridge  # noqa: F401
    assert caught.value.name == "cv_bridge"
    assert str(caught.value) == sentence_for("cv_bridge")
    with pytest.raises(
        ModuleNotFoundError,
        match=r"^actionlib is not available in RoboDojo: there are no action servers",
    ):
        from actionlib import SimpleActionClient  # noqa: F401
    with pytest.raises(ModuleNotFoundError, match=r"^std_srvs\.msg is not available"):
        import std_srvs.msg  # noqa: F401


@pytest.mark.usefixtures("finder")
def test_finder_is_last_and_installed_once() -> None:
    ros_imports.install()
    assert sys.meta_path[-1] is MissingRosModuleFinder
    assert sys.meta_path.count(MissingRosModuleFinder) == 1


@pytest.mark.usefixtures("finder")
def test_a_real_module_of_that_name_wins(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # The finder answers only after every other finder failed: a student's own cv_bridge.py
    # (or an installed package) is imported as usual.
    (tmp_path / "cv_bridge.py").write_text("CvBridge = 'mine'\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "cv_bridge", raising=False)
    assert importlib.import_module("cv_bridge").CvBridge == "mine"
    del sys.modules["cv_bridge"]


@pytest.mark.usefixtures("finder")
def test_a_missing_type_still_gets_the_message_modules_sentence() -> None:
    # `from std_msgs.msg import Int33` makes Python try the module std_msgs.msg.Int33 first; the
    # finder's answer for it must not replace the sentence naming Int32.
    with pytest.raises(
        ImportError, match=r"^std_msgs\.msg has no type 'Int33'\. Did you mean Int32"
    ):
        from std_msgs.msg import Int33  # noqa: F401
