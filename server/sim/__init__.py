"""The pure simulation core: robots, worlds, sensors and physics. No I/O, no wall clock."""

from server.sim.registry import get_robot, robot_ids, robots_for_world
from server.sim.simulation import EventKind, Published, Scene, SimEvent, Simulation, SimulationError
from server.sim.state import Pose2D, RobotState
from server.sim.world import load_world, world_ids

__all__ = [
    "EventKind",
    "Pose2D",
    "Published",
    "RobotState",
    "Scene",
    "SimEvent",
    "Simulation",
    "SimulationError",
    "get_robot",
    "load_world",
    "robot_ids",
    "robots_for_world",
    "world_ids",
]
