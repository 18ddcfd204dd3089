"""The ament index over the student's workspace: which folder is a package's share directory,
and which workspace file a Node's `executable` names.

A package is a folder holding a package.xml with its <name>; its share directory (where
colcon installs launch/ and config/) is that folder, as roslaunch's $(find pkg) is in the
ROS 1 reader. A workspace without any package.xml is one package of any name. Packages of the
robot, its simulator and ROS's own tools are refused with a sentence: the run provides the
robot, its world and the 3D view.

An executable is found as colcon installs it (ament_python's setup.py `console_scripts`
entry `name = pkg.module:main` -> pkg/module.py, whose `main` is called), else as a file of
that name (`talker.py` for `talker` or `talker.py`), in the package's folder first."""

from __future__ import annotations

import ast
import os
import re

from sandbox import python_ast
from sandbox.launch2.errors import LaunchError, PackageNotFoundError, Site

MAX_SCAN_DEPTH = 4  # folders below the workspace searched for package.xml and node files
# ROS 2 packages that are the robot, its simulator, or tools around them: a run has its own.
ROBOT_PACKAGES = re.compile(
    r"^(turtlebot3(_\w+)?|turtlebot4(_\w+)?|gazebo_ros\w*|ros_gz\w*|gz_\w+|ros_ign\w*|"
    r"robot_state_publisher|joint_state_publisher(_gui)?|rviz2?|rviz_\w+|rqt\w*|nav2_\w+|"
    r"slam_toolbox|cartographer\w*|tf2_ros|xacro|urdf\w*|rosbag2\w*|teleop_twist_\w+|"
    r"joy\w*|turtlesim|webots_ros2\w*|micro_ros\w*|ros2_control|controller_manager)$"
)
_WORKDIR: list[str] = []  # the job's workspace copy, set by evaluate.py


def set_workdir(workdir: str) -> None:
    _WORKDIR[:] = [workdir]


def workdir() -> str:
    return _WORKDIR[0] if _WORKDIR else os.getcwd()


def workspace_files(root: str | None = None) -> list[str]:
    """Workspace-relative paths of every file, sorted (hidden files and caches skipped)."""
    root = root or workdir()
    found: list[str] = []
    for folder, dirs, files in os.walk(root):
        depth = os.path.relpath(folder, root).count(os.sep)
        dirs[:] = sorted(
            d
            for d in dirs
            if not d.startswith(".") and d != "__pycache__" and depth < MAX_SCAN_DEPTH
        )
        for name in files:
            if not name.startswith("."):
                found.append(os.path.relpath(os.path.join(folder, name), root).replace(os.sep, "/"))
    return sorted(found)


def packages() -> dict[str, str]:
    """Package name -> its workspace-relative folder ("." for the workspace itself)."""
    found: dict[str, str] = {}
    for path in workspace_files():
        if os.path.basename(path) != "package.xml":
            continue
        with open(os.path.join(workdir(), path), encoding="utf-8", errors="replace") as file:
            match = re.search(r"<name>\s*([\w-]+)\s*</name>", file.read())
        if match:
            found.setdefault(match.group(1), os.path.dirname(path) or ".")
    return found


def package_folder(package: str, site: Site | None) -> str:
    known = packages()
    if package in known:
        return known[package]
    if ROBOT_PACKAGES.match(package):
        raise LaunchError(
            f"'{package}' is a ROS package of the robot, its simulator or ROS's tools, which a "
            "run does not have: the robot, its world and the 3D view come from the run's "
            "settings; remove what uses it",
            site,
        )
    if not known:
        return "."
    raise PackageNotFoundError(
        f"package '{package}' is not in your workspace (its packages, by package.xml: "
        f"{', '.join(sorted(known))})"
    )


def get_package_share_directory(package: str, site: Site | None = None) -> str:
    if not isinstance(package, str):
        raise LaunchError(f"a package name is a string, got {package!r}", site)
    return os.path.normpath(os.path.join(workdir(), package_folder(package, site)))


def get_package_prefix(package: str, site: Site | None = None) -> str:
    return get_package_share_directory(package, site)


