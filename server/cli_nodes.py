"""The command line's ROS side: `--node`, `--param`, `--remap` and `--args` in the order given,
turned into NodeSpecs and run-wide parameters, and a workspace folder read for `--launch`.

As rosrun and rosparam take them (http://wiki.ros.org/rosbash#rosrun,
http://wiki.ros.org/rosparam): a value is typed as YAML (`0.5` float, `3` int, `true` bool,
`[1, 2]` list, anything else a string); `--remap FROM:=TO` is rosrun's `from:=to`; `--args`
is the rest of a rosrun command line, split as a shell would (its `_x:=v` and `a:=b` work as
in rosrun). A `--param` after a `--node` is that node's own (`speed` -> `~speed`, like a
<param> inside <node>; `/name` stays global); before any `--node` it is run-wide (global).
"""

from __future__ import annotations

import shlex
from dataclasses import replace
from pathlib import Path

from sandbox.names import InvalidName, check_name, parse_param_value
from server.runs.spec import NodeSpec, RunSpecError
from server.service.workspace_files import CODE_EXTENSION, DATA_EXTENSIONS

MAX_WORKSPACE_FILES = 200  # files read from a workspace folder; more is not a ROS package
MAX_WORKSPACE_FILE_BYTES = 1024 * 1024  # [bytes] per file
MAX_WORKSPACE_BYTES = 16 * 1024 * 1024  # [bytes] all files together
MAX_WORKSPACE_DEPTH = 4  # folders below the workspace (src/pkg/config/x.yaml)
_SKIPPED_FOLDERS = ("__pycache__", "build", "devel", "install", "log")


def param_assignment(text: str, flag: str = "--param") -> tuple[str, object]:
    """`NAME=VALUE` -> (NAME, YAML-typed VALUE); RunSpecError with a sentence."""
    name, sep, value = text.partition("=")
    name = name.strip()
    if not sep or not name:
        raise RunSpecError(f"{flag} takes NAME=VALUE (e.g. {flag} speed=0.2), got '{text}'")
    try:
        check_name(name, "parameter name")
        return name, parse_param_value(value)
    except InvalidName as error:
        raise RunSpecError(f"{flag} {text}: {error}") from None


def remap_pair(text: str) -> tuple[str, str]:
    """`FROM:=TO` -> (FROM, TO), both valid ROS names; RunSpecError otherwise."""
    source, sep, target = text.partition(":=")
    if not sep or not source.strip() or not target.strip():
        raise RunSpecError(f"--remap takes FROM:=TO (e.g. --remap scan:=base_scan), got '{text}'")
    try:
        return check_name(source.strip(), "name"), check_name(target.strip(), "name")
    except InvalidName as error:
        raise RunSpecError(f"--remap {text}: {error}") from None


def node_file_spec(value: str) -> NodeSpec:
    """`--node FILE` or `--node NAME=FILE`."""
    name, _, path = value.rpartition("=") if "=" in value else ("", "", value)
    return NodeSpec.from_file(path, name or None)


def nodes_from_flags(
    ordered: list[tuple[str, str]],
) -> tuple[tuple[NodeSpec, ...], dict[str, object]]:
    """(flag, value) pairs in command-line order -> (nodes, run-wide params)."""
    nodes: list[NodeSpec] = []
    run_params: dict[str, object] = {}
    for flag, value in ordered:
        if flag == "node":
            nodes.append(node_file_spec(value))
            continue
        if flag == "param":
            name, typed = param_assignment(value)
            if not nodes:
                run_params[name] = typed
            else:
                key = name if name.startswith(("/", "~")) else "~" + name
                nodes[-1] = replace(nodes[-1], params={**nodes[-1].params, key: typed})
            continue
        if not nodes:
            raise RunSpecError(
                f"--{flag} applies to the node before it; put it after a --node FILE"
            )
        if flag == "remap":
            pair = remap_pair(value)
            kept = tuple(item for item in nodes[-1].remaps if item[0] != pair[0])
            nodes[-1] = replace(nodes[-1], remaps=(*kept, pair))
        elif flag == "args":
            try:
                words = shlex.split(value)
            except ValueError as error:
                raise RunSpecError(f'--args "{value}" cannot be split: {error}') from None
            nodes[-1] = replace(nodes[-1], args=(*nodes[-1].args, *words))
        elif flag == "ns":
            try:
                check_name(value, "namespace")
            except InvalidName as error:
                raise RunSpecError(f"--ns {value}: {error}") from None
            nodes[-1] = replace(nodes[-1], namespace="/" + value.strip("/"))
    return tuple(nodes), run_params


def launch_arguments(values: list[str]) -> dict[str, str]:
    """roslaunch's `name:=value` arguments."""
    args: dict[str, str] = {}
    for value in values:
        name, sep, text = value.partition(":=")
        if not sep or not name.strip():
            raise RunSpecError(f"launch arguments are NAME:=VALUE (e.g. speed:=0.2), got '{value}'")
        args[name.strip()] = text
    return args


def workspace_folder(launch_file: Path) -> Path:
    """The workspace of a launch file when none is given: the folder of the nearest
    package.xml above it, else the parent of a `launch/` folder, else its own folder."""
    for folder in list(launch_file.resolve().parents)[:3]:
        if (folder / "package.xml").is_file():
            return folder
    here = launch_file.resolve().parent
    return here.parent if here.name == "launch" else here


def read_workspace(folder: Path) -> dict[str, bytes]:
    """The code, launch and data files of a workspace folder (relative path -> bytes); hidden
    files and build folders are skipped; RunSpecError past the caps."""
    if not folder.is_dir():
        raise RunSpecError(f"workspace '{folder}' is not a folder")
    files: dict[str, bytes] = {}
    total = 0
    kept = (CODE_EXTENSION, *DATA_EXTENSIONS)
    for path in sorted(folder.rglob("*")):
        relative = path.relative_to(folder)
        parts = relative.parts
        if any(part.startswith(".") or part in _SKIPPED_FOLDERS for part in parts):
            continue
        if not path.is_file() or path.suffix.lower() not in kept:
            continue
        if len(parts) > MAX_WORKSPACE_DEPTH + 1:
            continue
        size = path.stat().st_size
        if size > MAX_WORKSPACE_FILE_BYTES:
            raise RunSpecError(
                f"workspace file '{relative}' is larger than "
                f"{MAX_WORKSPACE_FILE_BYTES // 1024} KiB; keep large data out of the workspace"
            )
        total += size
        if len(files) >= MAX_WORKSPACE_FILES or total > MAX_WORKSPACE_BYTES:
            raise RunSpecError(
                f"workspace '{folder}' holds more than {MAX_WORKSPACE_FILES} files or "
                f"{MAX_WORKSPACE_BYTES // (1024 * 1024)} MiB; give --workspace the package folder"
            )
        files[relative.as_posix()] = path.read_bytes()
    return files


def data_files(workspace: dict[str, bytes]) -> tuple[tuple[str, bytes], ...]:
    """The files a run copies next to its nodes: every data file (not code, not launch)."""
    data = tuple(ext for ext in DATA_EXTENSIONS if ext not in (".launch", ".xml"))
    return tuple((path, body) for path, body in workspace.items() if path.lower().endswith(data))
