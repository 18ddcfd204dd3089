"""``_definitions.py`` is what ``_generate.py`` writes from rosbags' ros2_jazzy type store."""

from __future__ import annotations

from sandbox.msgs2 import _generate
from sandbox.msgs2._definitions import MESSAGES


def test_the_table_is_up_to_date() -> None:
    assert _generate.TARGET.read_text() == _generate.render(), (
        "run `python3 -m sandbox.msgs2._generate`"
    )


def test_the_issue_packages_are_there() -> None:
    packages = {name.split("/")[0] for name in MESSAGES}
    for package in ("builtin_interfaces", "std_msgs", "geometry_msgs", "sensor_msgs", "nav_msgs",
                    "tf2_msgs", "rosgraph_msgs", "visualization_msgs"):  # fmt: skip
        assert package in packages
    assert "std_msgs/msg/Header" in MESSAGES and "seq" not in MESSAGES["std_msgs/msg/Header"]


def test_the_sandbox_does_not_import_rosbags() -> None:
    import subprocess
    import sys

    code = (
        "import sys, sandbox.msgs2 as m;"
        "m.get_message_class('nav_msgs/msg/Odometry')().serialize();"
        "print(any(n.startswith('rosbags') for n in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
