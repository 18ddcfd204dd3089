"""The pure simulation core: robots, worlds, sensors and physics. No I/O, no wall clock.

`__all__` is the public surface: what notebooks, tests and the run engine may import from
`server.sim` itself. Anything else lives in a submodule and may change without notice. Running a
step-API controller in-process is deliberately not here: it is `server.sim.unsandboxed`, a name
that says what it is.
"""

from server.sim.backend import RobotBackend, WorldView
from server.sim.checks import DefinitionError, check_robot, check_world
from server.sim.registry import get_robot, robot_ids, robots_for_world, topic_types
from server.sim.robots.base import Direction, TopicSpec
from server.sim.simulation import EventKind, Published, Scene, SimEvent, Simulation, SimulationError
from server.sim.state import Pose2D, RobotState
from server.sim.world import load_world, world_ids

__all__ = [
    "DefinitionError",
    "Direction",
    "EventKind",
    "Pose2D",
    "Published",
    "RobotBackend",
    "RobotState",
    "Scene",
    "SimEvent",
    "Simulation",
    "SimulationError",
    "TopicSpec",
    "WorldView",
    "check_robot",
    "check_world",
    "get_robot",
    "load_world",
    "robot_ids",
    "robots_for_world",
    "topic_types",
    "world_ids",
]
