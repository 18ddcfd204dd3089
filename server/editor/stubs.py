"""Source stubs of the message classes and the step API, for the editor's static analysis.

`sandbox.msgs` and `sandbox.msgs2` build their classes on first use from a table, so a static
analyser reading their source sees no `Twist` and no `linear`. This module writes, once per
server start, a plain Python package per message package (`geometry_msgs/msg/__init__.py` with
`class Twist:` and its annotated fields) from those same classes, and an `Observation` class
per robot for the step API. jedi reads these files as text; nothing here is ever imported.

    root/ros1/    message packages as ROS 1 has them, _robodojo_step_<robot>.py
    root/ros2/    message packages as ROS 2 has them (msg, srv, action)
    root/common/  a link to the real `sandbox` package, which rospy's and rclpy's source imports
                  (for an Analyser in the server's own process, as the tests make; the editor's
                  sandbox shows jedi /opt/robodojo instead, which holds `sandbox` alone)
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import sandbox
from server.editor.context import Topics
from server.editor.messages import ROS1, ROS2, MessageInfo, message_info, packages

STEP_MODULE = "_robodojo_step_{robot}"  # the step API's stub module of a robot
# The sandbox package as this process sees it: the checkout's in the server, the bound copy
# (/opt/robodojo/sandbox) inside the editor's sandbox.
SANDBOX_DIR = Path(sandbox.__file__).resolve().parent
HEADER = '"""Written by server/editor/stubs.py for the editor\'s analysis; never imported."""\n'


def _field_lines(info: MessageInfo, own_package: str | None) -> list[str]:
    lines = []
    for field in info.fields:
        python_type = field.python_type
        if own_package is not None:  # a type of this very module: its bare name
            python_type = python_type.replace(f"{own_package}.msg.", "")
        lines.append(f"    {field.name}: {python_type}")
        lines.append(f'    """{field.describe(info.type_name)}"""')
    for name, ros_type, value in info.constants:
        lines.append(f"    {name}: {'str' if ros_type == 'string' else 'int'} = {value!s}"
                     if ros_type != "string" else f"    {name}: str = {value!r}")  # fmt: skip
    return lines


def _class_source(stub_name: str, info: MessageInfo, own_package: str | None) -> str:
    own = f"{own_package}.msg." if own_package else "\0"
    params = ", ".join(f"{f.name}: {f.python_type.replace(own, '')} = ..." for f in info.fields)
    doc = f"{info.type_name}: fields {info.field_names()}"
    body = _field_lines(info, own_package)
    init = f"    def __init__(self, {params}) -> None: ...\n" if params else ""
    methods = (
        "    def serialize(self, buff) -> None: ...\n    def deserialize(self, data: bytes): ...\n"
    )
    return f'class {stub_name}:\n    """{doc}"""\n\n' + "\n".join(body) + "\n" + init + methods


def _imports(infos: list[MessageInfo], dialect: int) -> str:
    used = sorted(
        {f.message_type.split("/")[0] for info in infos for f in info.fields if f.message_type}
    )
    lines = [f"import {package}.msg" for package in used]
    if dialect == ROS1:
        lines.append("from sandbox.msgs import Duration, Time")
    return "\n".join(lines) + "\n\n\n"


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    for folder in (path.parent, path.parent.parent):
        init = folder / "__init__.py"
        if folder.name not in ("ros1", "ros2") and not init.exists():
            init.write_text(HEADER)
    path.write_text(text)


def _message_module(dialect: int, package: str, infos: list[MessageInfo]) -> str:
    classes = [_class_source(i.short_name, i, package) for i in infos]
    return HEADER + _imports(infos, dialect) + "\n\n".join(classes)


def _infos(dialect: int, package: str, names) -> list[MessageInfo]:
    found = (message_info(dialect, f"{package}/{name}") for name in names)
    return [info for info in found if info is not None]


def _module(parts: list[MessageInfo], classes: list[str], dialect: int) -> str:
    return HEADER + _imports(parts, dialect) + "\n\n".join(classes)


def _ros1_package(root: Path, package: str) -> None:
    from sandbox.msgs import _catalog

    infos = _infos(ROS1, package, _catalog.names(package, "msg"))
    if infos:
        _write(root / package / "msg" / "__init__.py", _message_module(ROS1, package, infos))
    services = [n for n in _catalog.names(package, "srv") if _catalog.is_service(f"{package}/{n}")]
    if not services:
        return
    parts = [i for n in services for s in ("Request", "Response")
             if (i := message_info(ROS1, f"{package}/{n}{s}"))]  # fmt: skip
    classes = [_class_source(i.short_name, i, None) for i in parts]
    classes += [
        f'class {n}:\n    """{package}/{n}: a service"""\n\n'
        f"    _request_class = {n}Request\n    _response_class = {n}Response\n"
        for n in services
    ]
    _write(root / package / "srv" / "__init__.py", _module(parts, classes, ROS1))


