"""What the analysis knows of the run a file is for: the robot's topics, and the topics an
exercise's built-in nodes publish (the TurtleBot exercises' `plan` and `pose`), which a step
API controller may SUBSCRIBE to as if they were sensors."""

from __future__ import annotations

from dataclasses import dataclass

Topics = tuple[tuple[str, str], ...]  # (name, ROS 1 type name "pkg/Name")
TopicRow = tuple[str, str, str]  # (name, "pkg/Name", "publish" or "subscribe": the robot's side)
_catalog: dict[str, tuple[TopicRow, ...]] | None = None


def robot_catalog() -> dict[str, tuple[TopicRow, ...]]:
    """Every robot's topics by robot id: from server.sim in the server; inside the editor's
    sandbox, which has no server.sim, what the server gave the host (`install_robot_catalog`)."""
    global _catalog
    if _catalog is None:
        from server.sim import get_robot, robot_ids

        _catalog = {
            robot: tuple((t.name, t.type_name, str(t.direction)) for t in get_robot(robot).topics())
            for robot in robot_ids()
        }
    return _catalog


def install_robot_catalog(catalog: dict[str, list[list[str]]]) -> None:
    global _catalog
    _catalog = {robot: tuple((str(n), str(t), str(d)) for n, t, d in rows)
                for robot, rows in catalog.items()}  # fmt: skip


@dataclass(frozen=True, slots=True)
class RobotTopics:
    """name -> type of every topic a node of this run can use, and which ones obs carries."""

    robot: str
    types: dict[str, str]
    sensors: tuple[str, ...]

    @classmethod
    def of(cls, robot_id: str | None, extra: Topics = ()) -> RobotTopics | None:
        rows = robot_catalog().get(robot_id) if robot_id is not None else None
        if rows is None:
            return None
        types = {name: type_name for name, type_name, _ in rows}
        sensors = [name for name, _, direction in rows if direction == "publish"]
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
