"""What a run is made of, checked before anything starts: a robot in a world, one or more nodes
(a launch file's worth of student code), a clock, a duration, a seed and optional parameters.
Every problem is a sentence a newcomer can act on."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from sandbox.protocol import Api, Clock
from server.sim import load_world, robot_ids, robots_for_world, world_ids

MAX_DURATION_S = 3600.0  # [s] an hour of simulated time: longer is a mistake, not an exercise
MAX_NODES = 8  # a launch file larger than this is not a student exercise
MAX_CODE_BYTES = 256 * 1024  # [bytes] per node file
SCRIPT_ACTIONS = ("light", "goal", "button", "fault", "teleop")
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
    # Scripted controls: (run time [s], action, value), e.g. (10.0, "light", ("lamp", 1.5, 1)).
    script: tuple[tuple[float, str, object], ...] = ()
    builtin_nodes: tuple[str, ...] = ()  # trusted helpers: map_server, localization, ...
    # Workspace data files (relative path, bytes) copied into every node's working directory.
    files: tuple[tuple[str, bytes], ...] = ()

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
        from server.runs.builtin import BUILTIN_NODES

        for name in self.builtin_nodes:
            if name not in BUILTIN_NODES:
                raise RunSpecError(
                    f"unknown built-in node '{name}'; built-in nodes: {', '.join(BUILTIN_NODES)}"
                )
        for time_s, action, _ in self.script:
            if not (isinstance(time_s, (int, float)) and 0 <= time_s <= self.duration_s):
                raise RunSpecError(f"scripted '{action}' at {time_s!r} s is outside the run")
            if action not in SCRIPT_ACTIONS:
                raise RunSpecError(
                    f"scripted action '{action}' is unknown; use one of {', '.join(SCRIPT_ACTIONS)}"
                )
        for label, values in (
            ("initial_pose", self.initial_pose),
            ("light_position", self.light_position),
            ("goal", self.goal),
        ):
            if values is not None and not all(
                isinstance(v, (int, float)) and math.isfinite(v) for v in values
            ):
                raise RunSpecError(f"{label} must be finite numbers, got {values!r}")
