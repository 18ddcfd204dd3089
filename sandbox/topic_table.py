"""The topics one node knows: the robot's, and those it advertised or subscribed to.

A node may name any topic, as in rospy; names resolve and remap through sandbox.names to the
run's bus names (no leading slash for root names). The table checks what a node may do with a
topic (the robot's sensor topics are the robot's to publish; one topic, one type), warns once
when a new name looks like a typo of one of the robot's topics, and collects the declarations
the node sends the parent with its next Yield.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable
from typing import Any

from sandbox.msgs import Message
from sandbox.names import Names
from sandbox.protocol import NodeInfo, TopicDecl
from sandbox.ros_errors import ROSException
from sandbox.services import is_internal

ANY_TYPE = "*"  # rospy.AnyMsg's type name


def is_message_class(data_class: Any) -> bool:
    """A ROS 1 class (sandbox.msgs.Message) or a ROS 2 one (sandbox.msgs2: `_type`,
    `serialize`, classmethod `deserialize`)."""
    if not isinstance(data_class, type):
        return False
    if issubclass(data_class, Message):
        return True
    return (
        isinstance(getattr(data_class, "_type", None), str)
        and callable(getattr(data_class, "serialize", None))
        and callable(getattr(data_class, "deserialize", None))
    )


class TopicTable:
    def __init__(self, info: NodeInfo, names: Names, warn: Callable[[str], None]) -> None:
        self._error = ROSException
        self.info = info
        self.names = names
        self._warn = warn
        self.types: dict[str, str] = {}  # topic -> type, the robot's and new ones
        self._robot: dict[str, tuple[str, str]] = {}  # name -> (type, direction)
        self._accepts: dict[str, list[str]] = {}  # robot topics taking several types
        for topic in info.robot_topics:
            self._robot[topic.name] = (topic.type, topic.direction)
            self.types[topic.name] = topic.type
            if topic.accepts:
                self._accepts[topic.name] = topic.accepts
        self.advertised: set[str] = set()
        self.subscribed: set[str] = set()
        self._latched: set[str] = set()
        self._checked: dict[tuple[str, Any], str] = {}  # (name as given, class) -> bus name
        self._warned: set[str] = set()
        self._new_advertised: list[TopicDecl] = []
        self._new_subscribed: list[TopicDecl] = []
        self._unsubscribed: list[str] = []

    # ------------------------------------------------------------------ names
    def bus_name(self, topic: Any) -> str:
        """The run's name for a topic this node names: resolved against the node's namespace
        and name and remapped, as rospy does; internal service topics as they are."""
        if isinstance(topic, str) and is_internal(topic):
            return topic
        if not isinstance(topic, str) or not topic.strip("/"):
            raise self._error(
                f"a topic name is a non-empty string such as 'Distance', got {topic!r}"
            )
        return self.names.topic(topic)

    def robot_direction(self, topic: str) -> str | None:
        """ "publish" for the robot's sensor topics, "subscribe" for its command topics."""
        entry = self._robot.get(topic)
        return entry[1] if entry else None

    def sensor_topics(self) -> list[str]:
        return [name for name, (_, way) in self._robot.items() if way == "publish"]

    def command_topics(self) -> list[str]:
        return [name for name, (_, way) in self._robot.items() if way == "subscribe"]

    def _close_robot_topic(self, name: str) -> str | None:
        """One of the robot's topic names that `name` is probably a typo of, or None."""
        by_lower = {topic.lower(): topic for topic in self._robot}
        if name.lower() in by_lower:
            return by_lower[name.lower()]
        close = difflib.get_close_matches(name.lower(), list(by_lower), n=1, cutoff=0.8)
        return by_lower[close[0]] if close else None

    def unknown_topic(self, name: str) -> Exception:
        close = self._close_robot_topic(name)
        hint = f"did you mean '{close}'? " if close else ""
        return self._error(
            f"unknown topic '{name}' on robot {self.info.robot}; {hint}its topics are "
            f"{', '.join(self.sensor_topics())} (sensors) and "
            f"{', '.join(self.command_topics())} (commands)"
        )

    def _new_topic(self, name: str) -> None:
        """A topic that is not the robot's: allowed, as in rospy; refused only where the run
        says so; a name close to a robot topic gets a warning once (a typo is a dead topic)."""
        if not self.info.allow_new_topics:
            raise self.unknown_topic(name)
        close = self._close_robot_topic(name)
        if close is not None and name not in self._warned:
            self._warned.add(name)
            self._warn(
                f"'{name}' is not one of the topics of robot {self.info.robot}; did you mean "
                f"'{close}'? (a new topic '{name}' was made; the robot does not see it)"
            )

    def _check_type(self, name: str, data_class: Any) -> str:
        type_name = getattr(data_class, "_type", None)
        if type_name == ANY_TYPE and isinstance(data_class, type):  # rospy.AnyMsg
            known = self.types.get(name)
            if known is None:
                raise self._error(
                    f"rospy.AnyMsg on '{name}' needs a topic whose type is known (one of the "
                    "robot's or one this node publishes); subscribe with the message class, "
                    "e.g. std_msgs.msg.String"
                )
            return known
        if not is_message_class(data_class):
            raise self._error(
                f"topic '{name}' needs a message class such as std_msgs.msg.Int32 as its type, "
                f"got {data_class!r}"
            )
        known = self.types.get(name)
        if known is not None and known != type_name:
            accepted = self._accepts.get(name)
            if accepted is None:
                raise self._error(f"topic '{name}' carries {known}, not {type_name}")
            if type_name not in accepted:
                raise self._error(f"topic '{name}' takes {' or '.join(accepted)}, not {type_name}")
        return type_name

    # ------------------------------------------------------------------ declarations
    def advertise(
        self, topic: Any, data_class: Any, latch: bool = False, best_effort: bool = False
    ) -> str:
        """Check that this node may publish `data_class` on `topic`; return the bus name.
        `latch`: later subscribers get the last message too (rospy's latch=True);
        `best_effort`: a ROS 2 publisher offering BEST_EFFORT (sandbox.protocol.TopicDecl)."""
        # Hot path: the step API and many scripts publish the same topic every period.
        checked = self._checked.get((topic, data_class))
        if checked is not None:
            return checked
        name = self.bus_name(topic)
        if self.robot_direction(name) == "publish":
            raise self._error(
                f"'{name}' is published by the robot; command topics are "
                f"{', '.join(self.command_topics())}"
            )
        type_name = self._check_type(name, data_class)
        if name not in self.types:
            self._new_topic(name)
        self.types[name] = type_name
        if name not in self.advertised:
            self.advertised.add(name)
            self._new_advertised.append(TopicDecl(name, type_name, latch, best_effort))
        elif latch and name not in self._latched:
            self._new_advertised.append(TopicDecl(name, type_name, latch, best_effort))
        if latch:
            self._latched.add(name)
            return name  # not cached: the plain entry must not hide a later latch
        if isinstance(topic, str):
            self._checked[(topic, data_class)] = name
        return name

    def subscribe(
        self,
        topic: Any,
        data_class: Any,
        *,
        best_effort: bool = False,
        transient_local: bool = False,
        volatile: bool = False,
    ) -> str:
        """Check a subscription of `data_class` to `topic`; return the bus name. The keywords
        are a ROS 2 subscription's QoS (sandbox.protocol.TopicDecl); the first subscription
        of a topic in the node declares them."""
        name = self.bus_name(topic)
        type_name = self._check_type(name, data_class)
        if name not in self.types:
            self._new_topic(name)
        elif self.robot_direction(name) == "subscribe" and name not in self.advertised:
            self._warn(f"'{name}' is a command topic the robot listens to; nothing publishes it")
        self.types[name] = type_name
        if name not in self.subscribed:
            self.subscribed.add(name)
            self._new_subscribed.append(
                TopicDecl(name, type_name, transient_local, best_effort, volatile)
            )
            if name in self._unsubscribed:
                self._unsubscribed.remove(name)
        return name

    def unsubscribe(self, name: str) -> None:
        """Nothing in the node listens to `name` any more."""
        if name in self.subscribed:
            self.subscribed.discard(name)
            self._new_subscribed = [d for d in self._new_subscribed if d.name != name]
            self._unsubscribed.append(name)

    def take_declarations(self) -> tuple[list[TopicDecl], list[TopicDecl], list[str]]:
        """(advertised, subscribed, unsubscribed) since the last call, for the next Yield."""
        taken = (self._new_advertised, self._new_subscribed, self._unsubscribed)
        self._new_advertised, self._new_subscribed, self._unsubscribed = [], [], []
        return taken
