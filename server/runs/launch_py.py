"""ROS 2 Python launch files read into a run: the file is evaluated in the sandbox (a one-shot
`Api.LAUNCH` job, sandbox/launch2/), never in this process, and its plan becomes NodeSpecs.

    plan = load_python_launch("my_pkg/launch/two.launch.py", workspace, {"speed": "0.3"},
                              launcher)

Each planned node is a workspace file (found as colcon installs executables: setup.py's
console_scripts, else the file of that name) with the node's own parameters (ROS 2 names,
dotted: `pid.kp`), remappings, namespace, and its command line as launch_ros builds it
(`arguments`, then `--ros-args ...`, with `-r __node:=<name>` when the launch names the node).
A node file whose console_scripts entry is a function the file does not call itself gets
that call appended under `if __name__ == "__main__":` (the line numbers above stay the
student's). The run's label for a node is its name (the launch's, else the code's, else the
executable's), made unique with its namespace.

Every failure is a LaunchFileError naming the launch file and line: what the job reported
(syntax errors, unknown packages, missing arguments, bad parameter files), or what became of
the job (killed past its budget: a launch file that loops; crashed: out of memory)."""

from __future__ import annotations

import ast
import posixpath
import re
from collections.abc import Mapping

import msgspec

from sandbox import python_ast
from sandbox.launch2.job import ERROR_TYPE
from sandbox.launch2.plan import PLAN_ARTIFACT, Plan, PlannedNode
from sandbox.launcher import Launcher
from sandbox.protocol import Api, Artifact, Clock, Exited, NodeInfo, Outcome
from server.runs.launch import LaunchFileError, LaunchPlan, load_launch
from server.runs.spec import NodeSpec

ROS2_FRONTEND_SUFFIXES = (".launch.xml", ".launch.yaml", ".launch.yml")
_LABEL = re.compile(r"[^A-Za-z0-9_]")
MAX_LABEL_CHARS = 40  # server/runs/spec.py's node names


def is_python_launch(path: str, text: str | bytes | None = None) -> bool:
    """A ROS 2 Python launch file: `.launch.py`, or a `.py` defining
    generate_launch_description() at the top level (read with ast, never run)."""
    if path.endswith(".launch.py"):
        return True
    if not path.endswith(".py") or text is None:
        return False
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    try:
        tree = python_ast.parse(text)
    except (SyntaxError, ValueError):
        return False
    return any(
        isinstance(node, ast.FunctionDef) and node.name == "generate_launch_description"
        for node in tree.body
    )


# A ROS 2 XML launch file's node names its program with exec= (ROS 1's with type=); a ROS 2
# YAML launch file starts with `launch:`.
_ROS2_XML_NODE = re.compile(r"<node\b[^>]*\bexec\s*=")
_ROS2_YAML_LAUNCH = re.compile(r"^launch\s*:", re.MULTILINE)


def frontend_refusal(path: str, text: str | bytes | None = None) -> str | None:
    """The sentence for a ROS 2 XML or YAML launch file, which is not read: by its name
    (.launch.xml, .launch.yaml) or, for .xml/.launch/.yaml names, by what it holds."""
    body = _text(text) if text is not None else ""
    ros2_xml = path.endswith((".xml", ".launch")) and _ROS2_XML_NODE.search(body)
    ros2_yaml = path.endswith((".yaml", ".yml")) and _ROS2_YAML_LAUNCH.search(body)
    if path.endswith(ROS2_FRONTEND_SUFFIXES) or ros2_xml or ros2_yaml:
        return (
            f"'{path}' is a ROS 2 XML/YAML launch file, which RoboDojo does not read; write it "
            "as a Python launch file (.launch.py with generate_launch_description()) or give "
            "a ROS 1 .launch file"
        )
    return None


def read_launch(
    path: str,
    workspace: Mapping[str, str | bytes],
    args: Mapping[str, str] | None,
    launcher: Launcher | None,
) -> LaunchPlan:
    """Any launch file the lab reads, by its kind: a ROS 2 Python launch file in the sandbox
    (load_python_launch), a ROS 1 .launch/.xml file on the server (server/runs/launch.py, pure
    XML reading); ROS 2 XML/YAML launch files are refused with a sentence."""
    clean = posixpath.normpath(path)
    text = {posixpath.normpath(k): v for k, v in workspace.items()}.get(clean)
    refusal = frontend_refusal(clean, text)
    if refusal:
        raise LaunchFileError(clean, None, refusal)
    if is_python_launch(clean, text):
        if launcher is None:
            raise ValueError("a Python launch file is read in the sandbox: give a launcher")
        return load_python_launch(clean, workspace, args, launcher)
    if clean.endswith(".py"):
        raise LaunchFileError(
            clean,
            None,
            "this Python file defines no generate_launch_description(), so it is a node, not "
            "a launch file; run it with --node (or name a .launch.py / .launch file)",
        )
    return load_launch(clean, workspace, args)


