"""Load a Python launch file and visit its description as `ros2 launch` does.

`ros2 launch FILE name:=value` includes FILE with the arguments set as launch configurations
(ros2launch/api/api.py); the description is visited depth-first, each entity's sub-entities in
order with the locals (the current launch file) pushed around each (launch_service.py,
visit_all_entities_and_collect_futures). Only the launch file's own code runs; the modules it
imports (`launch`, `launch_ros`, `ament_index_python`) are the stand-ins of
sandbox/launch_shim/, which this module puts first on sys.path while it runs.

One difference from ros2 launch, on purpose: an argument given on the command line that no
launch file declares is an error (ros2 launch sets it silently), so a typo such as
`sped:=0.3` is caught."""

from __future__ import annotations

import contextlib
import os
import sys
import types
from collections.abc import Iterator
from typing import Any

from sandbox.launch2 import packages
from sandbox.launch2.actions import LaunchDescription
from sandbox.launch2.context import LaunchContext
from sandbox.launch2.errors import LAUNCH_FILES, LaunchError, Site
from sandbox.launch2.plan import Plan

SHIM_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "launch_shim")
SHIM_PACKAGES = ("launch", "launch_ros", "ament_index_python")
MAX_LAUNCH_FILE_BYTES = 256 * 1024  # [bytes] a launch file larger than this is not hand-written
MAX_LAUNCH_FILES = 32  # distinct launch files read in one launch (includes of includes)
_DECLARED: set[str] = set()  # every DeclareLaunchArgument constructed, visited or not
_READ: list[str] = []  # launch files read, in order


def declared(name: str) -> None:
    _DECLARED.add(name)


def launch_arguments(argv: list[str], path: str) -> dict[str, str]:
    """`name:=value` words (ros2launch's parse_launch_arguments; the last one wins)."""
    args: dict[str, str] = {}
    for word in argv:
        name, sep, value = word.partition(":=")
        if not sep or not name:
            raise LaunchError(
                f"launch argument '{word}' is not NAME:=VALUE (e.g. speed:=0.2)", Site(path, None)
            )
        args[name] = value
    return args


def load_launch_file(relative: str, context: LaunchContext, site: Site | None) -> LaunchDescription:
    """Run a workspace launch file's code and call its generate_launch_description()."""
    base = os.path.basename(relative)
    if base.endswith((".launch.xml", ".launch.yaml", ".launch.yml", ".yaml", ".yml")) or (
        base.endswith(".xml") and not base.endswith(".launch")
    ):
        raise LaunchError(
            f"'{relative}' is a ROS 2 XML or YAML launch file; RoboDojo reads ROS 2 Python "
            "launch files (.launch.py) and ROS 1 .launch files: write it as a .launch.py",
            site,
        )
    if base.endswith(".launch"):
        raise LaunchError(
            f"'{relative}' is a ROS 1 launch file; a ROS 2 launch file includes .launch.py "
            "files only (a run is ROS 1 or ROS 2, not both)",
            site,
        )
    absolute = os.path.join(context.workdir, relative)
    if not os.path.isfile(absolute):
        known = [p for p in packages.workspace_files(context.workdir) if p.endswith(".py")]
        raise LaunchError(
            f"launch file '{relative}' is not in your workspace (its Python files: "
            f"{', '.join(known) or 'none'})",
            site,
        )
    if os.path.getsize(absolute) > MAX_LAUNCH_FILE_BYTES:
        raise LaunchError(
            f"launch file '{relative}' is larger than {MAX_LAUNCH_FILE_BYTES // 1024} KiB", site
        )
    if relative not in _READ:
        _READ.append(relative)
        if len(_READ) > MAX_LAUNCH_FILES:
            raise LaunchError(f"more than {MAX_LAUNCH_FILES} launch files are included", site)
    with open(absolute, encoding="utf-8", errors="replace") as file:
        text = file.read()
    LAUNCH_FILES.add(relative)
    code = compile(text, relative, "exec", dont_inherit=True)
    module = types.ModuleType("launch_file_" + str(len(_READ)))
    module.__file__ = absolute
    exec(code, module.__dict__)
    generate = module.__dict__.get("generate_launch_description")
    if not callable(generate):
        raise LaunchError(
            f"'{relative}' defines no generate_launch_description(); a ROS 2 Python launch "
            "file returns its LaunchDescription([...]) from that function",
            Site(relative, None) if site is None else site,
        )
    description = generate()
    if not isinstance(description, LaunchDescription):
        raise LaunchError(
            f"generate_launch_description() in '{relative}' returned {description!r}, not a "
            "LaunchDescription([...])",
            Site(relative, getattr(getattr(generate, "__code__", None), "co_firstlineno", None)),
        )
    return description


def visit(entity: Any, context: LaunchContext) -> None:
    for sub in entity.visit(context) or []:
        context.push_locals()
        try:
            visit(sub, context)
        finally:
            context.pop_locals()


@contextlib.contextmanager
def shim_on_path() -> Iterator[None]:
    """The stand-in packages importable as `launch`, `launch_ros`, `ament_index_python`."""
    saved_path = list(sys.path)
    saved = {n: m for n, m in sys.modules.items() if n.split(".")[0] in SHIM_PACKAGES}
    for name in saved:
        del sys.modules[name]
    sys.path.insert(0, SHIM_DIR)
    try:
        yield
    finally:
        sys.path[:] = saved_path
        for name in [n for n in sys.modules if n.split(".")[0] in SHIM_PACKAGES]:
            del sys.modules[name]
        sys.modules.update(saved)


def evaluate(path: str, workdir: str, argv: list[str]) -> Plan:
    """The plan of the workspace launch file `path` (relative to `workdir`, where the
    workspace's files are) with launch arguments `argv` (`name:=value` words)."""
    _DECLARED.clear()
    _READ.clear()
    LAUNCH_FILES.clear()
    packages.set_workdir(workdir)
    args = launch_arguments(argv, path)
    context = LaunchContext(workdir=os.path.abspath(workdir), argv=list(argv))
    with shim_on_path():
        description = load_launch_file(path, context, None)
        context.launch_configurations.update(args)
        absolute = os.path.join(context.workdir, path)
        context.extend_locals(
            {
                "current_launch_file_path": absolute,
                "current_launch_file_directory": os.path.dirname(absolute),
            }
        )
        visit(description, context)
    unknown = sorted(set(args) - _DECLARED)
    if unknown:
        raise LaunchError(
            f"launch argument(s) {', '.join(unknown)} are not declared by this file or the "
            f"files it includes (declared: {', '.join(sorted(_DECLARED)) or 'none'})",
            Site(path, None),
        )
    return Plan(nodes=list(context.nodes), notes=list(context.notes), launch_files=list(_READ))
