"""What the launch job answers (as the artifact `launch_plan.json` of its Exited frame), typed
so the server decodes it strictly (msgspec) and trusts nothing else the job might say."""

from __future__ import annotations

import msgspec

PLAN_ARTIFACT = "launch_plan.json"


class PlannedNode(msgspec.Struct, frozen=True):
    """One launch_ros Node, evaluated. Parameter names are the node's own (dotted, relative);
    `args` is the node's command line after its file name, as launch_ros builds it
    (`arguments`, then `--ros-args ...`: ros_arguments, `-r __node:=<name>` when named)."""

    package: str
    executable: str
    file: str  # workspace-relative path of the node's code
    entry: str | None  # function to call (setup.py console_scripts) if the file does not
    name: str | None  # name= of the launch file (None: the name the code gives)
    code_name: str | None  # the name the code gives its Node, when it could be read
    namespace: str  # "/" or "/a/b"
    params: dict[str, object]
    remaps: list[tuple[str, str]]
    args: list[str]
    launch_file: str  # where the Node(...) is
    line: int | None


class Plan(msgspec.Struct, frozen=True):
    nodes: list[PlannedNode]
    notes: list[str] = []
    launch_files: list[str] = []  # every launch file read (the first is the one run)
