"""What a run is made of, checked before anything starts: a robot in a world, one or more nodes
(a launch file's worth of student code), a clock, a duration, a seed and optional parameters.
Every problem is a sentence a newcomer can act on.

A run is ROS 1 or ROS 2, never both (docs/architecture.md, "ROS 2"): each node's file says which
by what it imports (`import rclpy` / `from rclpy... import`: ROS 2; rospy or the step API:
ROS 1; a file importing neither goes with the others), read with `ast` so nothing runs. A node
or the run may also say so explicitly (`NodeSpec.ros_version`, `RunSpec.explicit_ros_version`).
No bridge: a run mixing the two is refused with a sentence naming one node of each.
"""

from __future__ import annotations

import ast
import functools
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from sandbox import python_ast
from sandbox.protocol import Api, Clock
from server.runs.commands import SCRIPTABLE, RunCommand
from server.sim import load_world, robot_ids, robots_for_world, world_ids

MAX_DURATION_S = 3600.0  # [s] an hour of simulated time: longer is a mistake, not an exercise
MAX_NODES = 8  # a launch file larger than this is not a student exercise
MAX_CODE_BYTES = 256 * 1024  # [bytes] per node file
_NODE_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,39}$")


class RunSpecError(ValueError):
    """The run cannot start as described; the message says what to change."""


@dataclass(frozen=True, slots=True)
class NodeSpec:
    """One node: a name (as in a launch file), its code, the file name its tracebacks show,
    and what rosrun or a launch file would give it: parameters, remappings, arguments and a
    namespace."""

    name: str
    code: str
    filename: str
    api: Api = Api.AUTO
    # Parameter name -> value, names as a launch file's <param> gives them: "~speed" (private),
    # "/max_speed" (global) or "gain" (relative to the node's namespace).
    params: dict[str, object] = field(default_factory=dict)
    remaps: tuple[tuple[str, str], ...] = ()  # (from, to) name pairs, as <remap from to>
    args: tuple[str, ...] = ()  # command-line arguments after the file name (rosrun style)
    namespace: str = "/"  # <group ns="..."> / <node ns="...">
    # 1 (rospy) or 2 (rclpy); None: read from the code (a node of a Python launch file is 2).
    ros_version: int | None = None

    @classmethod
    def from_file(cls, path: str | Path, name: str | None = None) -> NodeSpec:
        file = Path(path)
        if not file.is_file():
            raise RunSpecError(f"node file '{path}' does not exist (or is not a file)")
        try:
            code = file.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            raise RunSpecError(f"node file '{path}' is not UTF-8 text") from None
        default = re.sub(r"[^A-Za-z0-9_]", "_", file.stem) or "node"
        if not default[0].isalpha():
            default = "node_" + default
        return cls(name=name or default, code=code, filename=file.name)


