"""How a run hosts its built-in nodes (server/runs/builtin.py): starts them once every student
node has declared its subscriptions, ticks them at their rates, hands them the messages they
subscribe to, and gives what they publish to the run's one routing path (`RunCore.route`: bus,
recording, the robot for command topics like teleop's Twist, other built-ins), as trusted.

Built-ins speak ROS 1 message objects (sandbox.msgs) unless they say `ros2_native = True`. In a
ROS 2 run the host converts at the robot's edge (server/runs/dialect.py) for the ROS 1 ones: what
they publish reaches the bus as ROS 2 CDR, what they receive arrives as ROS 1 objects. A ROS 2
native built-in (the NavigateToPose server) publishes and receives sandbox.msgs2 objects as they
are, and is left out of a ROS 1 run. `graph_subscriptions()` puts a built-in in the run's graph as
a subscriber, which a service or action server needs: a client's wait_for_service looks there.
Every hook gets the run's core (server/runs/core.py) as `run`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from sandbox.protocol import Envelope
from sandbox.units import NS_PER_S
from server.runs.builtin import BUILTIN_NODES, BuiltinNode
from server.runs.nav2_server import NavigationServer

if TYPE_CHECKING:
    from server.runs.core import RunCore

# The navigation server joins the built-ins here, not in builtin.py: it builds on the planner
# there and on the ROS 2 action wire, so builtin.py cannot import it.
BUILTIN_NODES.setdefault(NavigationServer.name, NavigationServer)


class BuiltinHost:
    def __init__(self, names: tuple[str, ...], ros_version: int = 1) -> None:
        self.ros_version = ros_version
        nodes = [BUILTIN_NODES[name]() for name in names]
        self.nodes: list[BuiltinNode] = [
            node for node in nodes if ros_version == 2 or not node.ros2_native
        ]
        self._next_ns: dict[str, int] = {}

    def __bool__(self) -> bool:
        return bool(self.nodes)

    def get(self, name: str) -> BuiltinNode | None:
        return next((node for node in self.nodes if node.name == name), None)

    def published_topics(self, run: RunCore) -> list[tuple[str, str, float | None]]:
        """(topic, ROS type in the run's dialect, rate) of everything the built-ins publish,
        for the students."""
        return [
            (topic, kind if node.ros2_native else run.dialect.type_name(kind), node.rate_hz)
            for node in self.nodes
            for topic, kind in node.publishes
        ]

    def start(self, run: RunCore) -> None:
        for node in self.nodes:
            run.bus.add_node(node.name)
            for topic, kind in node.graph_subscriptions():
                run.bus.declare_listener(node.name, topic, kind)
            for topic, kind in node.publishes:
                if topic in node.latched:
                    name = kind if node.ros2_native else run.dialect.type_name(kind)
                    run.bus.declare_topic(topic, name, node.name)
                    run.bus.topics[topic].latched_by.add(node.name)
        # Every built-in is ready before any publishes (the planner needs its map before the
        # waypoints node sends the first goal).
        started = [(node, node.start(run)) for node in self.nodes]
        for node in self.nodes:  # after start(): a node may take its rate from the run's params
            # start() publishes the time-0 message; ticks follow one period later.
            self._next_ns[node.name] = round(NS_PER_S / node.rate_hz) if node.rate_hz else 0
        for node, published in started:
            self.publish(run, node, published)

    def publish(self, run: RunCore, node: BuiltinNode, published: list[tuple[str, object]]) -> None:
        """Convert what `node` published to the run's dialect and route it (trusted)."""
        for topic, message in published:
            if node.ros2_native:
                envelope = Envelope(topic, message._type, message.serialize())
            elif "/msg/" in message._type:  # our mistake, said plainly
                raise TypeError(
                    f"built-in node '{node.name}' published a ROS 2 {message._type}; a built-in "
                    "that speaks ROS 2 says ros2_native = True (server/runs/builtin.py)"
                )
            else:
                envelope = run.dialect.envelope(topic, message)
            run.route(node.name, envelope, message, node.ros2_native)

    def listens_to(self, topic: str) -> bool:
        """Does any built-in take messages on `topic`?"""
        return any(node.listens_to(topic) for node in self.nodes)

    def deliver(
        self, run: RunCore, source: str, topic: str, message: object, native: bool = False
    ) -> None:
        """Hand `message` (a ROS 2 object if `native`, else ROS 1) to every built-in that
        listens to `topic`, converted to the dialect each speaks."""
        for node in self.nodes:
            if node.name == source or not node.listens_to(topic):
                continue
            if node.ros2_native == native:
                mine = message
            elif node.ros2_native:
                mine = run.dialect.to_ros2(message)
            else:
                mine = run.dialect.to_ros1(message)
            self.publish(run, node, node.on_message(run, topic, mine))

    def tick(self, run: RunCore) -> None:
        for node in self.nodes:
            if node.rate_hz and self._next_ns[node.name] <= run.time_ns:
                self._next_ns[node.name] = run.time_ns + round(NS_PER_S / node.rate_hz)
                self.publish(run, node, node.tick(run))

    def next_ns(self) -> int | None:
        """Run time of the next tick, if any built-in ticks (the clocks stop there)."""
        ticking = [self._next_ns[node.name] for node in self.nodes if node.rate_hz]
        return min(ticking) if ticking else None
