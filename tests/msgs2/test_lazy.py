"""Student-facing ROS 2 package modules (sandbox/ros_compat2/<pkg>/msg|srv|action)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from sandbox.msgs2 import get_action_class, get_message_class, get_service_class
from sandbox.msgs2._catalog import KINDS, packages
from sandbox.msgs2._lazy import module_names

COMPAT = Path(__file__).resolve().parents[2] / "sandbox" / "ros_compat2"


def _run(code: str) -> subprocess.CompletedProcess[str]:
    """``code`` in a fresh interpreter with ros_compat2 on sys.path, as a ROS 2 node has it."""
    root = str(COMPAT.parents[1])
    prelude = f"import sys; sys.path[:0] = [{str(COMPAT)!r}, {root!r}]\n"
    return subprocess.run(
        [sys.executable, "-c", prelude + code], capture_output=True, text=True, timeout=60
    )


def test_every_package_and_kind_has_its_module() -> None:
    for package in packages():
        for kind in KINDS:
            exists = (COMPAT / package / kind / "__init__.py").exists()
            # robodojo_msgs' messages are the lab's own service wire, not for students
            wanted = bool(module_names(package, kind)) and (package, kind) != (
                "robodojo_msgs",
                "msg",
            )
            assert exists == wanted, f"{package}.{kind}"


def test_student_imports_give_the_registry_classes() -> None:
    result = _run(
        "from std_msgs.msg import String\n"
        "from geometry_msgs.msg import Twist, TwistStamped\n"
        "from example_interfaces.srv import AddTwoInts\n"
        "from example_interfaces.action import Fibonacci\n"
        "from nav2_msgs.action import NavigateToPose\n"
        "from rcl_interfaces.msg import SetParametersResult, ParameterDescriptor\n"
        "import std_srvs.srv\n"
        "from sandbox.msgs2 import get_message_class, get_service_class, get_action_class\n"
        "assert String is get_message_class('std_msgs/msg/String')\n"
        "assert AddTwoInts is get_service_class('example_interfaces/srv/AddTwoInts')\n"
        "assert Fibonacci is get_action_class('example_interfaces/action/Fibonacci')\n"
        "assert std_srvs.srv.SetBool.Request(data=True).data is True\n"
        "print(repr(String(data='hi')), std_srvs.srv.__all__)\n"
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "std_msgs.msg.String(data='hi') ['Empty', 'SetBool', 'Trigger']"


@pytest.mark.parametrize(
    ("statement", "sentence"),
    [
        ("from std_msgs.msg import Strin", "Did you mean String?"),
        ("from std_msgs.msg import Pose", "geometry_msgs.msg.Pose"),
        ("from example_interfaces.msg import AddTwoInts", "import it from example_interfaces.srv"),
        ("from std_srvs.srv import SetBool_Request", "SetBool.Request"),
    ],
)
def test_a_missing_name_is_an_import_error_with_a_sentence(statement: str, sentence: str) -> None:
    result = _run(statement)
    assert result.returncode != 0
    assert "ImportError" in result.stderr and sentence in result.stderr


def test_nothing_is_built_before_it_is_used() -> None:
    result = _run(
        "import std_msgs.msg, sandbox.msgs2._core as core\n"
        "before = len(core._REGISTRY)\n"
        "std_msgs.msg.Int32\n"
        "print(before, sorted(core._REGISTRY))\n"
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "0 ['std_msgs/msg/Int32']"


def test_module_names() -> None:
    assert "Fibonacci" in module_names("example_interfaces", "action")
    assert module_names("std_srvs", "msg") == ()
    assert get_service_class("std_srvs/srv/Trigger").Response().success is False
    assert get_action_class("nav2_msgs/action/NavigateToPose").Goal().behavior_tree == ""
    assert get_message_class("rosgraph_msgs/msg/Clock")().clock.sec == 0
    with pytest.raises(ValueError, match="kind"):
        module_names("std_msgs", "msgs")