@dataclass(frozen=True, slots=True)
class RunSpec:
    robot: str
    world: str
    nodes: tuple[NodeSpec, ...]
    clock: Clock = Clock.LOCKSTEP
    duration_s: float = 30.0
    seed: int = 0
    spawn: str | None = None  # a named spawn pose of the world
    initial_pose: tuple[float, float, float] | None = None  # x [m], y [m], yaw [rad]
    light_position: tuple[float, float] | None = None  # moves the world's first movable light
    goal: tuple[float, float, float] | None = None  # x [m], y [m], yaw [rad], on topic "goal"
    params: dict[str, object] = field(default_factory=dict)  # rospy.get_param values
    # Scripted commands: (run time [s], command), e.g. (10.0, Light(1.5, 1.0, name="lamp")).
    script: tuple[tuple[float, RunCommand], ...] = ()
    builtin_nodes: tuple[str, ...] = ()  # trusted helpers: map_server, localization, ...
    # Workspace data files (relative path, bytes) copied into every node's working directory.
    files: tuple[tuple[str, bytes], ...] = ()
    explicit_ros_version: int | None = None  # 1 or 2; None: decided from the nodes

    @property
    def ros_version(self) -> int:
        """1 or 2: the run's ROS (the explicit value, else what its nodes use, else 1).
        Raises RunSpecError for a run that mixes the two."""
        decided = [(node, *node_ros_version(node)) for node in self.nodes]
        explicit = self.explicit_ros_version
        if explicit is not None:
            if explicit not in (1, 2):
                raise RunSpecError(f"ros_version must be 1 or 2, got {explicit!r}")
            for node, version, why in decided:
                if version is not None and version != explicit:
                    raise RunSpecError(
                        f"node `{node.name}` {why} (ROS {version}) but this run is ROS "
                        f"{explicit}; a run is one or the other"
                    )
            return explicit
        ros2 = next(((n, why) for n, version, why in decided if version == 2), None)
        ros1 = next(((n, why) for n, version, why in decided if version == 1), None)
        if ros2 and ros1:
            (node2, why2), (node1, why1) = ros2, ros1
            raise RunSpecError(
                f"node `{node2.name}` {why2} (ROS 2) and node `{node1.name}` {why1} (ROS 1); "
                "a run is one or the other"
            )
        return 2 if ros2 else 1

    def validate(self) -> None:
        """Raise RunSpecError naming the first problem found."""
        if self.robot not in robot_ids():
            raise RunSpecError(
                f"unknown robot '{self.robot}'; valid robot ids: {', '.join(robot_ids())}"
            )
        if self.world not in world_ids():
            raise RunSpecError(
                f"unknown world '{self.world}'; valid world ids: {', '.join(world_ids())}"
            )
        if self.robot not in load_world(self.world).robots:
            raise RunSpecError(
                f"robot '{self.robot}' cannot be placed in world '{self.world}'; its worlds: "
                f"{', '.join(robots_for_world(self.robot))}"
            )
        if not isinstance(self.duration_s, (int, float)) or not (
            math.isfinite(self.duration_s) and 0 < self.duration_s <= MAX_DURATION_S
        ):
            raise RunSpecError(
                f"duration must be a positive number of seconds up to {MAX_DURATION_S:g}, "
                f"got {self.duration_s!r}"
            )
        if not isinstance(self.seed, int) or self.seed < 0:
            raise RunSpecError(f"seed must be a non-negative integer, got {self.seed!r}")
        if not self.nodes:
            raise RunSpecError("a run needs at least one node (a controller file)")
        if len(self.nodes) > MAX_NODES:
            raise RunSpecError(f"a run may have at most {MAX_NODES} nodes, got {len(self.nodes)}")
        seen: set[str] = set()
        for node in self.nodes:
            if not _NODE_NAME.match(node.name):
                raise RunSpecError(
                    f"node name '{node.name}' must start with a letter and use only letters, "
                    "digits and _ (at most 40 characters)"
                )
            if node.name in seen:
                raise RunSpecError(f"two nodes are named '{node.name}'; give each its own name")
            seen.add(node.name)
            if len(node.code.encode()) > MAX_CODE_BYTES:
                raise RunSpecError(
                    f"node '{node.name}' is larger than {MAX_CODE_BYTES // 1024} KiB of code"
                )
        self.ros_version  # noqa: B018  # a run mixing ROS 1 and ROS 2 nodes is refused here
        from server.runs.builtin_host import BUILTIN_NODES

        for name in self.builtin_nodes:
            if name not in BUILTIN_NODES:
                raise RunSpecError(
                    f"unknown built-in node '{name}'; built-in nodes: {', '.join(BUILTIN_NODES)}"
                )
            if BUILTIN_NODES[name].ros2_native and self.ros_version != 2:
                raise RunSpecError(
                    f"built-in node '{name}' serves ROS 2 nodes (rclpy) only, and this run's "
                    "nodes are ROS 1; write them with rclpy or leave the built-in out"
                )
        for time_s, command in self.script:
            if not isinstance(command, SCRIPTABLE):
                raise RunSpecError(
                    f"a script cannot send {command!r}; it sends one of "
                    f"{', '.join(cls.op for cls in SCRIPTABLE)}"
                )
            if not (isinstance(time_s, (int, float)) and 0 <= time_s <= self.duration_s):
                raise RunSpecError(f"scripted '{command.op}' at {time_s!r} s is outside the run")
        for label, values in (
            ("initial_pose", self.initial_pose),
            ("light_position", self.light_position),
            ("goal", self.goal),
        ):
            if values is not None and not all(
                isinstance(v, (int, float)) and math.isfinite(v) for v in values
            ):
                raise RunSpecError(f"{label} must be finite numbers, got {values!r}")


def node_ros_version(node: NodeSpec) -> tuple[int | None, str]:
    """(1, 2 or None for "either", and the words saying why: "uses rclpy") for one node."""
    if node.ros_version is not None:
        if node.ros_version not in (1, 2):
            raise RunSpecError(
                f"node `{node.name}`: ros_version must be 1 or 2, got {node.ros_version!r}"
            )
        return node.ros_version, f"is a ROS {node.ros_version} node"
    if node.api is Api.STEP:
        return 1, "uses the step API"
    return _ros_version_of_code(node.code)


@functools.lru_cache(maxsize=256)
def _ros_version_of_code(code: str) -> tuple[int | None, str]:
    """What a file's imports say (rclpy wins over rospy: a file trying one then the other is
    written for ROS 2 first); a file that does not parse is left to its own error later."""
    try:
        tree = python_ast.parse(code)
    except (SyntaxError, ValueError):
        return None, ""
    imported = set()
    for item in ast.walk(tree):
        if isinstance(item, ast.Import):
            imported.update(alias.name.split(".")[0] for alias in item.names)
        elif isinstance(item, ast.ImportFrom) and item.module and not item.level:
            imported.add(item.module.split(".")[0])
    if "rclpy" in imported:
        return 2, "uses rclpy"
    if "rospy" in imported:
        return 1, "uses rospy"
    defines_step = any(
        isinstance(item, ast.FunctionDef | ast.AsyncFunctionDef) and item.name == "step"
        for item in tree.body
    )
    return (1, "uses the step API") if defines_step else (None, "")
