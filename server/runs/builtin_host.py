"""How a run hosts its built-in nodes (server/runs/builtin.py): starts them once every student
node has declared its subscriptions, ticks them at their rates, hands them the messages they
subscribe to, and routes what they publish through the bus, the recording and - for command
topics like teleop's Twist - to the robot."""

from __future__ import annotations

from typing import TYPE_CHECKING

from sandbox.msgs import get_message_class
from sandbox.protocol import Envelope
from server.runs.builtin import BUILTIN_NODES, BuiltinNode

if TYPE_CHECKING:
    from server.runs.run import Run

NS = 1_000_000_000


class BuiltinHost:
    def __init__(self, names: tuple[str, ...]) -> None:
        self.nodes: list[BuiltinNode] = [BUILTIN_NODES[name]() for name in names]
        self._next_ns: dict[str, int] = {}

    def __bool__(self) -> bool:
        return bool(self.nodes)

    def get(self, name: str) -> BuiltinNode | None:
        return next((node for node in self.nodes if node.name == name), None)

    def published_topics(self) -> list[tuple[str, str, float | None]]:
        """(topic, ROS type, rate) of everything the built-ins publish, for the students."""
        return [(t, kind, node.rate_hz) for node in self.nodes for t, kind in node.publishes]

    def start(self, run: Run) -> None:
        for node in self.nodes:
            run.bus.add_node(node.name)
            # start() publishes the time-0 message; ticks follow one period later.
            self._next_ns[node.name] = round(NS / node.rate_hz) if node.rate_hz else 0
        # Every built-in is ready before any publishes (the planner needs its map before the
        # waypoints node sends the first goal).
        started = [(node, node.start(run)) for node in self.nodes]
        for node, published in started:
            self.publish(run, node, published)

    def publish(self, run: Run, node: BuiltinNode, published: list[tuple[str, object]]) -> None:
        for topic, message in published:
            envelope = Envelope(topic, message._type, message.serialize())
            run.bus.publish(node.name, envelope, run.time_s)
            run.record(topic, envelope.type, run.time_ns, envelope.data)
            if topic in run.sim.robot.commands and not run.faults.motors_stalled():
                run.sim.apply(topic, message)  # trusted: a rejection is our bug, let it raise
            self.deliver(run, node.name, topic, message)

    def deliver(self, run: Run, source: str, topic: str, message: object) -> None:
        for node in self.nodes:
            if topic in node.subscribes and node.name != source:
                self.publish(run, node, node.on_message(run, topic, message))

    def deliver_envelope(self, run: Run, source: str, envelope: Envelope) -> None:
        """A student node's message, decoded only if a built-in listens to its topic."""
        if any(envelope.topic in node.subscribes for node in self.nodes):
            message = get_message_class(envelope.type).deserialize(envelope.data)
            self.deliver(run, source, envelope.topic, message)

    def tick(self, run: Run) -> None:
        for node in self.nodes:
            if node.rate_hz and self._next_ns[node.name] <= run.time_ns:
                self._next_ns[node.name] = run.time_ns + round(NS / node.rate_hz)
                self.publish(run, node, node.tick(run))

    def next_ns(self) -> int | None:
        """Run time of the next tick, if any built-in ticks (the clocks stop there)."""
        ticking = [self._next_ns[node.name] for node in self.nodes if node.rate_hz]
        return min(ticking) if ticking else None
