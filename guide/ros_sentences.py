"""The sentences a node gets for what RoboDojo's ROS 1 and ROS 2 layers do not provide, taken
from the sandbox's own code at build time: each table row is the real error of the real call.

The ROS layers import one another by their ROS names (`import rclpy`, `import rospy`), as a node
does inside the sandbox, so the sentences are collected in a child Python whose path starts with
that dialect's compatibility folder, as the sandbox's runner sets it up.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COMPAT = {"ros1": ROOT / "sandbox" / "ros_compat", "ros2": ROOT / "sandbox" / "ros_compat2"}

# Run in the child: (what the student writes, the exception's type, its message) per row.
_COLLECT = r"""
import importlib, json, sys
dialect = sys.argv[1]
rows = []

def attribute(module_name, name):
    module = importlib.import_module(module_name)
    try:
        getattr(module, name)
    except AttributeError as error:
        rows.append((f"{module_name}.{name}", "AttributeError", str(error)))

if dialect == "ros1":
    from sandbox import ros_imports as imports
    libraries = {}
    for name in ("rospy", "tf", "tf2_ros"):
        module = importlib.import_module(name)
        for missing in module._NOT_PROVIDED:
            attribute(name, missing)
    attribute("rospy", "spinOnce")
else:
    from sandbox import ros2_imports as imports
    libraries = getattr(imports, "LIBRARY_MODULES", {})
    for name in ("rclpy", "tf2_ros"):
        module = importlib.import_module(name)
        for missing in module._NOT_PROVIDED:
            attribute(name, missing)
    attribute("rclpy", "spin_some")
modules = [*imports.MISSING_MODULES, *getattr(imports, "MISSING_SUBMODULES", {})]
for name in modules:
    sentence = imports.sentence_for(name)
    if sentence:
        rows.insert(0, (f"import {name}", "ModuleNotFoundError", sentence))
print(json.dumps(sorted(rows, key=lambda row: (row[1] != "ModuleNotFoundError", row[0]))))
"""


def sentences(dialect: str) -> list[tuple[str, str, str]]:
    """(what the node writes, exception type, message) for `ros1` or `ros2`."""
    if dialect not in COMPAT:
        raise ValueError(f"unknown dialect '{dialect}'; use ros1 or ros2")
    path = f"{COMPAT[dialect]}:{ROOT}"
    done = subprocess.run(
        [sys.executable, "-c", _COLLECT, dialect],
        capture_output=True,
        text=True,
        check=False,
        env={"PYTHONPATH": path, "PATH": "/usr/bin:/bin"},
        timeout=60,
    )
    if done.returncode != 0:
        raise ValueError(f"collecting the {dialect} sentences failed:\n{done.stderr}")
    return [tuple(row) for row in json.loads(done.stdout)]


def sentences_markdown(dialect: str) -> str:
    lines = ["| you write | you get |", "|---|---|"]
    for written, kind, message in sentences(dialect):
        text = message.replace("|", "\\|").replace("\n", " ")
        lines.append(f"| `{written}` | `{kind}`: {text} |")
    return "\n".join(lines) + "\n"
