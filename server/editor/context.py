"""What the analysis knows of the run a file is for: the robot's topics, and the topics an
exercise's built-in nodes publish (the TurtleBot exercises' `plan` and `pose`), which a step
API controller may SUBSCRIBE to as if they were sensors."""

from __future__ import annotations

from dataclasses import dataclass

Topics = tuple[tuple[str, str], ...]  # (name, ROS 1 type name "pkg/Name")


@dataclass(frozen=True, slots=True)
class RobotTopics:
    """name -> type of every topic a node of this run can use, and which ones obs carries."""

    robot: str
    types: dict[str, str]
    sensors: tuple[str, ...]

    @classmethod
    def of(cls, robot_id: str | None, extra: Topics = ()) -> RobotTopics | None:
        from server.sim import get_robot, robot_ids

        if robot_id is None or robot_id not in robot_ids():
            return None
        topics = get_robot(robot_id).topics()
        types = {t.name: t.type_name for t in topics}
        sensors = [t.name for t in topics if str(t.direction) == "publish"]
        for name, type_name in extra:
            types.setdefault(name, type_name)
            if name not in sensors:
                sensors.append(name)
        return cls(robot_id, types, tuple(sensors))

    def listing(self) -> str:
        return ", ".join(f"{name} ({kind})" for name, kind in self.types.items())


@dataclass(frozen=True, slots=True)
class RunContext:
    """Which run a file is for, as far as the editor's analysis needs it."""

    robot: str | None = None
    extra_topics: Topics = ()  # published by the exercise's built-in nodes

    def to_json(self) -> dict:
        return {"robot": self.robot, "extra_topics": [list(t) for t in self.extra_topics]}


def builtin_topics(builtin_nodes: tuple[str, ...] | list[str]) -> Topics:
    """What an exercise's built-in nodes publish (server/runs/builtin.py), in their order."""
    from server.runs.builtin import BUILTIN_NODES

    found: list[tuple[str, str]] = []
    for name in builtin_nodes:
        node = BUILTIN_NODES.get(name)
        if node is not None:
            found += [(topic, kind) for topic, kind in node.publishes if (topic, kind) not in found]
    return tuple(found)


def topics_from_json(items) -> Topics:
    return tuple((str(name), str(kind)) for name, kind in items or ())
