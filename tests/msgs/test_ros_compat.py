"""The message packages as student code imports them (``from std_msgs.msg import Int32``), and
``roslib``. The node host puts sandbox/ros_compat on sys.path; these tests do the same."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

import sandbox
from sandbox.msgs import Duration, Time, geometry_msgs, std_msgs, std_srvs
from sandbox.msgs._catalog import kinds, names, packages
from sandbox.msgs._lazy import MissingTypeError

ROS_COMPAT = Path(sandbox.__file__).parent / "ros_compat"
OWNED_ELSEWHERE = {"rospy", "roslib", "tf", "tf2_ros", "tf2_geometry_msgs"}


@pytest.fixture(autouse=True)
def ros_path(monkeypatch: pytest.MonkeyPatch):
    """ros_compat on sys.path; the modules imported from it are forgotten afterwards."""
    monkeypatch.syspath_prepend(str(ROS_COMPAT))
    before = set(sys.modules)
    yield
    for name in set(sys.modules) - before:
        if name.split(".")[0] in set(packages()) | {"roslib"}:
            del sys.modules[name]


def test_every_package_has_its_modules_and_nothing_else() -> None:
    directories = {p.name for p in ROS_COMPAT.iterdir() if (p / "__init__.py").exists()}
    assert directories - OWNED_ELSEWHERE == set(packages())
    for package in packages():
        present = {p.name for p in (ROS_COMPAT / package).iterdir() if p.is_dir()} - {"__pycache__"}
        assert present == set(kinds(package)), package


def test_the_imports_course_scripts_write() -> None:
    from geometry_msgs.msg import Twist
    from std_srvs.srv import SetBool, SetBoolResponse
    from tf2_msgs.msg import TFMessage
    from visualization_msgs.msg import Marker

    assert Twist is geometry_msgs.Twist  # one class, whichever way it is imported
    assert SetBool is std_srvs.SetBool and SetBool._response_class is SetBoolResponse
    assert TFMessage._md5sum == "94810edda583a504dfda3829e70d7eec"
    assert Marker.SPHERE == 2

    import sensor_msgs.msg

    assert sensor_msgs.msg.LaserScan._type == "sensor_msgs/LaserScan"


@pytest.mark.parametrize("package", packages())
def test_each_module_holds_exactly_its_kind(package: str) -> None:
    for kind in kinds(package):
        module = importlib.import_module(f"{package}.{kind}")
        assert module.__all__ == list(names(package, kind))
        assert set(module.__all__) <= set(dir(module))
        namespace: dict[str, object] = {}
        exec(f"from {package}.{kind} import *", namespace)
        assert {n for n in namespace if not n.startswith("__")} == set(module.__all__)


def test_star_import_of_std_msgs_gives_the_same_classes() -> None:
    namespace: dict[str, object] = {}
    exec("from std_msgs.msg import *", namespace)
    assert namespace["Header"] is std_msgs.Header and namespace["String"] is std_msgs.String


def test_a_misspelt_name_in_from_import_says_what_exists() -> None:
    with pytest.raises(ImportError) as caught:
        from std_msgs.msg import Int33  # noqa: F401
    assert str(caught.value) == (
        "std_msgs.msg has no type 'Int33'. Did you mean Int32, UInt32 or Int8? It holds: "
        + ", ".join(names("std_msgs", "msg"))
        + " (the ROS 1 noetic types of std_msgs)."
    )


def test_a_type_from_another_package_is_pointed_at() -> None:
    with pytest.raises(
        ImportError,
        match=r"^std_msgs\.msg has no type 'Twist'\. Did you mean geometry_msgs\.msg\.Twist\?",
    ):
        from std_msgs.msg import Twist  # noqa: F401
    with pytest.raises(
        ImportError, match=r"^nav_msgs/GetMap is a service: import it from nav_msgs\.srv$"
    ):
        from nav_msgs.msg import GetMap  # noqa: F401
    with pytest.raises(ImportError, match=r"^std_srvs\.srv has no type 'SetBoolRequests'\. Did "):
        from std_srvs.srv import SetBoolRequests  # noqa: F401


def test_a_misspelt_attribute_is_an_attribute_error_with_the_sentence() -> None:
    import sensor_msgs.msg

    with pytest.raises(MissingTypeError) as caught:
        sensor_msgs.msg.Laserscan  # noqa: B018
    assert isinstance(caught.value, AttributeError)
    assert str(caught.value).startswith(
        "sensor_msgs.msg has no type 'Laserscan'. Did you mean LaserScan, MultiEchoLaserScan"
    )


def test_roslib_load_manifest_is_a_no_op() -> None:
    import roslib

    assert roslib.load_manifest("beginner_tutorials") is None
    assert roslib.load_manifest("any_package_at_all") is None


def test_roslib_message_finds_classes_as_genpy_does() -> None:
    import roslib.message

    get = roslib.message.get_message_class
    assert get("std_msgs/String") is std_msgs.String
    assert get("Header") is std_msgs.Header  # genpy's one bare name
    assert (get("time"), get("duration")) == (Time, Duration)
    assert get("std_msgs/Strin") is None  # roslib answers None, scripts test for it
    assert get("no_such_msgs/Thing") is None
    with pytest.raises(ValueError, match="message type is missing package name: String"):
        get("String")
    service = roslib.message.get_service_class("std_srvs/SetBool")
    assert service is std_srvs.SetBool
    assert roslib.message.get_service_class("std_srvs/SetBul") is None
    assert roslib.message.get_service_class("std_msgs/String") is None


def test_roslib_message_is_there_after_import_roslib() -> None:
    import roslib

    assert roslib.message.get_message_class("std_msgs/Bool") is std_msgs.Bool