def load_python_launch(
    path: str,
    workspace: Mapping[str, str | bytes],
    args: Mapping[str, str] | None,
    launcher: Launcher,
) -> LaunchPlan:
    """Evaluate the workspace launch file `path` with launch arguments `args` in the sandbox;
    raises LaunchFileError."""
    files = {posixpath.normpath(key): value for key, value in workspace.items()}
    path = posixpath.normpath(path)
    if path not in files:
        raise LaunchFileError(path, None, "this launch file is not in the workspace")
    exited = _run_job(path, files, dict(args or {}), launcher)
    plan = _plan_of(path, exited, launcher)
    return LaunchPlan(
        nodes=_node_specs(plan, files), params={}, notes=tuple(plan.notes), ros_version=2
    )


def _text(value: str | bytes) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else value


def _run_job(
    path: str, files: dict[str, str | bytes], args: dict[str, str], launcher: Launcher
) -> Exited:
    info = NodeInfo(
        node_name="launch",
        robot="",
        robot_topics=[],
        velocity_topic=None,
        clock=Clock.REALTIME,
        argv=[f"{name}:={value}" for name, value in args.items()],
        ros_version=2,
    )
    artifacts = [
        Artifact(key, value.encode() if isinstance(value, str) else value)
        for key, value in sorted(files.items())
    ]
    job = launcher.start("launch")
    try:
        reply = job.load(_text(files[path]), path, Api.LAUNCH, info, artifacts)
        if not isinstance(reply, Exited):  # the job never sleeps; a Yield is not ours
            reply = job.kill("the launch job yielded", Outcome.CRASHED)
        return reply
    finally:
        job.close()


def _plan_of(path: str, exited: Exited, launcher: Launcher) -> Plan:
    if exited.outcome is Outcome.FINISHED:
        data = next((a.data for a in exited.artifacts if a.name == PLAN_ARTIFACT), None)
        if data is None:
            raise LaunchFileError(path, None, "the launch job gave no plan (an internal fault)")
        try:
            return msgspec.json.decode(data, type=Plan)
        except msgspec.DecodeError as error:
            raise LaunchFileError(
                path, None, f"the launch job's plan is unreadable: {error}"
            ) from None
    error = exited.error
    if exited.outcome is Outcome.ERROR and error is not None:
        if error.type == ERROR_TYPE:
            raise LaunchFileError(error.filename or path, error.line, error.message)
        raise LaunchFileError(error.filename or path, error.line, f"{error.type}: {error.message}")
    if exited.outcome is Outcome.KILLED:
        budget = launcher.limits.first_step_budget_s
        raise LaunchFileError(
            path,
            None,
            f"reading this launch file took longer than {budget:g} s and was stopped: "
            "generate_launch_description() must return its LaunchDescription at once (a loop "
            "that never ends? a wait?)",
        )
    raise LaunchFileError(path, None, f"reading this launch file failed: {exited.reason}")


def _node_specs(plan: Plan, files: dict[str, str | bytes]) -> tuple[NodeSpec, ...]:
    labels = _labels(plan.nodes)
    specs = []
    for node, label in zip(plan.nodes, labels, strict=True):
        if node.file not in files or not node.file.endswith(".py"):
            raise LaunchFileError(
                node.launch_file, node.line, f"the node file '{node.file}' is not in the workspace"
            )
        code = _text(files[node.file])
        if node.entry:
            if not node.entry.isidentifier():
                raise LaunchFileError(
                    node.launch_file, node.line, f"'{node.entry}' is not a function name"
                )
            code = code.rstrip("\n") + (
                "\n\n\nif __name__ == '__main__':  # setup.py's console_scripts entry point\n"
                f"    {node.entry}()\n"
            )
        specs.append(
            NodeSpec(
                name=label,
                code=code,
                filename=posixpath.basename(node.file),
                params=dict(node.params),
                remaps=tuple((source, target) for source, target in node.remaps),
                args=tuple(node.args),
                namespace=node.namespace or "/",
                ros_version=2,  # a Python launch file's node is ROS 2 (spec.py decides the run)
            )
        )
    return tuple(specs)


def _labels(nodes: list[PlannedNode]) -> list[str]:
    """Unique run labels: the node's name, else its namespace joined in, else a count."""

    def clean(text: str) -> str:
        label = _LABEL.sub("_", text).strip("_") or "node"
        return label if label[0].isalpha() else "node_" + label

    bases = [
        clean(
            node.name or node.code_name or posixpath.basename(node.executable).removesuffix(".py")
        )
        for node in nodes
    ]
    labels = []
    for node, base in zip(nodes, bases, strict=True):
        label = base
        if bases.count(base) > 1 and node.namespace != "/":
            label = clean(node.namespace.strip("/") + "_" + base)
        labels.append(label[:MAX_LABEL_CHARS])
    seen: dict[str, int] = {}
    unique = []
    for label in labels:
        seen[label] = seen.get(label, 0) + 1
        unique.append(
            label if seen[label] == 1 else f"{label[: MAX_LABEL_CHARS - 3]}_{seen[label]}"
        )
    return unique


__all__ = ["frontend_refusal", "is_python_launch", "load_python_launch", "read_launch"]
