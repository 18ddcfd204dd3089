"""Loading a ROS 2 student-side package (sandbox/ros_compat2/<name>) in the test process.

The node host puts sandbox/ros_compat2 on a ROS 2 node's sys.path, where `std_msgs` or
`tf2_ros` are ROS 2 packages; the test process already holds the ROS 1 ones of
sandbox/ros_compat under those names. A package whose top-level name is ROS 2's alone (and
which imports only `sandbox.*`) is loaded here from its file, leaving sys.path alone."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

ROS_COMPAT2 = Path(__file__).resolve().parents[2] / "sandbox" / "ros_compat2"


def load_ros2_package(name: str) -> ModuleType:
    """The package sandbox/ros_compat2/<name>, imported under its own name."""
    if name in sys.modules:
        return sys.modules[name]
    location = ROS_COMPAT2 / name / "__init__.py"
    spec = importlib.util.spec_from_file_location(
        name, location, submodule_search_locations=[str(location.parent)]
    )
    assert spec is not None and spec.loader is not None, location
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module
