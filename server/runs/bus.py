"""The topic bus of one run: every message from the robot and from every node passes here.

Any node may subscribe to any topic; each subscriber has its own inbox, bounded per topic
(`QUEUE_SIZE`, oldest dropped first, like a ROS subscriber's queue), delivered at the node's
next wake in the order messages arrived. The bus also knows the graph - nodes, topics, their
publishers and subscribers, and measured rates - for an rqt_graph-like view.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import msgspec

from sandbox.protocol import Envelope, GraphTopic, TopicDecl

QUEUE_SIZE = 100  # [messages] per topic per subscriber between two wakes
RATE_WINDOW = 50  # [messages] recent arrival times kept per topic to measure its rate
ROBOT = "robot"  # the publisher name of everything the robot (sim or hardware) publishes
RUN = "run"  # the publisher name of what the run itself publishes (the goal)


@dataclass(slots=True)
class _Topic:
    type: str
    publishers: set[str] = field(default_factory=set)
    subscribers: set[str] = field(default_factory=set)
    count: int = 0
    recent: deque = field(default_factory=lambda: deque(maxlen=RATE_WINDOW))
    latched_by: set[str] = field(default_factory=set)  # publishers with latch=True
    latched: dict[str, tuple[float, Envelope]] = field(default_factory=dict)  # their last
    # A topic open to several types (a ROS 2 robot's velocity topic takes Twist and
    # TwistStamped): each subscriber gets only messages of the type it subscribed with.
    mixed: bool = False
    subscriber_types: dict[str, str] = field(default_factory=dict)
    # ROS 2 QoS (sandbox.protocol.TopicDecl): publishers offering BEST_EFFORT, and the ROS 2
    # subscribers, whose deliveries say which publisher sent them and whether they are a
    # latched topic's history (a RELIABLE or a VOLATILE subscription drops those itself).
    best_effort_by: set[str] = field(default_factory=set)
    ros2_subscribers: set[str] = field(default_factory=set)

    def rate_hz(self) -> float | None:
        if len(self.recent) < 2 or self.recent[-1] <= self.recent[0]:
            return None
        return (len(self.recent) - 1) / (self.recent[-1] - self.recent[0])


@dataclass(slots=True)
class _Inbox:
    queues: dict[str, deque] = field(default_factory=dict)  # topic -> deque[(seq, t, env)]
    pending: int = 0
    dropped: int = 0


class TopicTypeMismatch(ValueError):
    pass


class TopicBus:
    def __init__(self) -> None:
        self.topics: dict[str, _Topic] = {}
        self.nodes: list[str] = []
        self._inboxes: dict[str, _Inbox] = {}
        self._seq = 0
        self.version = 0  # bumped whenever a node, a publisher or a subscriber comes or goes
        self._ended: set[str] = set()  # nodes that ended: not routed to, not in graph_topics

    # ----------------------------------------------------------------------------- graph
    def add_node(self, name: str) -> None:
        if name not in self._inboxes:
            self.nodes.append(name)
            self._inboxes[name] = _Inbox()

    def declare_topic(self, name: str, type_name: str, publisher: str | None = None) -> None:
        topic = self.topics.get(name)
        if topic is None:
            topic = self.topics[name] = _Topic(type_name)
            self.version += 1
        elif topic.type != type_name and not topic.mixed:
            raise TopicTypeMismatch(f"topic '{name}' carries {topic.type}, not {type_name}")
        if publisher is not None and publisher not in topic.publishers:
            topic.publishers.add(publisher)
            self.version += 1

    def allow_types(self, name: str, type_name: str) -> None:
        """Declare `name` with `type_name` as the type it is listed with, and let publishers
        use other types on it too (the robot's edge checks what reaches the robot)."""
        self.declare_topic(name, type_name)
        self.topics[name].mixed = True

    def declare_listener(self, node: str, name: str, type_name: str) -> None:
        """A built-in node listens to topic `name` in-process (its host hands it the messages):
        it shows in the graph as a subscriber - so clients see the services it serves - and
        nothing is queued for it here."""
        self.declare_topic(name, type_name)
        topic = self.topics[name]
        topic.subscribers.add(node)
        if topic.mixed:
            topic.subscriber_types[node] = type_name
        self.version += 1

    def declare(self, node: str, advertised: list[TopicDecl], subscribed: list[TopicDecl]) -> None:
        """Record what a node said it publishes and subscribes to (from its Yield)."""
        for decl in advertised:
            self.declare_topic(decl.name, decl.type, node)
            if decl.latch:
                self.topics[decl.name].latched_by.add(node)
            if decl.best_effort:
                self.topics[decl.name].best_effort_by.add(node)
                self.version += 1
        for decl in subscribed:
            self.declare_topic(decl.name, decl.type)
            topic = self.topics[decl.name]
            topic.subscribers.add(node)
            ros2 = decl.volatile or decl.latch or decl.best_effort
            if ros2:
                topic.ros2_subscribers.add(node)
            if topic.mixed:
                topic.subscriber_types[node] = decl.type
            queue = self._inboxes[node].queues.setdefault(decl.name, deque(maxlen=QUEUE_SIZE))
            self.version += 1
            # A latched topic's last message reaches a subscriber that comes late (rospy).
            for publisher, (time_s, envelope) in sorted(topic.latched.items()):
                if publisher != node and (not topic.mixed or envelope.type == decl.type):
                    if ros2:
                        envelope = msgspec.structs.replace(
                            envelope, publisher=publisher, replayed=True
                        )
                    self._enqueue(self._inboxes[node], queue, time_s, envelope)

    def unsubscribe(self, node: str, names: list[str]) -> None:
        """The node stopped listening to `names`: nothing more is queued for it there."""
        inbox = self._inboxes[node]
        for name in names:
            topic = self.topics.get(name)
            if topic is not None:
                topic.subscribers.discard(node)
                topic.ros2_subscribers.discard(node)
            queue = inbox.queues.pop(name, None)
            if queue:
                inbox.pending -= len(queue)
            self.version += 1

    def remove_node(self, node: str) -> None:
        """A node ended: nothing more is queued for it, and the nodes still running no longer
        see it in the graph (services it served are gone). The run's graph keeps it: it shows
        what talked to what over the whole run."""
        inbox = self._inboxes.get(node)
        if inbox is None or node in self._ended:
            return
        self._ended.add(node)
        for queue in inbox.queues.values():
            queue.clear()
        inbox.pending = 0
        for topic in self.topics.values():
            # rospy: a latched message lives as long as its publisher's node.
            topic.latched_by.discard(node)
            topic.latched.pop(node, None)
        self.version += 1

    def graph_topics(self) -> list[GraphTopic]:
        """The graph as running nodes see it (rospy.get_published_topics, services)."""
        ended = self._ended
        return [
            GraphTopic(
                name,
                topic.type,
                sorted(topic.publishers - ended),
                sorted(topic.subscribers - ended),
                sorted(topic.best_effort_by - ended),
                sorted(topic.latched_by - ended),
            )
            for name, topic in sorted(self.topics.items())
        ]

    # ----------------------------------------------------------------------------- traffic
    def publish(self, publisher: str, envelope: Envelope, time_s: float) -> None:
        """Route one message to every subscriber's inbox (not back to its publisher)."""
        topic = self.topics.get(envelope.topic)
        if topic is None:
            self.declare_topic(envelope.topic, envelope.type, publisher)
            topic = self.topics[envelope.topic]
        elif topic.type != envelope.type and not topic.mixed:
            raise TopicTypeMismatch(
                f"topic '{envelope.topic}' carries {topic.type}, not {envelope.type}"
            )
        if publisher not in topic.publishers:
            topic.publishers.add(publisher)
            self.version += 1
        if publisher in topic.latched_by:
            topic.latched[publisher] = (time_s, envelope)
        topic.count += 1
        topic.recent.append(time_s)
        self._seq += 1
        stamped = envelope
        if topic.best_effort_by:  # ROS 2 subscribers need to know who sent it
            stamped = msgspec.structs.replace(envelope, publisher=publisher)
        for name in topic.subscribers:
            if name == publisher or name in self._ended:
                continue
            if topic.mixed and topic.subscriber_types.get(name, envelope.type) != envelope.type:
                continue
            inbox = self._inboxes[name]
            queue = inbox.queues.get(envelope.topic)
            if queue is not None:  # None: a built-in listener (declare_listener)
                delivered = stamped if name in topic.ros2_subscribers else envelope
                self._enqueue(inbox, queue, time_s, delivered, self._seq)

    def _enqueue(
        self, inbox: _Inbox, queue: deque, time_s: float, envelope: Envelope, seq: int = 0
    ) -> None:
        """Queue one message for a subscriber (the oldest drops out of a full queue)."""
        if not seq:
            self._seq += 1
            seq = self._seq
        if len(queue) == queue.maxlen:
            inbox.dropped += 1
            inbox.pending -= 1
        queue.append((seq, time_s, envelope))
        inbox.pending += 1

    def has_subscribers(self, name: str) -> bool:
        """Does a running node subscribe to topic `name`?"""
        topic = self.topics.get(name)
        return topic is not None and bool(topic.subscribers - self._ended)

    def has_pending(self, node: str) -> bool:
        return self._inboxes[node].pending > 0

    def has_pending_on(self, node: str, topics: frozenset[str]) -> bool:
        """Is a message waiting for `node` on one of `topics`?"""
        inbox = self._inboxes[node]
        if not inbox.pending:
            return False
        return any(inbox.queues.get(name) for name in topics)

    def take(self, node: str) -> tuple[list[Envelope], float | None]:
        """Everything waiting for `node`, in arrival order, and the publication time of the
        newest robot message among them (for command latency), or None."""
        inbox = self._inboxes[node]
        if not inbox.pending:
            return [], None
        items = []
        for queue in inbox.queues.values():
            items.extend(queue)
            queue.clear()
        inbox.pending = 0
        items.sort(key=lambda item: item[0])
        newest_robot = None
        for _, time_s, envelope in items:
            if ROBOT in self.topics[envelope.topic].publishers:
                newest_robot = time_s
        return [envelope for _, _, envelope in items], newest_robot

    def dropped(self, node: str) -> int:
        return self._inboxes[node].dropped

    def graph(self) -> dict:
        """Nodes, topics with type, publishers, subscribers, message count and measured rate."""
        return {
            "nodes": [ROBOT, *self.nodes],
            "topics": [
                {
                    "name": name,
                    "type": topic.type,
                    "publishers": sorted(topic.publishers),
                    "subscribers": sorted(topic.subscribers),
                    "messages": topic.count,
                    "rate_hz": topic.rate_hz(),
                }
                for name, topic in sorted(self.topics.items())
            ],
        }