# ------------------------------------------------------------------ executables
def _console_scripts(setup_py: str) -> dict[str, str]:
    """name -> 'module.path:function' from a setup.py's entry_points, read without running it
    (only literal values are understood)."""
    try:
        with open(setup_py, encoding="utf-8", errors="replace") as file:
            tree = python_ast.parse(file.read())
    except (OSError, SyntaxError, ValueError):
        return {}
    scripts: dict[str, str] = {}
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        for keyword in node.keywords:
            if keyword.arg != "entry_points":
                continue
            try:
                entry_points = ast.literal_eval(keyword.value)  # a tree, no text
            except ValueError:
                continue
            if not isinstance(entry_points, dict):
                continue
            for line in entry_points.get("console_scripts", []) or []:
                name, _, target = str(line).partition("=")
                if target.strip():
                    scripts[name.strip()] = target.strip()
    return scripts


def find_executable(package: str, executable: str, site: Site | None) -> tuple[str, str | None]:
    """(workspace-relative file, entry function or None) for a Node's package and executable."""
    if ROBOT_PACKAGES.match(package) and package not in packages():
        raise LaunchError(
            f"Node(package='{package}', executable='{executable}') runs a ROS program that a "
            "run does not have: the robot, its world, its transforms and the 3D view come from "
            "the run's settings; remove this Node",
            site,
        )
    folder = package_folder(package, site)
    files = workspace_files()
    setup = os.path.normpath(os.path.join(folder, "setup.py")).replace(os.sep, "/")
    if setup in files:
        target = _console_scripts(os.path.join(workdir(), setup)).get(executable)
        if target:
            module, _, function = target.partition(":")
            path = os.path.normpath(
                os.path.join(folder, module.strip().replace(".", "/") + ".py")
            ).replace(os.sep, "/")
            if path not in files:
                raise LaunchError(
                    f"setup.py names '{executable} = {target}', but the workspace has no '{path}'",
                    site,
                )
            return path, function.strip() or None
    names = {executable} if executable.endswith(".py") else {executable, executable + ".py"}
    matches = [path for path in files if os.path.basename(path) in names and path.endswith(".py")]
    if len(matches) > 1 and folder != ".":
        inside = [path for path in matches if path.startswith(folder + "/")]
        matches = inside or matches
    if len(matches) == 1:
        return matches[0], None
    if matches:
        raise LaunchError(
            f"executable '{executable}' matches {len(matches)} workspace files: "
            f"{', '.join(matches)}; rename one so the name is unique",
            site,
        )
    scripts = [
        path
        for path in files
        if path.endswith(".py")
        and not path.endswith(".launch.py")
        and os.path.basename(path) not in ("setup.py", "__init__.py")
    ]
    raise LaunchError(
        f"no workspace file is executable '{executable}' of package '{package}' (a file named "
        f"{executable if executable.endswith('.py') else executable + '.py'}, or a setup.py "
        f"console_scripts entry); the workspace's Python files: {', '.join(scripts) or 'none'}",
        site,
    )


def runs_entry_itself(path: str) -> bool:
    """Whether the file has an `if __name__ == '__main__':` block (it then calls its entry
    point itself when run as a script)."""
    try:
        with open(os.path.join(workdir(), path), encoding="utf-8", errors="replace") as file:
            tree = python_ast.parse(file.read())
    except (OSError, SyntaxError, ValueError):
        return True  # the node reports its own syntax error when it runs
    for node in tree.body:
        if isinstance(node, ast.If) and "__main__" in ast.unparse(node.test):
            return True
    return False


def node_name_in_code(path: str) -> str | None:
    """The node name a file gives its rclpy Node, when it gives exactly one as a literal:
    `super().__init__('talker')`, `Node('talker')`, `rclpy.create_node('talker')`."""
    try:
        with open(os.path.join(workdir(), path), encoding="utf-8", errors="replace") as file:
            tree = python_ast.parse(file.read())
    except (OSError, SyntaxError, ValueError):
        return None
    names: set[str] = set()
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
        if called not in ("Node", "__init__", "create_node", "LifecycleNode"):
            continue
        candidates = [*node.args[:1]] + [k.value for k in node.keywords if k.arg == "node_name"]
        for value in candidates:
            if isinstance(value, ast.Constant) and isinstance(value.value, str):
                names.add(value.value)
    return names.pop() if len(names) == 1 else None
