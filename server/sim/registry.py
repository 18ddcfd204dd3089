"""Robots by id. Worlds have their own registry in server.sim.world; this module joins the two
(which robot makes sense in which world, as the worlds declare). `server.sim.checks` validates
every entry of both."""

from __future__ import annotations

from server.sim.robots.base import RobotModel
from server.sim.robots.crop_rover import CropRover
from server.sim.robots.crowbot import CrowBot
from server.sim.robots.ir_scout import IrScout
from server.sim.robots.turtlebot import TurtleBot
from server.sim.robots.turtlebot3 import TurtleBot3
from server.sim.world import load_world, world_ids

_ROBOTS: dict[str, type[RobotModel]] = {
    cls.id: cls for cls in (CrowBot, CropRover, IrScout, TurtleBot, TurtleBot3)
}


class UnknownRobotError(ValueError):
    pass


def robot_ids() -> tuple[str, ...]:
    return tuple(sorted(_ROBOTS))


def get_robot(robot_id: str) -> RobotModel:
    """A fresh model of the robot `robot_id`; unknown ids fail with the list of valid ones."""
    cls = _ROBOTS.get(robot_id)
    if cls is None:
        raise UnknownRobotError(
            f"unknown robot '{robot_id}'; valid robot ids: {', '.join(robot_ids())}"
        )
    return cls()


def topic_types() -> tuple[str, ...]:
    """The ROS 1 type names of every robot's topics (the warm sandboxes build their classes)."""
    return tuple(
        sorted({topic.type_name for robot_id in _ROBOTS for topic in get_robot(robot_id).topics()})
    )


def robots_for_world(robot_id: str) -> tuple[str, ...]:
    """Ids of the worlds that declare they suit `robot_id`."""
    return tuple(w for w in world_ids() if robot_id in load_world(w).robots)