def _ros2_package(root: Path, package: str) -> None:
    from sandbox.msgs2 import _catalog, get_action_class, get_service_class
    from sandbox.msgs2 import get_message_class as message_class2

    infos = _infos(ROS2, package, _catalog.names(package, "msg"))
    if infos:
        _write(root / package / "msg" / "__init__.py", _message_module(ROS2, package, infos))
    for kind, getter, members in (
        ("srv", get_service_class, ("Request", "Response")),
        ("action", get_action_class, ("Goal", "Result", "Feedback")),
    ):
        names = _catalog.names(package, kind)
        if not names:
            continue
        parts, wrappers = [], []
        for name in names:
            try:
                cls = getter(f"{package}/{kind}/{name}")
            except (KeyError, LookupError, ValueError):
                continue
            aliases = []
            for member in members:
                part = getattr(cls, member)
                info = message_info(ROS2, part._type) or _part_info(message_class2, part._type)
                if info is not None:
                    parts.append(info)
                    aliases.append(f"    {member} = {info.short_name}")
            doc = f'    """{package}/{kind}/{name}"""\n\n'
            wrappers.append(f"class {name}:\n{doc}" + "\n".join(aliases) + "\n")
        classes = [_class_source(i.short_name, i, None) for i in parts] + wrappers
        _write(root / package / kind / "__init__.py", _module(parts, classes, ROS2))


def _part_info(message_class2, type_name: str) -> MessageInfo | None:
    from server.editor.messages import _from_class

    try:
        return _from_class(message_class2(type_name), ROS2)
    except (KeyError, LookupError, ValueError):
        return None


def step_module(root: Path, robot_id: str, extra: Topics = ()) -> str:
    """The name of the step API's stub module for a robot whose run's built-in nodes publish
    `extra` (written on first use: exercises bring few combinations)."""
    if not extra:
        return STEP_MODULE.format(robot=robot_id)
    digest = hashlib.sha1(repr(extra).encode()).hexdigest()[:12]
    name = f"{STEP_MODULE.format(robot=robot_id)}_{digest}"
    path = root / "ros1" / f"{name}.py"
    if not path.exists():
        partial = path.with_suffix(f".{os.getpid()}.tmp")  # two workers may write it at once
        partial.write_text(_step_module(robot_id, extra))
        partial.replace(path)
    return name


def _step_module(robot_id: str, extra: Topics = ()) -> str:
    from server.sim import get_robot

    robot = get_robot(robot_id)
    sensors = [(t.name, t.type_name, t.description) for t in robot.topics()
               if str(t.direction) == "publish"]  # fmt: skip
    sensors += [(name, kind, "published by the exercise's built-in node") for name, kind in extra]
    lines, used = [], set()
    for topic, type_name, description in sensors:
        if not topic.isidentifier():
            continue  # "ultrasonic/range_0" only by obs["..."]
        package, name = type_name.split("/")
        used.add(package)
        lines.append(f"    {topic}: {package}.msg.{name} | None")
        lines.append(f'    """{type_name}: {description}"""')
    sensors = [name for name, _, _ in sensors]
    imports = "".join(f"import {p}.msg\n" for p in sorted(used))
    return (
        HEADER + imports + "\n\n"
        "class Observation:\n"
        f'    """The latest message of each sensor topic of robot {robot_id} (None before the '
        f'first one), by attribute or by key (obs["{sensors[0] if sensors else "topic"}"]), and '
        'time [s]."""\n\n'
        + "\n".join(lines)
        + '\n    time: float\n    """the node\'s time [s]"""\n\n'
        "    def get(self, name: str, default=None): ...\n"
        "    def keys(self) -> list[str]: ...\n"
        "    def __getitem__(self, name: str): ...\n\n\n"
        "class NodeInfo:\n"
        f'    """What setup(info) is told about the run of robot {robot_id}."""\n\n'
        "    node_name: str\n    robot: str\n    velocity_topic: str | None\n"
        "    start_time_s: float\n    default_rate_hz: float\n    params: dict[str, object]\n"
    )


def write_stubs(root: Path) -> Path:
    """Write every stub under `root` (an empty folder); returns `root`."""
    from server.sim import robot_ids

    for package in packages(ROS1):
        _ros1_package(root / "ros1", package)
    for package in packages(ROS2):
        _ros2_package(root / "ros2", package)
    for robot_id in robot_ids():
        (root / "ros1" / f"{STEP_MODULE.format(robot=robot_id)}.py").write_text(
            _step_module(robot_id)
        )
    (root / "common").mkdir(parents=True, exist_ok=True)
    os.symlink(SANDBOX_DIR, root / "common" / "sandbox")
    return root


if __name__ == "__main__":  # the pool writes them in a process of their own (pool.py says why)
    import sys

    write_stubs(Path(sys.argv[1]))
