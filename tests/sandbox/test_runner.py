"""The child's start-up (sandbox/runner.py): what a warm-pool process does before Ready so that
a node taken from the pool reaches its first Yield at once (issue 18: warm start ~1 ms).

Each test runs the runner's steps in a fresh interpreter: they change sys.modules and the
message registries for the life of a process, as they do in a pool process."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _in_fresh_python(code: str) -> dict:
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def test_rclpy_imported_ahead_waits_outside_sys_modules_until_a_ros2_node():
    """A ROS 1 node finds no ROS 2 module to forget (deleting ~200 modules cost 1-2.5 ms of its
    start); a ROS 2 node gets the very modules imported ahead, not a second import."""
    found = _in_fresh_python(
        """
import json, sys
from sandbox import runner
from sandbox.host import install_ros_compat
runner._host_imports()
runner._warm_rclpy()
after_warm = sorted(name for name in sys.modules if name.split(".")[0] == "rclpy")
install_ros_compat(1)
ros1 = "rclpy" in sys.modules
install_ros_compat(2)
import rclpy.node
ros2 = [name for name in after_warm if name not in sys.modules]
install_ros_compat(1)
print(json.dumps({"after_warm": after_warm, "ros1": ros1, "missing_in_ros2": ros2,
                  "ros1_again": "rclpy" in sys.modules, "reimported": rclpy.node.__name__}))
"""
    )
    assert found["after_warm"] == []
    assert found["ros1"] is False
    assert found["missing_in_ros2"] == []
    assert found["ros1_again"] is False  # forgotten again for the next ROS 1 node, as before


def test_set_aside_modules_are_the_same_objects_a_ros2_node_imports():
    found = _in_fresh_python(
        """
import json, sys
from sandbox import host, runner
runner._host_imports()
runner._warm_rclpy()
aside = host._SET_ASIDE[host.ROS_COMPAT2_DIR]["rclpy.node"]
host.install_ros_compat(2)
import rclpy.node
print(json.dumps({"same": rclpy.node is aside, "count": len(host._SET_ASIDE)}))
"""
    )
    assert found == {"same": True, "count": 0}


def test_a_warm_process_builds_the_message_classes_it_is_given_in_both_dialects():
    """Built at a node's first use, sensor_msgs/LaserScan's class cost 13 ms of its start."""
    found = _in_fresh_python(
        """
import json
from sandbox import runner
from sandbox.msgs import _core as ros1
from sandbox.msgs2 import _core as ros2
from sandbox.msgs2.bridge import build_both_dialects
runner._host_imports()
before = ["sensor_msgs/LaserScan" in ros1._REGISTRY, "sensor_msgs/msg/LaserScan" in ros2._REGISTRY]
build_both_dialects(["sensor_msgs/LaserScan"])  # as the runner does for its warm pool
after = ["sensor_msgs/LaserScan" in ros1._REGISTRY, "sensor_msgs/msg/LaserScan" in ros2._REGISTRY]
print(json.dumps({"before": before, "after": after}))
"""
    )
    assert found == {"before": [False, False], "after": [True, True]}
